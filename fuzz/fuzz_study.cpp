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
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "kdl_space/study/study.hpp"

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
  std::string pattern = (fs::temp_directory_path() / "kdl_space_fuzz_study.XXXXXX").string();
  if (!mkdtemp(pattern.data())) {
    std::cerr << "fuzz_study: cannot create a temporary folder\n";
    std::abort();
  }
  g_root = pattern;
  std::atexit(removeRoot);
  fs::create_directories(g_root / "scenarios");
  fs::create_directory_symlink(KDL_SPACE_URDF_DIR, g_root / "urdf");
  for (const fs::directory_entry& e : fs::directory_iterator(KDL_SPACE_SCENARIOS_DIR))
    if (e.is_regular_file()) fs::create_symlink(e.path(), g_root / "scenarios" / e.path().filename());
  g_input = (g_root / "scenarios" / "input.yaml").string();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  {
    std::ofstream out(g_input, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) {
      std::cerr << "fuzz_study: cannot write " << g_input << "\n";
      std::abort();
    }
  }
  try {
    const kdl_space::Study study = kdl_space::loadStudy(g_input);
    // What a run asks of a loaded study first: its columns (the loader's promise that they exist).
    (void)kdl_space::studyColumns(study);
  } catch (const kdl_space::Error&) {
    // A refused study (InputError, or a scenario's URDF's ModelError): the expected outcome for most inputs.
  }
  return 0;
}
