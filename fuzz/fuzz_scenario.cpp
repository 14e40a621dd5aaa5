// libFuzzer target: scenario text (YAML or JSON) -> kdl_space::loadScenario, the library's
// loader that `kdl_space capture` and `simulate` call.
// Expected outcomes: a scenario, or kdl_space::InputError naming the file and the field (a
// URDF it names that loads no model: the loader's ModelError, the same file and field in front)
// (scenario.hpp's contract). Anything else -- a crash, another exception, a sanitizer report, a
// hang -- is a bug. Built by KDL_SPACE_FUZZ=ON, run by tools/fuzz.sh on fuzz/corpus/scenario/.
//
// The parser reads a file and resolves URDF paths relative to its folder: each input is written
// to <tmp>/scenarios/input.yaml, where <tmp>/urdf and <tmp>/reference/models link to the bundled
// and the reference models, so that the seeds' "../urdf/..." and "../reference/models/..." load.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "kdl_space/parsers/scenario/scenario.hpp"

namespace {
namespace fs = std::filesystem;
fs::path g_root;
std::string g_input;

void removeRoot() {
  std::error_code ec;
  if (!g_root.empty()) fs::remove_all(g_root, ec);
}
}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::string pattern = (fs::temp_directory_path() / "kdl_space_fuzz_scenario.XXXXXX").string();
  if (!mkdtemp(pattern.data())) {
    std::cerr << "fuzz_scenario: cannot create a temporary folder\n";
    std::abort();
  }
  g_root = pattern;
  std::atexit(removeRoot);
  fs::create_directories(g_root / "scenarios");
  fs::create_directories(g_root / "reference");
  fs::create_directory_symlink(KDL_SPACE_URDF_DIR, g_root / "urdf");
  fs::create_directory_symlink(KDL_SPACE_REFERENCE_MODELS_DIR, g_root / "reference" / "models");
  g_input = (g_root / "scenarios" / "input.yaml").string();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  {
    std::ofstream out(g_input, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) {
      std::cerr << "fuzz_scenario: cannot write " << g_input << "\n";
      std::abort();
    }
  }
  try {
    kdl_space::loadScenario(g_input);
  } catch (const kdl_space::Error&) {
    // A refused scenario (InputError, or a URDF's ModelError): the expected outcome for most inputs.
  }
  return 0;
}
