// The types a run returns: kdl_space.Integrator, JointRecord, SimulationStats, Stiffness and
// SimulationResult (the samples as NumPy arrays).
#include <cstring>
#include <sstream>

#include "simulation_types.hpp"

namespace kdl_space::python {
namespace {

py::array_t<double> rows(const std::vector<double>& v, long k, long cols) {
  py::array_t<double> a = cols < 0 ? py::array_t<double>(k) : py::array_t<double>(std::vector<py::ssize_t>{k, cols});
  if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(double));
  return a;
}

}  // namespace

py::list reportWarnings(const std::vector<Diagnostic>& warnings) {
  py::list l;
  for (const Diagnostic& w : warnings) {
    l.append(py::dict(py::arg("kind") = w.kind, py::arg("element") = w.element, py::arg("message") = w.message));
    const std::string text = w.kind + ": " + (w.element.empty() ? "" : w.element + ": ") + w.message;
    if (PyErr_WarnEx(PyExc_RuntimeWarning, text.c_str(), 1) != 0) throw py::error_already_set();
  }
  return l;
}

PyRun::PyRun(const Samples& x, const PyState& final, const PyStats& st)
  : joint_names(st.joint_names), final_state(final), stats(st) {
  const long n = static_cast<long>(joint_names.size());
  t = rows(x.t, x.k, -1), base_position = rows(x.p, x.k, 3), base_quaternion = rows(x.quat, x.k, 4);
  base_twist = rows(x.twist, x.k, 6), q = rows(x.q, x.k, n), qdot = rows(x.qdot, x.k, n), tau = rows(x.tau, x.k, n);
  base_wrench = rows(x.base_wrench, x.k, 6), momentum = rows(x.h, x.k, 6), energy = rows(x.T, x.k, -1);
  impulse = rows(x.impulse, x.k, 6);
  const char* names[] = {"controller", "friction", "limits", "base_control", "wrenches", "gravity"};
  for (long i = 0; i < 6; ++i) {
    std::vector<double> column(static_cast<std::size_t>(x.k));
    for (long r = 0; r < x.k; ++r) column[r] = x.work[r * 6 + i];
    work[names[i]] = rows(column, x.k, -1);
  }
}

void bindSimulationResults(py::module_& m) {
  py::enum_<Integrator>(m, "Integrator", "Time integration schemes (Simulator(integrator=...) also takes their names).")
      .value("RK4", Integrator::RK4).value("DormandPrince54", Integrator::DormandPrince54)
      .value("Rosenbrock", Integrator::Rosenbrock);

  py::class_<JointRecord>(m, "JointRecord", "What happened to one joint in a run (times in s; NaN: never).")
      .def_readonly("limit_first_time", &JointRecord::limit_first_time, "First step outside the position limits.")
      .def_readonly("limit_worst", &JointRecord::limit_worst, "The position farthest outside them.")
      .def_readonly("stops", &JointRecord::stops, "Hard-stop impacts.")
      .def_readonly("saturation_first_time", &JointRecord::saturation_first_time, "First step its torque was limited.")
      .def_readonly("saturation_time", &JointRecord::saturation_time, "How long it was limited [s].")
      .def("__repr__", [](const JointRecord& r) {
        std::ostringstream s;
        s << "JointRecord(limit_first_time=" << r.limit_first_time << ", stops=" << r.stops
          << ", saturation_time=" << r.saturation_time << ")";
        return s.str();
      });
  py::class_<PyStats>(m, "SimulationStats", "Counters of a run.")
      .def_property_readonly("accepted_steps", [](const PyStats& x) { return x.stats.accepted_steps; })
      .def_property_readonly("rejected_steps", [](const PyStats& x) { return x.stats.rejected_steps; })
      .def_property_readonly("min_step", [](const PyStats& x) { return x.stats.min_step; }, "Of the accepted steps [s].")
      .def_property_readonly("max_step", [](const PyStats& x) { return x.stats.max_step; }, "[s]")
      .def_property_readonly("base_saturation_time", [](const PyStats& x) { return x.stats.base_saturation_time; },
                             "How long the base control was limited [s].")
      .def_property_readonly("joints", [](const PyStats& x) {
        py::dict d;
        for (std::size_t j = 0; j < x.joint_names.size() && j < x.stats.joints.size(); ++j)
          d[py::str(x.joint_names[j])] = x.stats.joints[j];
        return d;
      }, "Joint name -> JointRecord.")
      .def("__repr__", [](const PyStats& x) {
        return "<kdl_space.SimulationStats " + std::to_string(x.stats.accepted_steps) + " steps, " +
               std::to_string(x.stats.rejected_steps) + " rejected>";
      });
  py::class_<PyStiffness>(m, "Stiffness", "The servos' fastest closed-loop rate at a state and the explicit step it allows.")
      .def_property_readonly("fastest_rate", [](const PyStiffness& x) { return x.s.fastest_rate; }, "[1/s]")
      .def_property_readonly("fastest_joint", [](const PyStiffness& x) -> py::object {
        if (x.s.fastest_joint < 0) return py::none();
        return py::str(x.joint_names[x.s.fastest_joint]);
      }, "Its joint's name, or None without a servo.")
      .def_property_readonly("explicit_step", [](const PyStiffness& x) { return x.s.explicit_step; },
                             "2.8 / fastest_rate [s] (inf without a servo).")
      .def("__repr__", [](const PyStiffness& x) {
        std::ostringstream s;
        s << "Stiffness(fastest_rate=" << x.s.fastest_rate << ", fastest_joint="
          << (x.s.fastest_joint < 0 ? std::string("None") : "'" + x.joint_names[x.s.fastest_joint] + "'")
          << ", explicit_step=" << x.s.explicit_step << ")";
        return s.str();
      });
  py::class_<PyRun>(m, "SimulationResult",
                    "The samples of a run (k rows: its start, every output_dt, its end), world frame, joint columns in "
                    "`joint_names` order.")
      .def_readonly("joint_names", &PyRun::joint_names)
      .def_readonly("t", &PyRun::t, "(k,) [s]")
      .def_readonly("base_position", &PyRun::base_position, "(k, 3) [m]")
      .def_readonly("base_quaternion", &PyRun::base_quaternion, "(k, 4), (x, y, z, w) of world_R_base.")
      .def_readonly("base_twist", &PyRun::base_twist, "(k, 6): (v of the base origin; w).")
      .def_readonly("warnings", &PyRun::warnings,
                    "[{kind, element, message}]: a controller sampled at control_rate whose rate gain on a joint "
                    "(element) exceeds what its zero-order hold keeps stable (kind 'sampled_gain_unstable'); each "
                    "also issued as a RuntimeWarning.")
      .def_readonly("q", &PyRun::q, "(k, nj)")
      .def_readonly("qdot", &PyRun::qdot, "(k, nj)")
      .def_readonly("tau", &PyRun::tau, "(k, nj): joint torques applied (controls, limited, plus friction).")
      .def_readonly("base_wrench", &PyRun::base_wrench, "(k, 6): the base control's (f; n about the base CoM).")
      .def_readonly("momentum", &PyRun::momentum, "(k, 6): (P; L about the world origin).")
      .def_readonly("energy", &PyRun::energy, "(k,): kinetic energy [J].")
      .def_readonly("work", &PyRun::work, "Work since the start by what did it: dict name -> (k,) [J] (controller, "
                                          "friction, limits, base_control, wrenches, gravity).")
      .def_readonly("impulse", &PyRun::impulse, "(k, 6): external impulse since the start (f; moment about the origin).")
      .def_readonly("final_state", &PyRun::final_state, "The State where the run ended.")
      .def_property_readonly("final_t", [](const PyRun& r) { return r.t.size() ? r.t.at(r.t.size() - 1) : std::nan(""); },
                             "The time of the last sample [s].")
      .def_readonly("stats", &PyRun::stats, "SimulationStats of the run.")
      .def("__len__", [](const PyRun& r) { return r.t.size(); })
      .def("__repr__", [](const PyRun& r) {
        std::ostringstream s;
        s << "<kdl_space.SimulationResult " << r.t.size() << " samples";
        if (r.t.size()) s << " over [" << r.t.at(0) << ", " << r.t.at(r.t.size() - 1) << "] s";
        s << ", q (" << r.t.size() << ", " << r.joint_names.size() << ")>";
        return s.str();
      });
}

}  // namespace kdl_space::python
