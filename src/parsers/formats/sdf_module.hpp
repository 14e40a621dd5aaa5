// The SDF reader is a module of its own, libkdl_space_sdf.so, loaded when an SDF file is first read
// (sdf_module.cpp): SDFormat and Ignition Math, which it links, cost every process that loads them
// ~60 ms of static initialisation (~0.3 s under AddressSanitizer), and most never read an SDF file.
// What the module and the library share: the model it reads and the one function it exports.
#pragma once

#include <string>
#include <vector>

#include "kdl_space/multibody/diagnostics.hpp"
#include "parsers/formats/urdf_builder.hpp"

namespace kdl_space::formats {

/// One SDF <model> as the links and joints of a URDF document (urdfText writes it).
struct SdfModel {
  std::string name;
  std::vector<UrdfLink> links;
  std::vector<UrdfJoint> joints;
};

/// The module's entry, exported with C linkage under `sdf_entry_name`: reads `path` into `model`,
/// appends what it assumed to `notes`; throws InputError (the library's class) on a refusal.
using ReadSdf = void (*)(const std::string& path, std::vector<Diagnostic>& notes, SdfModel& model);
inline constexpr const char* sdf_entry_name = "kdl_space_read_sdf";
inline constexpr const char* sdf_module_file = "libkdl_space_sdf.so";

}  // namespace kdl_space::formats
