#include "cli_common.hpp"

#include <cmath>
#include <iomanip>

namespace kdl_space::cli {

Json toJson(const Eigen::MatrixXd& m) {
  Json rows = Json::array();
  if (m.cols() == 1) {
    for (Eigen::Index i = 0; i < m.rows(); ++i) rows.push_back(m(i, 0));
    return rows;
  }
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    Json row = Json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

const std::vector<std::string>& twistLabels() {
  static const std::vector<std::string> labels{"vx", "vy", "vz", "wx", "wy", "wz"};
  return labels;
}

void printMatrix(std::ostream& os, const std::string& title, const Eigen::MatrixXd& m,
                 const std::vector<std::string>& row_labels, const std::vector<std::string>& col_labels) {
  std::size_t width = 4;
  for (const auto& l : row_labels) width = std::max(width, l.size());
  os << title << "\n";
  if (m.size() == 0) {
    os << "  (empty)\n";
    return;
  }
  os << "  " << std::setw(static_cast<int>(width)) << "";
  for (const auto& c : col_labels) os << " " << std::setw(13) << c.substr(0, 13);
  os << "\n";
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    os << "  " << std::left << std::setw(static_cast<int>(width)) << row_labels.at(i) << std::right;
    for (Eigen::Index j = 0; j < m.cols(); ++j)
      os << " " << std::setw(13) << std::setprecision(6) << std::scientific << m(i, j);
    os << std::defaultfloat << "\n";
  }
}

std::pair<std::string, double> parseAssignment(const std::string& text, const std::string& option) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw UsageError(option + " expects NAME=VALUE, got '" + text + "'");
  const std::string name = text.substr(0, eq), value = text.substr(eq + 1);
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != value.size() || !std::isfinite(v))
    throw UsageError(option + " " + name + ": '" + value + "' is not a finite number");
  return {name, v};
}

}  // namespace kdl_space::cli
