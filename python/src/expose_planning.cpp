// kdl_space.plan_capture: the library's planCapture on a scenario (a path or a Scenario), a
// CapturePlan object with the fields of `kdl_space plan --json`.
#include <cmath>
#include <csignal>

#include "capture_types.hpp"
#include "conversions.hpp"
#include "kdl_space/planning/capture_plan.hpp"
#include "json_objects.hpp"
#include "kdl_space/report/plan_json.hpp"
#include "simulation_types.hpp"

namespace kdl_space::python {
namespace {

struct PyPlan {
  CapturePlan plan;
  std::string scenario;
};

/// The JSON of the terms (report::termsJson, as `plan --json` writes them) as a dict.
py::dict termsDict(const PlanTerms& t, const std::vector<std::string>& names) { return toPython(report::termsJson(t, names)); }

std::optional<PlanRange> rangeOf(py::handle r, const char* name) {
  if (r.is_none()) return std::nullopt;
  const auto ab = argumentAs<std::pair<double, double>>(r, name, "a pair (lower, upper)");
  if (ab.first > ab.second) throw py::value_error(std::string(name) + ": the range's lower end must not exceed its upper end");
  return PlanRange{ab.first, ab.second};
}

/// plan_capture's keyword arguments (the ranges as given: None or a pair).
struct PlanArgs {
  std::string objective;
  py::object weights, self_motion, wrist_roll, timing, closing_speed;
  unsigned int scan, polish_starts;
  py::object horizon;
  double settling_band;
};

PyPlan plan(const Scenario& sc, const PlanArgs& a) {
  const py::handle weights = a.weights;
  PlanOptions o;
  if (!weights.is_none()) {
    o.weights.clear();
    for (const auto& [key, value] : argumentAs<py::dict>(weights, "weights", "a dict {term: weight}"))
      o.weights.emplace_back(py::str(key), argumentAs<double>(value, "weights[" + std::string(py::repr(key)) + "]", "a number"));
  } else {
    o.weights = {{a.objective, 1.0}};
  }
  o.self_motion = rangeOf(a.self_motion, "self_motion");
  if (const auto r = rangeOf(a.wrist_roll, "wrist_roll")) o.wrist_roll = *r;
  if (const auto r = rangeOf(a.timing, "timing")) o.timing = *r;
  o.closing_speed = rangeOf(a.closing_speed, "closing_speed");
  o.scan = a.scan;
  o.polish_starts = a.polish_starts;
  if (!a.horizon.is_none()) o.horizon = argumentAs<double>(a.horizon, "horizon", "a number of seconds");
  o.settling_band = a.settling_band;
  PyPlan result{{}, sc.file};
  const SignalFlag interrupted;  // Ctrl-C: the search stops, then KeyboardInterrupt
  o.cancelled = interrupted;
  {
    py::gil_scoped_release nogil;
    result.plan = planCapture(sc, o);  // InputError: the options, nothing to plan
  }
  if (interrupted.raised()) throw py::error_already_set();
  return result;
}

template <typename T>
py::dict byName(const std::vector<std::string>& names, const std::vector<T>& values) {
  py::dict d;
  for (std::size_t j = 0; j < names.size(); ++j) d[py::str(names[j])] = values[j];
  return d;
}

}  // namespace

void bindPlanning(py::module_& m) {
  py::class_<PyPlan>(m, "CapturePlan", "A planned capture (plan_capture): the fields of `kdl_space plan --json`.")
      .def_property_readonly("scenario", [](const PyPlan& p) { return p.scenario; }, "The scenario's path.")
      .def_property_readonly("joint_names", [](const PyPlan& p) { return p.plan.joint_names; }, "Model order.")
      .def_property_readonly("q", [](const PyPlan& p) { return toNumpyVec(Eigen::Map<const Eigen::VectorXd>(p.plan.q.data(), static_cast<Eigen::Index>(p.plan.q.size()))); },
                             "The optimum's joint angles (nj,) [rad or m].")
      .def_property_readonly("q_by_name", [](const PyPlan& p) { return byName(p.plan.joint_names, p.plan.q); }, "Name -> angle.")
      .def_property_readonly("qdot_after", [](const PyPlan& p) { return toNumpyVec(Eigen::Map<const Eigen::VectorXd>(p.plan.qdot_after.data(), static_cast<Eigen::Index>(p.plan.qdot_after.size()))); },
                             "The joint rates after its capture (nj,).")
      .def_property_readonly("qdot_before", [](const PyPlan& p) { return toNumpyVec(Eigen::Map<const Eigen::VectorXd>(p.plan.qdot_before.data(), static_cast<Eigen::Index>(p.plan.qdot_before.size()))); },
                             "The joint rates before its capture (nj,): the scenario's, or the closing speed's when planned.")
      .def_property_readonly("base_twist_before", [](const PyPlan& p) { return toNumpyVec(Eigen::Map<const Eigen::VectorXd>(p.plan.base_twist_before.data(), 6)); },
                             "The base's twist before its capture (6,): (v of its origin; w), world frame.")
      .def_property_readonly("parameters", [](const PyPlan& p) {
        py::dict d;
        for (const auto& [name, value] : p.plan.parameters) d[py::str(name)] = value;
        return d;
      }, "self_motion [rad], wrist_roll [rad], timing [s], closing_speed [m/s] at the optimum (those that apply).")
      .def_property_readonly("searched", [](const PyPlan& p) { return p.plan.searched; }, "The parameters searched.")
      .def_property_readonly("objective", [](const PyPlan& p) { return p.plan.optimum.objective; }, "At the optimum.")
      .def_property_readonly("optimum", [](const PyPlan& p) { return termsDict(p.plan.optimum, p.plan.joint_names); },
                             "objective, base_rate, impulse, joint_rate_jump, feasible, violation at the optimum.")
      .def_property_readonly("nominal_objective", [](const PyPlan& p) { return p.plan.nominal.objective; },
                             "At the scenario as written.")
      .def_property_readonly("nominal", [](const PyPlan& p) { return termsDict(p.plan.nominal, p.plan.joint_names); }, "The nominal's terms.")
      .def_property_readonly("nominal_q_by_name", [](const PyPlan& p) { return byName(p.plan.joint_names, p.plan.nominal_q); },
                             "The scenario's joint angles.")
      .def_property_readonly("evaluations", [](const PyPlan& p) { return p.plan.evaluations; }, "Captures computed.")
      .def_property_readonly("horizon", [](const PyPlan& p) { return p.plan.horizon; },
                             "The motion after each capture that was measured [s] (0: none).")
      .def_property_readonly("momentum_rate", [](const PyPlan& p) {
        return p.plan.optimum.motion ? p.plan.optimum.motion->momentum_rate : std::nan("");
      }, "The stack's momentum-determined base rate at the optimum once its joints are still [rad/s] (NaN: no horizon).")
      .def("__repr__", [](const PyPlan& p) {
        return "<kdl_space.CapturePlan objective " + std::to_string(p.plan.optimum.objective) + " (nominal " +
               std::to_string(p.plan.nominal.objective) + ")>";
      });
  const char* doc =
      "Capture planning (as `kdl_space plan`): over a redundant arm's self-motion, the wrist roll about the contact "
      "frame's z and optionally the capture instant and the hand's closing speed on the grasp before it (the joint "
      "rates before the capture then follow from J*: see capture_plan.hpp), the configuration whose capture minimises `objective` "
      "(at the capture's instant: base_rate, impulse, joint_rate_jump; over the motion after it, `horizon` seconds "
      "with the scenario's servos holding and its base control: peak_base_rate, final_base_rate, attitude_excursion, "
      "settling_time, peak_torque_ratio, peak_grasp_force, peak_grasp_moment, time_to_detumble, wheel_momentum_fraction) or the weighted sum `weights` "
      "({name: weight}), inside the joints' position and velocity limits. With a horizon (or an operation term), "
      "optimum and nominal carry `motion`: what the bus felt over it, and momentum_rate the stack's rate once still. Ranges are (lower, upper) pairs; None: the default (self_motion (-1, 1) for a "
      "redundant arm, wrist_roll (-pi/2, pi/2), timing (0, 0), closing_speed: the scenario's rates); (a, a) fixes one. Returns a CapturePlan; InputError "
      "for nothing to plan, an unknown term or a bad weight.";
  m.def(
      "plan_capture",
      [=](const ScenarioArg& s, const std::string& objective, py::object weights, py::object self_motion, py::object wrist_roll,
          py::object timing, py::object closing_speed, unsigned int scan, unsigned int polish_starts, py::object horizon,
          double settling_band) {
        return plan(s.get(), {objective, weights, self_motion, wrist_roll, timing, closing_speed, scan, polish_starts,
                              horizon, settling_band});
      },
      py::arg("scenario"), py::kw_only(), py::arg("objective") = "base_rate", py::arg("weights") = py::none(),
      py::arg("self_motion") = py::none(), py::arg("wrist_roll") = py::none(), py::arg("timing") = py::none(),
      py::arg("closing_speed") = py::none(), py::arg("scan") = 21, py::arg("polish_starts") = 5,
      py::arg("horizon") = py::none(), py::arg("settling_band") = 0.05, doc);
}

}  // namespace kdl_space::python
