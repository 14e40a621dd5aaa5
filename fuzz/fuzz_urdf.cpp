// libFuzzer target: URDF text -> kdl_space::loadUrdfString -> both G* solvers at the zero state;
// and the same text -> kdl_space::checkUrdfString (`kdl_space check`), which never throws.
// Expected outcomes: a model, or kdl_space::ModelError (a clean refusal); a report. Anything
// else -- a crash, another exception, a sanitizer report, a hang or a runaway allocation -- is a
// bug, and so is a report without errors for a text the loader refuses.
// Built by KDL_SPACE_FUZZ=ON, run by tools/fuzz.sh on fuzz/corpus/urdf/ with fuzz/urdf.dict.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "kdl_space/spatial/errors.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/recursive_ex_iit.hpp"
#include "kdl_space/multibody/state.hpp"
#include "kdl_space/parsers/urdf/urdf_check.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace kdl_space;
  const std::string xml(reinterpret_cast<const char*>(data), size);
  bool loaded = false;
  try {
    const auto model = std::make_shared<const FloatingModel>(loadUrdfString(xml, "fuzz.urdf"));
    const State state(*model);  // base at the origin, joints at 0
    Contact h;
    h.body = static_cast<int>(model->bodies().size()) - 1;  // the last body
    h.offset = KDL::Vector(0.1, -0.2, 0.3);
    Matrix6d G;
    // Compute calls return codes (a massless or singular model is refused with a code): only
    // the absence of crashes, exceptions and sanitizer reports is checked.
    FreeFloatingSolver dense(model);
    if (dense.compute(state) == E_NOERROR) {
      dense.G_star(h, G);
      dense.G(h, Response::Grounded, G);
      dense.G(h, Response::JointsLocked, G);
    }
    RecursiveExIITSolver recursive(model);
    if (recursive.compute(state) == E_NOERROR) recursive.G_star(h, G);
    loaded = true;
  } catch (const ModelError&) {
    // A refused model: the expected outcome for most inputs.
  }
  // The checker applies the loader's rules ("a file without errors loads").
  const UrdfReport report = checkUrdfString(xml, "fuzz.urdf");
  if (!loaded && report.errors.empty()) {
    std::fprintf(stderr, "fuzz_urdf: the loader refuses this text, checkUrdfString reports no error\n");
    std::abort();
  }
  return 0;
}
