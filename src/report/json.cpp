#include "kdl_space/report/json.hpp"

namespace kdl_space::report {

Json fixedJointsJson(const FloatingModel& model) {
  Json list = Json::array();
  for (const FixedJoint& f : model.fixedJoints()) list.push_back(Json{{"joint", f.joint}, {"reason", f.reason}});
  return list;
}

Json toJson(const Eigen::MatrixXd& m) {
  if (m.cols() != 1) return toJsonRows(m);
  Json column = Json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) column.push_back(m(i, 0));
  return column;
}

Json toJsonRows(const Eigen::MatrixXd& m) {
  Json rows = Json::array();
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

}  // namespace kdl_space::report
