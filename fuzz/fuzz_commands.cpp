// libFuzzer target: the commands, not only the readers. A scenario's text (mutated from seeds over
// the model families of tests/data/families/: no joints, one prismatic, a chain, continuous
// joints, a tree, a mimic gripper, massless parts) -> loadScenario, then the library calls behind
// `inspect` (J*, G*, the grounded and locked G, the conditioning and the configuration's warnings
// at the contact), `capture` (solveCapture), `ik` (the contact frame to the target's frame) and
// `plan` (a small scan).
// Expected outcomes: each call's result, a non-zero code, or a kdl_space::Error (InputError,
// ModelError, IkUnreachable) with a message. Anything else -- a crash, another exception, a
// sanitizer report, a hang -- is a bug; what it finds becomes a regression test
// (tests/data/fuzz_regressions/commands/, run by test_fuzz_regressions.cpp).
//
// Each input is written to <tmp>/scenarios/input.yaml; <tmp>/families links to the families'
// folder, so that the seeds' "../families/NAME.urdf" load.
#include <cstddef>
#include <cstdint>
#include <memory>

#include "commands_driver.hpp"
#include "input_folder.hpp"

namespace {
std::unique_ptr<kdl_space::fuzz::InputFolder> g_folder;
}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  g_folder = std::make_unique<kdl_space::fuzz::InputFolder>(
      "commands", std::vector<std::pair<std::string, std::filesystem::path>>{{"families", KDL_SPACE_FAMILIES_DIR}});
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  kdl_space::fuzz::driveCommands(g_folder->write(data, size));
  return 0;
}
