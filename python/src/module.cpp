// The extension module kdl_space._kdl_space: one binding file per concept (errors, model and
// state, solvers, impact laws, capture, forward dynamics, simulation, studies); the package kdl_space
// (python/kdl_space) re-exports it.
#include "conversions.hpp"
#include "expose_html.hpp"

PYBIND11_MODULE(_kdl_space, m) {
  m.doc() = "Free-floating space manipulator dynamics (kdl_space, Yoshida et al.): the C++ library's "
            "models, solvers (J*, H*, G*), impact laws, captures, forward dynamics, the simulator and capture studies, "
            "NumPy in and out, world frame, twist (v; w), wrench (f; n).";
  using namespace kdl_space::python;
  bindErrors(m);
  bindModel(m);
  bindPoses(m);
  bindSolvers(m);
  bindImpact(m);
  bindCapture(m);
  bindForwardDynamics(m);
  bindSimulation(m);
  bindStudy(m);
  bindOperation(m);
  bindHtml(m);
  bindInverseKinematics(m);
  bindPlanning(m);
  bindFormats(m);
}
