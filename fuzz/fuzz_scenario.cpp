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
#include <cstddef>
#include <cstdint>
#include <memory>

#include "input_folder.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"

namespace {
std::unique_ptr<kdl_space::fuzz::InputFolder> g_folder;
}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  g_folder = std::make_unique<kdl_space::fuzz::InputFolder>(
      "scenario", std::vector<std::pair<std::string, std::filesystem::path>>{
                      {"urdf", KDL_SPACE_URDF_DIR}, {"reference/models", KDL_SPACE_REFERENCE_MODELS_DIR}});
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    kdl_space::loadScenario(g_folder->write(data, size));
  } catch (const kdl_space::Error&) {
    // A refused scenario (InputError, or a URDF's ModelError): the expected outcome for most inputs.
  }
  return 0;
}
