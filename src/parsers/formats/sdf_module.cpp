// sdfToUrdf: loads the SDF module (sdf_module.hpp) on the first SDF file, then writes what it read
// as one URDF document.
#include <dlfcn.h>

#include <filesystem>
#include <mutex>

#include "kdl_space/parsers/formats/sdf_reader.hpp"
#include "kdl_space/spatial/errors.hpp"
#include "parsers/formats/sdf_module.hpp"

namespace kdl_space {
namespace {

/// The module's entry: from the directory of the object this code is in (libkdl_space.so, where
/// the build and the install put the module), else by the loader's search (the RUNPATH of the
/// executable that links these objects itself: the test suites). Loaded once, never unloaded.
formats::ReadSdf sdfEntry() {
  static std::once_flag once;
  static formats::ReadSdf entry = nullptr;
  static std::string why;
  std::call_once(once, [] {
    std::vector<std::string> candidates;
    Dl_info self{};
    if (dladdr(reinterpret_cast<const void*>(&sdfToUrdf), &self) && self.dli_fname)
      candidates.push_back((std::filesystem::path(self.dli_fname).parent_path() / formats::sdf_module_file).string());
    candidates.push_back(formats::sdf_module_file);
    for (const std::string& file : candidates) {
      void* module = dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!module) {
        why += std::string(why.empty() ? "" : "; ") + dlerror();
        continue;
      }
      entry = reinterpret_cast<formats::ReadSdf>(dlsym(module, formats::sdf_entry_name));
      if (entry) return;
      why += std::string(why.empty() ? "" : "; ") + file + ": no " + formats::sdf_entry_name;
    }
  });
  if (!entry)
    throw InputError(std::string("reading SDF needs kdl_space's module ") + formats::sdf_module_file +
                     " beside libkdl_space.so (installed with it): " + why);
  return entry;
}

}  // namespace

std::string sdfToUrdf(const std::string& path, std::vector<Diagnostic>& notes) {
  formats::SdfModel model;
  sdfEntry()(path, notes, model);
  return formats::urdfText(model.name, model.links, model.joints);
}

}  // namespace kdl_space
