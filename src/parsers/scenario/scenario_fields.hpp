// The scenario loader's field reader: a YAML node with its dotted path ("target.inertia[1]") and
// its file, whose reads check the value and throw InputError "FILE:LINE: PATH: what is wrong".
// Private to the library (yaml-cpp is a private dependency).
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <kdl/frames.hpp>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include "spatial/message_text.hpp"

namespace kdl_space::fields {

/// A text from the file, quoted for a message (spatial/message_text.hpp).
using detail::echo;

/// The largest scenario or study file (YAML or JSON) parseFile reads: 16 MiB. Such files are
/// kilobytes; yaml-cpp holds ~55 bytes of nodes per byte of a file (a 5 MB mapping of 200,000 keys
/// takes 300 MB), so this bounds the parse to about 1 GB (max_input_file_bytes, 64 MiB, would
/// allow 3.5 GB).
inline constexpr std::uintmax_t max_yaml_file_bytes = std::uintmax_t{16} << 20;

/// A file's YAML (or JSON, which YAML reads), or an InputError "FILE[:LINE]: what is wrong";
/// `kind` names what the file should be ("scenario file (YAML or JSON)").
YAML::Node parseFile(const std::string& file, const std::string& kind);

/// What a YAML node is, for messages ("no value", "a list of 2", "a mapping", or its text).
std::string kindOf(const YAML::Node& node);

/// A YAML node with its dotted path, for messages that name the field.
class Field {
 public:
  /// `file` names the file in messages; it must outlive the Field.
  Field(YAML::Node node, std::string path, const std::string* file);

  /// Throws InputError "FILE[:LINE]: PATH: what".
  [[noreturn]] void fail(const std::string& what) const;
  /// "FILE[:LINE]: PATH: ", what fail() puts in front: the context a caller adds to an Error of
  /// another part (a URDF's ModelError) that this field brought in (Error::rethrowWithContext).
  std::string where() const;
  /// The key is present (with a value or without: at() reports "has no value").
  bool has(const std::string& key) const;
  /// The value of a required key ("missing (a required field)", "has no value").
  Field at(const std::string& key) const;
  /// Refuses keys not in `keys`, keys given twice and keys that are not names.
  void onlyKeys(std::initializer_list<const char*> keys) const;
  /// The keys of a mapping, in file order; refuses a key given twice or one that is not a name.
  std::vector<std::string> keys() const;
  struct Entry;
  /// The keys of a mapping with their values, in file order, checked as keys() (O(n) for n keys:
  /// at() searches the mapping, so a loop of at() over a large mapping would be O(n^2)).
  std::vector<Entry> entries() const;

  std::string text() const;
  /// A finite number, read by readNumber (input_file.hpp); YAML's .inf and .nan are refused as not finite.
  double number() const;
  /// A list of `size` finite numbers.
  Eigen::VectorXd vector(int size) const;
  /// \brief An angle [rad], or an angular rate [rad/s] when `rate`: a number in SI, or the same
  /// in degrees as `{deg: 30}` (`{deg_per_s: 5}` for a rate), converted here (outputs stay SI).
  double angle(bool rate = false) const;
  /// `size` angles [rad] (roll, pitch, yaw): a list of numbers, or `{deg: [r, p, y]}`.
  Eigen::VectorXd angles(int size) const;
  /// 3 rows of 3 finite numbers.
  Eigen::Matrix3d matrix3() const;
  /// The items of a list, each with its path PATH[i] ("expected a list of `what`, got ..." else).
  std::vector<Field> items(const std::string& what) const;
  /// true or false.
  bool flag() const;
  /// A number, or a list of 3 (one value for three axes).
  Eigen::Vector3d perAxis() const;

  const std::string& path() const { return path_; }
  bool isScalar() const { return node_.IsScalar(); }
  bool isSequence() const { return node_.IsSequence(); }
  bool isMap() const { return node_.IsMap(); }
  /// Throws "PATH: expected `expected`, got WHAT IT IS".
  [[noreturn]] void failKind(const std::string& expected) const { fail("expected " + expected + ", got " + kindOf(node_)); }

 private:
  /// path.key, the key cut to a readable length (detail::cut).
  std::string join(const std::string& key) const;
  Field child(const YAML::Node& node, const std::string& path) const { return Field(node, path, file_); }
  YAML::Node node_;
  std::string path_;
  const std::string* file_;
};

/// A pose from optional `position` and `rpy` fields of f (URDF convention; rpy in rad or {deg: [...]}).
KDL::Frame pose(const Field& f);

/// A key of a mapping and its value (Field::entries).
struct Field::Entry {
  std::string name;
  Field key;    ///< the key: its line is where a key without a value is reported
  Field value;  ///< its value (no value: a null node)
  /// The value, or "PATH: has no value" at the key's line, as Field::at.
  const Field& required() const;
};

}  // namespace kdl_space::fields
