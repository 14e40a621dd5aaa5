#include "parsers/scenario/scenario_fields.hpp"

#include <yaml-cpp/depthguard.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <cmath>
#include <unordered_set>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/multibody/state.hpp"
#include "kdl_space/parsers/input_file.hpp"

namespace kdl_space::fields {
namespace {

/// YAML's names of the numbers that are not finite: .inf, .nan (and their signed and capitalised
/// forms: .Inf, -.INF, .NaN, ...).
bool yamlNotFinite(const std::string& text) {
  std::string t = text.empty() || (text[0] != '+' && text[0] != '-') ? text : text.substr(1);
  if (t == ".inf" || t == ".Inf" || t == ".INF") return true;
  return t == ".nan" || t == ".NaN" || t == ".NAN";
}

/// "a key of N characters at line L: YAML reads keys of at most 1024 (...)" when the file has
/// a quoted key (JSON's are) longer than YAML's limit on an implicit key, else "".
std::string longKey(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::size_t line = 1;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n') ++line;
    if (text[i] != '"') continue;
    std::size_t end = i + 1;
    while (end < text.size() && text[end] != '"' && text[end] != '\n') end += text[end] == '\\' ? 2 : 1;
    if (end >= text.size() || text[end] != '"') continue;
    std::size_t colon = end + 1;
    while (colon < text.size() && (text[colon] == ' ' || text[colon] == '\t')) ++colon;
    if (colon < text.size() && text[colon] == ':' && end - i - 1 > 1024)
      return "a key of " + std::to_string(end - i - 1) + " characters at line " + std::to_string(line) +
             ": YAML reads keys of at most 1024 (the scenario's keys are short names: is it the right file?)";
    i = end;
  }
  return "";
}

}  // namespace

YAML::Node parseFile(const std::string& file, const std::string& kind) {
  checkInputFile(file, kind, max_yaml_file_bytes);  // before it is read: it bounds yaml-cpp's memory too
  try {
    return YAML::LoadFile(file);
  } catch (const YAML::BadFile&) {
    throw InputError(file + ": cannot open the file");
  } catch (const YAML::DeepRecursion& e) {  // yaml-cpp says "bad file"
    throw InputError(file + ":" + std::to_string(e.mark.line + 1) + ": nested " + std::to_string(e.depth()) +
                     " levels deep, deeper than the reader follows (a scenario nests 4 or 5): is it the right file?");
  } catch (const YAML::Exception& e) {
    std::string msg;  // yaml-cpp quotes the offending byte: keep it printable
    for (const char c : e.msg) msg += static_cast<unsigned char>(c) >= 0x20 && static_cast<unsigned char>(c) < 0x7f ? c : '?';
    if (const std::string key = longKey(file); !key.empty())  // yaml-cpp: "end of map flow not found"
      throw InputError(file + ": not valid YAML or JSON: " + key);
    throw InputError(file + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML or JSON: " + detail::cut(msg));
  } catch (const std::exception& e) {
    throw InputError(file + ": cannot read the file: " + e.what());
  }
}

std::string kindOf(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "no value";
  if (node.IsSequence()) return "a list of " + std::to_string(node.size());
  if (node.IsMap()) return "a mapping";
  return echo(node.Scalar());
}

Field::Field(YAML::Node node, std::string path, const std::string* file)
    : node_(std::move(node)), path_(std::move(path)), file_(file) {}

std::string Field::join(const std::string& key) const {
  const std::string shown = detail::cut(key);  // a key of megabytes named in a message
  return path_.empty() ? shown : path_ + "." + shown;
}

std::string Field::where() const {
  std::string where = *file_;
  if (node_.IsDefined() && node_.Mark().line >= 0) where += ":" + std::to_string(node_.Mark().line + 1);
  return where + ": " + (path_.empty() ? "" : path_ + ": ");
}

void Field::fail(const std::string& what) const { throw InputError(where() + what); }

bool Field::has(const std::string& key) const { return node_.IsMap() && node_[key].IsDefined(); }

Field Field::at(const std::string& key) const {
  if (!node_.IsMap()) fail("expected a mapping, got " + kindOf(node_));
  const std::string path = join(key);
  if (!has(key)) child(node_, path).fail("missing (a required field)");
  const Field f = child(node_[key], path);
  if (node_[key].IsNull()) {
    for (const auto& item : node_)  // the key's line: a missing value has none of its own
      if (item.first.IsScalar() && item.first.Scalar() == key) child(item.first, path).fail("has no value");
    f.fail("has no value");
  }
  return f;
}

void Field::onlyKeys(std::initializer_list<const char*> allowed) const {
  std::string expected;
  for (const char* k : allowed) expected += (expected.empty() ? "" : ", ") + std::string(k);
  for (const Entry& e : entries()) {  // a mapping, no key twice
    const bool known = std::any_of(allowed.begin(), allowed.end(), [&](const char* a) { return e.name == a; });
    if (!known) e.key.fail("unknown field (expected one of " + expected + ")");
  }
}

std::vector<Field::Entry> Field::entries() const {
  if (!node_.IsMap()) fail("expected a mapping, got " + kindOf(node_));
  std::vector<Entry> list;
  // The keys seen, hashed: O(n) for n keys (a search of the list for each key was O(n^2):
  // 40,000 keys took 15 s, 200,000 would take minutes).
  std::unordered_set<std::string> seen;
  for (const auto& item : node_) {
    if (!item.first.IsScalar()) child(item.first, path_).fail("a field name must be a text, got " + kindOf(item.first));
    const std::string& name = item.first.Scalar();
    const Field key = child(item.first, join(name));
    if (!seen.insert(name).second) key.fail("given twice");
    list.push_back(Entry{name, key, child(item.second, key.path_)});
  }
  return list;
}

const Field& Field::Entry::required() const {
  if (!value.node_.IsDefined() || value.node_.IsNull()) key.fail("has no value");
  return value;
}

std::vector<std::string> Field::keys() const {
  std::vector<std::string> k;
  for (Entry& e : entries()) k.push_back(std::move(e.name));
  return k;
}

std::string Field::text() const {
  if (!node_.IsScalar()) fail("expected a text value, got " + kindOf(node_));
  return node_.Scalar();
}

double Field::number() const {
  if (!node_.IsScalar()) fail("expected a number, got " + kindOf(node_));
  const std::string& text = node_.Scalar();
  double v = 0.0;
  const NumberText read = readNumber(text, v);
  if (read == NumberText::Finite) return v;
  if (read == NumberText::TooLarge) fail(echo(text) + " is too large (not a finite number)");
  if (read == NumberText::NotFinite || yamlNotFinite(text)) fail(echo(text) + " is not a finite number");
  fail(echo(text) + " is not a number");
}

Eigen::VectorXd Field::vector(int size) const {
  if (!node_.IsSequence() || static_cast<int>(node_.size()) != size)
    fail("expected a list of " + std::to_string(size) + " numbers, got " + kindOf(node_));
  Eigen::VectorXd v(size);
  for (int i = 0; i < size; ++i) v(i) = child(node_[i], path_ + "[" + std::to_string(i) + "]").number();
  return v;
}

namespace {
constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;
}  // namespace

double Field::angle(bool rate) const {
  const char* unit = rate ? "deg_per_s" : "deg";
  if (!node_.IsMap()) {
    if (!node_.IsScalar())
      fail("expected " + std::string(rate ? "an angular rate [rad/s]" : "an angle [rad]") + ", or {" + unit +
           ": VALUE}, got " + kindOf(node_));
    return number();
  }
  onlyKeys({unit});
  return at(unit).number() * kRadPerDeg;
}

Eigen::VectorXd Field::angles(int size) const {
  if (!node_.IsMap()) return vector(size);
  onlyKeys({"deg"});
  return at("deg").vector(size) * kRadPerDeg;
}

Eigen::Matrix3d Field::matrix3() const {
  if (!node_.IsSequence() || node_.size() != 3) fail("expected 3 rows of 3 numbers, got " + kindOf(node_));
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i) m.row(i) = child(node_[i], path_ + "[" + std::to_string(i) + "]").vector(3);
  return m;
}

std::vector<Field> Field::items(const std::string& what) const {
  if (!node_.IsSequence()) fail("expected a list of " + what + ", got " + kindOf(node_));
  std::vector<Field> list;
  for (std::size_t i = 0; i < node_.size(); ++i) list.push_back(child(node_[i], path_ + "[" + std::to_string(i) + "]"));
  return list;
}

bool Field::flag() const {
  const std::string t = text();
  if (t == "true") return true;
  if (t == "false") return false;
  fail(echo(t) + " is not one of true, false");
}

Eigen::Vector3d Field::perAxis() const {
  if (node_.IsSequence()) return vector(3);
  return Eigen::Vector3d::Constant(number());
}

KDL::Frame pose(const Field& f) {
  const Eigen::VectorXd p = f.has("position") ? f.at("position").vector(3) : Eigen::VectorXd::Zero(3);
  const Eigen::VectorXd r = f.has("rpy") ? f.at("rpy").angles(3) : Eigen::VectorXd::Zero(3);
  return basePose(KDL::Vector(p(0), p(1), p(2)), r(0), r(1), r(2));
}

}  // namespace kdl_space::fields
