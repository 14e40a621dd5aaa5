// libFuzzer target: study text (YAML or JSON) -> kdl_space::loadStudy, the library's loader that
// `kdl_space study` and kdl_space.study() call (it loads the scenario the study names too).
// Expected outcomes: a study, or kdl_space::InputError naming the file and the field (a scenario
// or URDF it names that loads no model: that loader's Error, the field in front) (study.hpp's
// contract). Anything else -- a crash, another exception, a sanitizer report, a hang -- is a bug.
// Built by KDL_SPACE_FUZZ=ON, run by tools/fuzz.sh on fuzz/corpus/study/.
//
// The loader reads a file and resolves the scenario relative to its folder: each input is written
// to <tmp>/scenarios/input.yaml beside links to the bundled scenarios (whose "../urdf/..." reach
// <tmp>/urdf, a link to the bundled models), so the seeds' `scenario: tumbling_box_capture.yaml`
// loads.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>

#include "input_folder.hpp"
#include "kdl_space/study/study.hpp"

namespace {
std::unique_ptr<kdl_space::fuzz::InputFolder> g_folder;
}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::vector<std::pair<std::string, std::filesystem::path>> links{{"urdf", KDL_SPACE_URDF_DIR}};
  for (const std::filesystem::directory_entry& e : std::filesystem::directory_iterator(KDL_SPACE_SCENARIOS_DIR))
    if (e.is_regular_file()) links.emplace_back("scenarios/" + e.path().filename().string(), e.path());
  g_folder = std::make_unique<kdl_space::fuzz::InputFolder>("study", links);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const kdl_space::Study study = kdl_space::loadStudy(g_folder->write(data, size));
    // What a run asks of a loaded study first: its columns (the loader's promise that they exist).
    (void)kdl_space::studyColumns(study);
  } catch (const kdl_space::Error&) {
    // A refused study (InputError, or a scenario's URDF's ModelError): the expected outcome for most inputs.
  }
  return 0;
}
