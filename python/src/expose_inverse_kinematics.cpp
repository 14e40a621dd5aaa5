// kdl_space.inverse_kinematics: the joint angles that put a contact frame at a world pose (the
// library's solveInverseKinematics); a dict of the solution; InputError, with the best attempt's
// residuals and angles as attributes, when the pose is out of reach.
#include "capture_types.hpp"
#include "conversions.hpp"
#include "json_objects.hpp"
#include "kdl_space/report/ik_json.hpp"
#include "kdl_space/algorithm/inverse_kinematics.hpp"
#include "simulation_types.hpp"

namespace kdl_space::python {
namespace {

/// The CLI's JSON keys (ikSolutionJson), q as a NumPy array.
py::dict solutionDict(const FloatingModel& model, const IkResult& r) {
  py::dict d = toPython(report::ikSolutionJson(model, r));
  d["q"] = toNumpyVec(r.q.data);
  return d;
}

/// Solves, the GIL released; an unreachable pose raises kdl_space.InputError carrying the best
/// attempt (position_residual, orientation_residual, q, q_by_name).
py::dict solve(const std::shared_ptr<const FloatingModel>& model, const State& seed, const Contact& contact, py::handle goal,
               py::handle preferred, const std::string& prefer, double position_tolerance, double orientation_tolerance,
               unsigned int restarts, unsigned int max_iterations) {
  const KDL::Frame world_T_goal = frameFromPython(goal, "goal");
  IkOptions o;
  o.position_tolerance = position_tolerance;
  o.orientation_tolerance = orientation_tolerance;
  o.restarts = restarts;
  o.max_iterations = max_iterations;
  o.cancelled = SignalPoll();  // Ctrl-C: a KeyboardInterrupt within about 0.1 s
  if (prefer != "posture" && prefer != "reaction")
    throw py::value_error("prefer: '" + prefer + "' is neither 'posture' nor 'reaction'");
  o.prefer = prefer == "reaction" ? IkPreference::Reaction : IkPreference::Posture;
  if (!preferred.is_none() && o.prefer == IkPreference::Reaction)
    throw py::value_error("preferred: a posture is for prefer='posture'; prefer='reaction' minimises the base's reaction");
  if (!preferred.is_none()) {
    // A dict names only some joints: the others keep the seed's angle (not 0).
    KDL::JntArray p = seed.q;
    if (py::isinstance<py::dict>(preferred)) {
      for (const auto& [key, value] : argumentAs<py::dict>(preferred, "preferred", "a dict of joint angles or an array")) {
        const std::string name = py::str(key);
        const int j = model->jointIndex(name);
        if (j < 0) throw py::value_error("preferred: the model has no movable joint '" + name + "'");
        p(j) = argumentAs<double>(value, "preferred['" + name + "']", "a number");
      }
    } else {
      p = jointValues(*model, preferred, "preferred");
    }
    o.preferred = p;
  }
  try {
    const IkResult r = [&] {
      py::gil_scoped_release nogil;
      return solveInverseKinematics(*model, seed, contact, world_T_goal, o);
    }();
    return solutionDict(*model, r);
  } catch (const IkUnreachable& e) {
    const py::dict best = solutionDict(*model, e.best());
    py::object type = py::module_::import("kdl_space._kdl_space").attr("InputError");
    py::object error = type(e.what());
    for (const char* key : {"position_residual", "orientation_residual", "q", "q_by_name", "attempts"})
      error.attr(key) = best[key];
    PyErr_SetObject(type.ptr(), error.ptr());
    throw py::error_already_set();
  }
}

}  // namespace

void bindInverseKinematics(py::module_& m) {
  const char* doc =
      "The joint angles that put the contact frame (the contact link's axes, origin at its offset) at the world pose "
      "`goal` (a 4x4 matrix, or (position, rpy)), the base where the state (or the scenario's robot) puts it, every joint "
      "inside its limits. preferred: a redundant arm's posture to stay closest to (array (nj,) or dict name -> value; "
      "default the state's q). prefer: 'posture' (that) or 'reaction' (the self-motion solution from which a unit hand "
      "motion turns the base least: the least reaction_measure, || W J_h^+ ||_F, W the base's angular rows of J*). Returns a dict: q (nj,), q_by_name, joint_names, moved_joints, position_residual [m], "
      "orientation_residual [rad], iterations, attempts, preference_gradient, reaction_measure. Raises InputError when the pose is out of "
      "reach: its message says how far the best attempt came; the error's position_residual, orientation_residual, q, "
      "q_by_name and attempts are that attempt's.";
  m.def(
      "inverse_kinematics",
      [](const PyState& state, const PyContact& contact, py::object goal, py::object preferred, const std::string& prefer,
         double position_tolerance, double orientation_tolerance, unsigned int restarts, unsigned int max_iterations) {
        checkContact(*state.model, contact);
        return solve(state.model, state.state, contact.contact, goal, preferred, prefer, position_tolerance, orientation_tolerance,
                     restarts, max_iterations);
      },
      py::arg("state"), py::arg("contact"), py::arg("goal"), py::kw_only(), py::arg("preferred") = py::none(),
      py::arg("prefer") = "posture", py::arg("position_tolerance") = 1e-10, py::arg("orientation_tolerance") = 1e-10, py::arg("restarts") = 16,
      py::arg("max_iterations") = 500, doc);
  m.def(
      "inverse_kinematics",
      [](const ScenarioArg& s, py::object goal, py::object preferred, const std::string& prefer,
         double position_tolerance, double orientation_tolerance, unsigned int restarts, unsigned int max_iterations) {
        const FloatingSystem& robot = s.get().capture.robot;
        return solve(robot.model, robot.state, robot.contact, goal, preferred, prefer, position_tolerance, orientation_tolerance,
                     restarts, max_iterations);
      },
      py::arg("scenario"), py::arg("goal"), py::kw_only(), py::arg("preferred") = py::none(),
      py::arg("prefer") = "posture", py::arg("position_tolerance") = 1e-10, py::arg("orientation_tolerance") = 1e-10, py::arg("restarts") = 16,
      py::arg("max_iterations") = 500, doc);
}

}  // namespace kdl_space::python
