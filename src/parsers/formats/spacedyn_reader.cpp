// spaceDynToUrdf: an LP function file's numeric assignments read (a small MATLAB subset), checked
// against num_q, and written as the URDF document of the same link system.
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "kdl_space/parsers/formats/spacedyn_lp.hpp"
#include "kdl_space/parsers/input_file.hpp"
#include "kdl_space/spatial/errors.hpp"
#include "parsers/formats/spacedyn_angles.hpp"
#include "parsers/formats/urdf_builder.hpp"
#include "spatial/message_text.hpp"

namespace kdl_space {
namespace {
using Eigen::Vector3d;

/// A value of the subset: numbers (column-major, up to 3 dimensions), a char row, or a cell of char rows.
struct Value {
  std::vector<int> dims{0, 0};
  std::vector<double> data;
  std::string text;
  std::vector<std::string> cells;
  bool is_text = false, is_cells = false;
  int line = 0;
  int count() const { int c = 1; for (int d : dims) c *= d; return c; }
};

/// One statement: its first line and its text (comments removed, lines joined inside brackets).
struct Statement {
  int line = 0;
  std::string text;
};

std::vector<Statement> statements(const std::string& src) {
  std::vector<Statement> out;
  Statement cur;
  int depth = 0, line = 1;
  bool quote = false, comment = false, continued = false;
  for (std::size_t i = 0; i <= src.size(); ++i) {
    const char c = i < src.size() ? src[i] : '\n';
    if (c == '\n' && continued) {  // "..." continues the statement on the next line
      comment = continued = false;
      ++line;
      cur.text += ' ';
      continue;
    }
    if (c == '\n') comment = false, quote = false;
    else if (comment) continue;
    else if (!quote && src.compare(i, 3, "...") == 0) { comment = continued = true; continue; }
    else if (c == '%' && !quote) { comment = true; continue; }
    else if (c == '\'' && !quote && depth == 0 && !cur.text.empty() && (std::isalnum((unsigned char)cur.text.back()) || cur.text.back() == ']' || cur.text.back() == '\''))
      ;  // a transpose, not a quote
    else if (c == '\'') quote = !quote;
    else if (!quote && (c == '[' || c == '{' || c == '(')) ++depth;
    else if (!quote && (c == ']' || c == '}' || c == ')')) --depth;
    const bool ends = !quote && depth <= 0 && (c == ';' || c == '\n' || c == ',');
    if (ends && (c != ',' || cur.text.rfind("function", 0) != 0)) {
      const auto b = cur.text.find_first_not_of(" \t\r"), e = cur.text.find_last_not_of(" \t\r");
      if (b != std::string::npos) out.push_back({cur.line, cur.text.substr(b, e - b + 1)});
      cur = Statement{};
      depth = 0;
    } else {
      if (cur.text.empty() && (c == ' ' || c == '\t' || c == '\r')) continue;
      if (cur.text.empty()) cur.line = line;
      cur.text += c == '\n' ? ';' : c;  // a line break inside brackets ends a row
    }
    if (c == '\n') ++line;
  }
  if (cur.text.find_first_not_of(" \t\r;") != std::string::npos) out.push_back(cur);  // a bracket never closed: read, refused
  return out;
}

struct Parser {
  std::string path;
  int line = 0;

  [[noreturn]] void fail(const std::string& what) const { throw InputError(path + ":" + std::to_string(line) + ": " + what); }

  double number(const std::string& token, const std::string& field) const {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(token, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != token.size() || !std::isfinite(v))
      fail(field + ": " + detail::quoted(token) + " is not a finite number (an LP is read as numbers: no names, operators or functions but zeros)");
    return v;
  }

  Value matrix(const std::string& body, const std::string& field) const {
    Value v;
    std::vector<std::vector<double>> rows(1);
    std::string token;
    auto flush = [&] {
      if (!token.empty()) rows.back().push_back(number(token, field)), token.clear();
    };
    for (std::size_t i = 0; i < body.size(); ++i) {
      const char c = body[i];
      if ((c == '-' || c == '+') && !token.empty() && std::tolower(static_cast<unsigned char>(token.back())) != 'e')
        fail(field + ": " + detail::quoted(token + c) + "...: an operator (MATLAB reads [1-2] as -1): an LP is read as numbers");
      if (c == ' ' || c == '\t' || c == ',' || c == '\r') flush();
      else if (c == ';') {
        flush();
        if (!rows.back().empty()) rows.emplace_back();  // ";" then a line break: one row's end
      }
      else token += c;
    }
    flush();
    while (!rows.empty() && rows.back().empty()) rows.pop_back();
    const int r = int(rows.size()), cols = r ? int(rows[0].size()) : 0;
    for (const auto& row : rows)
      if (int(row.size()) != cols) fail(field + ": rows of different lengths");
    v.dims = {r, cols};
    v.data.resize(std::size_t(r) * cols);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < cols; ++j) v.data[std::size_t(j) * r + i] = rows[i][j];
    return v;
  }

  /// A whole number in [lo, hi] (an index or a size), checked before it is cast.
  int whole(const std::string& token, const std::string& field, double lo, double hi) const {
    const auto b = token.find_first_not_of(' '), e = token.find_last_not_of(' ');
    if (b == std::string::npos) fail(field + ": a size or index is missing");
    const double v = number(token.substr(b, e - b + 1), field);
    if (v < lo || v > hi || v != std::floor(v)) fail(field + ": " + detail::number(v) + " is not a whole number in [" + detail::number(lo) + ", " + detail::number(hi) + "]");
    return int(v);
  }

  Value value(std::string e, const std::string& field) const {
    bool transpose = false;
    while (!e.empty() && (e.back() == ' ')) e.pop_back();
    if (e.empty()) fail(field + ": no value after '='");
    if (e.size() > 1 && e.back() == '\'' && e[e.size() - 2] != '\'' && e.front() != '\'') transpose = true, e.pop_back();
    Value v;
    if (e.size() >= 2 && e.front() == '\'' && e.back() == '\'') {
      v.is_text = true;
      v.text = e.substr(1, e.size() - 2);
      v.dims = {1, int(v.text.size())};
      return v;
    }
    if (e.size() >= 2 && e.front() == '{' && e.back() == '}') {
      v.is_cells = true;
      for (const Statement& s : statements(e.substr(1, e.size() - 2) + ","))
        if (s.text.size() < 2 || s.text.front() != '\'' || s.text.back() != '\'') fail(field + ": a cell of names is read as {'a', 'b'}");
        else v.cells.push_back(s.text.substr(1, s.text.size() - 2));
      return v;
    }
    if (e.rfind("zeros(", 0) == 0 && e.back() == ')') {
      std::stringstream in(e.substr(6, e.size() - 7));
      std::string d;
      v.dims.clear();
      double total = 1.0;
      while (std::getline(in, d, ',')) total *= v.dims.emplace_back(whole(d, field + ": zeros(...)", 0, 100000));
      if (v.dims.size() == 1) total *= v.dims.emplace_back(v.dims[0]);
      if (v.dims.size() > 3 || total > 1e7) fail(field + ": zeros(...) of more than 3 dimensions or 1e7 numbers");
      v.data.assign(std::size_t(v.count()), 0.0);
      return v;
    }
    if (e.front() == '[' && e.back() == ']') v = matrix(e.substr(1, e.size() - 2), field);
    else v = matrix(e, field), v.dims = {1, 1};
    if (transpose && v.dims.size() == 2) {
      Value t = v;
      t.dims = {v.dims[1], v.dims[0]};
      for (int i = 0; i < v.dims[0]; ++i)
        for (int j = 0; j < v.dims[1]; ++j) t.data[std::size_t(i) * v.dims[1] + j] = v.data[std::size_t(j) * v.dims[0] + i];
      v = t;
    }
    return v;
  }
};

const std::set<std::string> known = {"num_q", "BB", "SS", "S0", "SE", "J_type", "c0", "cc", "ce", "Qi", "Qe", "m0", "m",
                                     "mass", "inertia0", "inertia", "link_names", "joint_names", "end_names"};

/// The LP's fields by name, each with the line it was set on.
std::map<std::string, Value> readFields(const std::string& path) {
  checkInputFile(path, "SpaceDyn LP file", max_input_file_bytes);
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  Parser p{path};
  std::map<std::string, Value> fields;
  for (const Statement& s : statements(text.str())) {
    p.line = s.line;
    if (s.text == "end" || s.text.rfind("function ", 0) == 0) continue;
    const auto eq = s.text.find('=');
    if (s.text.rfind("LP.", 0) != 0 || eq == std::string::npos)
      p.fail("SpaceDyn LP: " + detail::quoted(s.text.substr(0, 60)) + ": not read (an LP file is read as LP.FIELD = numbers; statements)");
    std::string target = s.text.substr(3, eq - 3);
    while (!target.empty() && target.back() == ' ') target.pop_back();
    std::string expr = s.text.substr(eq + 1);
    expr = expr.substr(std::min(expr.size(), expr.find_first_not_of(' ')));
    const std::string field = target.substr(0, target.find('('));
    if (!known.count(field)) p.fail("LP." + field + ": not a field of SpaceDyn's LP that is read (" + [] { std::string l; for (const auto& k : known) l += (l.empty() ? "" : ", ") + k; return l; }() + ")");
    if (field == "mass") continue;  // derived: m0 + sum(m)
    if (target.size() == field.size()) {
      fields[field] = p.value(expr, "LP." + field);
      fields[field].line = s.line;
      continue;
    }
    // LP.F(:,i[,j]) = a column of 3
    if (!fields.count(field)) p.fail("LP." + target + ": assigned before LP." + field + " has a size (zeros(...) first)");
    std::vector<int> index;
    if (target.size() < field.size() + 2 || target[field.size()] != '(' || target.back() != ')')
      p.fail("LP." + target + ": only a column LP.F(:,i) or LP.F(:,i,j) is read");
    std::stringstream in(target.substr(field.size() + 1, target.size() - field.size() - 2));
    std::string part;
    std::getline(in, part, ',');
    if (part != ":") p.fail("LP." + target + ": only a column LP.F(:,i) or LP.F(:,i,j) is read");
    while (std::getline(in, part, ',')) index.push_back(p.whole(part, "LP." + target, 1, 100000));
    Value& f = fields[field];
    const Value col = p.value(expr, "LP." + target);
    if (index.size() + 1 != f.dims.size() || col.count() != f.dims[0]) p.fail("LP." + target + ": index or size does not match LP." + field);
    std::size_t offset = 0, stride = std::size_t(f.dims[0]);
    for (std::size_t k = 0; k < index.size(); ++k) {
      if (index[k] < 1 || index[k] > f.dims[k + 1]) p.fail("LP." + target + ": index out of range");
      offset += std::size_t(index[k] - 1) * stride;
      stride *= std::size_t(f.dims[k + 1]);
    }
    for (int r = 0; r < f.dims[0]; ++r) f.data[offset + r] = col.data[r];
  }
  return fields;
}

/// The fields as the link system: sizes checked against num_q.
struct Lp {
  std::string path;
  std::map<std::string, Value> f;
  int n = 0;

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    const auto it = f.find(field);
    throw InputError(path + (it != f.end() ? ":" + std::to_string(it->second.line) : "") + ": LP." + field + ": " + what);
  }
  const Value& need(const std::string& field) const {
    const auto it = f.find(field);
    if (it == f.end() || it->second.is_cells || (it->second.is_text && field != "J_type"))
      throw InputError(path + ": LP." + field + ": missing (an LP gives num_q, BB, J_type, c0, cc, Qi, m0, m, inertia0, inertia)");
    return it->second;
  }
  /// Column-major numbers of `field`, which must have exactly `dims`.
  const std::vector<double>& numbers(const std::string& field, std::vector<int> dims) const {
    const Value& v = need(field);
    std::vector<int> got = v.dims;
    if (dims.size() == 2 && dims[0] == 1 && got.size() == 2 && got[1] == 1) std::swap(got[0], got[1]);  // a column for a row
    if (got != dims) {
      std::string want, have;
      for (int d : dims) want += (want.empty() ? "" : "x") + std::to_string(d);
      for (int d : v.dims) have += (have.empty() ? "" : "x") + std::to_string(d);
      fail(field, "is " + have + ", expected " + want + " for num_q = " + std::to_string(n));
    }
    return v.data;
  }
  Vector3d column(const std::string& field, int j, int cols) const {
    const auto& d = numbers(field, {3, cols});
    return {d[3 * j], d[3 * j + 1], d[3 * j + 2]};
  }
  std::vector<std::string> names(const std::string& field, std::size_t count, const std::string& fallback, int first) const {
    const auto it = f.find(field);
    std::vector<std::string> out;
    if (it != f.end()) {
      if (!it->second.is_cells || it->second.cells.size() != count)
        fail(field, "expected a cell of " + std::to_string(count) + " names");
      return it->second.cells;
    }
    for (std::size_t i = 0; i < count; ++i) out.push_back(fallback + std::to_string(first + int(i)));
    return out;
  }
};

formats::UrdfInertial inertial(double mass, const Vector3d& com, const std::vector<double>& I, std::size_t at) {
  formats::UrdfInertial in;
  in.mass = mass;
  in.origin = KDL::Frame(KDL::Vector(com.x(), com.y(), com.z()));
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) in.inertia(r, c) = I[at + std::size_t(3 * c + r)];
  return in;
}

KDL::Frame frame(const Vector3d& p, const Vector3d& angles) {
  const Eigen::Matrix3d R = formats::spaceDynRotation(angles);
  return KDL::Frame(KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
                    KDL::Vector(p.x(), p.y(), p.z()));
}

}  // namespace

std::string spaceDynToUrdf(const std::string& lp_path, std::vector<Diagnostic>& notes) {
  Lp lp{lp_path, readFields(lp_path)};
  const double n_value = lp.numbers("num_q", {1, 1})[0];
  if (n_value < 0 || n_value != std::floor(n_value) || n_value > 10000) lp.fail("num_q", "must be a whole number >= 0");
  const int n = lp.n = int(n_value);
  const auto& BB = lp.numbers("BB", {1, n});
  const Value& J = lp.need("J_type");
  if (!J.is_text || int(J.text.size()) != n) lp.fail("J_type", "expected " + std::to_string(n) + " characters 'R' or 'P'");
  const auto& m = lp.numbers("m", {1, n});
  const auto& inertia = lp.numbers("inertia", {3, 3 * n});
  lp.numbers("cc", {3, n, n});
  lp.numbers("Qi", {3, n});
  lp.numbers("c0", {3, n});
  const bool ends = lp.f.count("SE");
  const auto& SE = ends ? lp.numbers("SE", {1, n}) : std::vector<double>(std::size_t(n), 0.0);
  if (ends) lp.numbers("ce", {3, n}), lp.numbers("Qe", {3, n});
  int end_count = 0;
  for (double e : SE) end_count += e != 0.0;
  const auto links = lp.names("link_names", std::size_t(n) + 1, "link", 0);
  const auto joint_names = lp.names("joint_names", std::size_t(n), "joint", 1);
  const auto end_names = lp.names("end_names", std::size_t(end_count), "end", 1);
  const double m0 = lp.numbers("m0", {1, 1})[0];
  std::vector<formats::UrdfLink> out{{lp.f.count("link_names") ? links[0] : "base", inertial(m0, Vector3d::Zero(), lp.numbers("inertia0", {3, 3}), 0), {}}};
  std::vector<formats::UrdfJoint> joints;
  auto cc = [&](int i, int j) {  // cc(:,i,j), 1-based
    const auto& d = lp.numbers("cc", {3, n, n});
    const std::size_t at = 3 * (std::size_t(i - 1) + std::size_t(n) * std::size_t(j - 1));
    return Vector3d(d[at], d[at + 1], d[at + 2]);
  };
  auto name = [&](int i) { return i == 0 ? out[0].name : links[std::size_t(i)]; };
  int end = 0;
  for (int i = 1; i <= n; ++i) {
    const int b = int(BB[std::size_t(i - 1)]);
    if (b < 0 || b >= i || b != BB[std::size_t(i - 1)]) lp.fail("BB", "BB(" + std::to_string(i) + ") = " + detail::number(BB[std::size_t(i - 1)]) +
                                                               ": each link hangs on the base (0) or on a link numbered before it");
    if (m[std::size_t(i - 1)] < 0.0) lp.fail("m", "m(" + std::to_string(i) + ") < 0");
    const char t = J.text[std::size_t(i - 1)];
    if (t != 'R' && t != 'P') lp.fail("J_type", std::string("joint ") + std::to_string(i) + " is '" + t + "': 'R' or 'P'");
    formats::UrdfJoint j;
    j.name = joint_names[std::size_t(i - 1)];
    j.parent = name(b);
    j.child = links[std::size_t(i)];
    j.type = t == 'R' ? "continuous" : "prismatic";
    const Vector3d at = b == 0 ? lp.column("c0", i - 1, n) : Vector3d(cc(b, i) - cc(b, b));
    j.origin = frame(at, lp.column("Qi", i - 1, n));
    if (t == 'P') {
      j.properties.lower = -1e9, j.properties.upper = 1e9;
      notes.push_back({j.name, "an LP gives no limits: the prismatic joint is given +-1e9 m (URDF requires limits)", "", Severity::Note});
    }
    joints.push_back(j);
    out.push_back({j.child, inertial(m[std::size_t(i - 1)], -cc(i, i), inertia, 9 * std::size_t(i - 1)), {}});
    if (SE[std::size_t(i - 1)] != 0.0) {
      formats::UrdfJoint e;
      e.name = end_names[std::size_t(end)] + "_joint";
      e.type = "fixed";
      e.parent = j.child;
      e.child = end_names[std::size_t(end++)];
      e.origin = frame(lp.column("ce", i - 1, n) - cc(i, i), lp.column("Qe", i - 1, n));
      joints.push_back(e);
      out.push_back({e.child, std::nullopt, {}});
    }
  }
  return formats::urdfText(std::filesystem::path(lp_path).stem().string(), out, joints);
}

}  // namespace kdl_space
