// kdl_space.Scenario, CaptureProblem, RigidTarget, CaptureResult; load_scenario and
// solve_capture (capture.hpp, scenario.hpp): the capture as one call, GIL released.
#include <sstream>

#include "conversions.hpp"
#include "capture_types.hpp"
#include "expose_html.hpp"
#include "kdl_space/algorithm/conditioning.hpp"
#include "impact_law.hpp"
#include "kdl_space/impact/capture.hpp"
#include "kdl_space/operation/overlap_check.hpp"
#include "kdl_space/parsers/scenario/scenario.hpp"

namespace kdl_space::python {
namespace {

/// `robot_urdf`: the robot's visuals for the overlap check ("" for its boxes of inertia).
PyResult solve(const CaptureProblem& p, std::shared_ptr<const Scenario> scenario, const std::string& robot_urdf) {
  CaptureResult r;
  {
    py::gil_scoped_release nogil;
    r = solveCapture(p);  // InputError or a side's ModelError, as kdl_space's
  }
  PyResult out{r, PySide{r.robot, p.robot.model->jointNames()}, std::nullopt, {}, std::move(scenario)};
  if (r.floating_target)
    out.floating_target = PySide{*r.floating_target, std::get<FloatingSystem>(p.target).model->jointNames()};
  Conditioning c;  // a state the solver refused has failed the capture above: only the limits then
  checkConfiguration(p.robot.model, p.robot.state, p.robot.contact, c, out.warnings);
  for (Diagnostic& d : overlapWarnings(p, robot_urdf, "capture")) out.warnings.push_back(std::move(d));
  return out;
}

RigidTarget makeTarget(double mass, py::object inertia, py::object pose, py::object com, py::object twist) {
  RigidTarget t;
  t.mass = mass;
  t.inertia = mat3(inertia, "inertia");
  if (!pose.is_none()) t.pose = frameFromPython(pose, "pose");
  if (!com.is_none()) t.com = vec3(com, "com");
  if (!twist.is_none()) t.twist = vec6(twist, "twist");
  return t;
}

Response responseOf(const std::string& r) {
  if (r == "free") return Response::FreeFloating;
  if (r == "grounded") return Response::Grounded;
  if (r == "locked") return Response::JointsLocked;
  throw py::value_error("response: expected 'free', 'grounded' or 'locked', got '" + r + "'");
}

PyProblem makeProblem(const PyState& state, const PyContact& contact, const RigidTarget& target,
                      const PyImpactLaw& law, const std::string& response, const std::string& method) {
  checkContact(*state.model, contact);
  PyProblem p;
  p.problem.robot = FloatingSystem{state.model, state.state, state.velocity, contact.contact, responseOf(response), {}};
  p.problem.target = target;
  p.problem.law = law.law;
  p.problem.has_normal = law.has_normal;
  if (method == "recursive") p.problem.method = ExIITMethod::Recursive;
  else if (method == "dense") p.problem.method = ExIITMethod::Dense;
  else throw py::value_error("method: expected 'recursive' or 'dense', got '" + method + "'");
  return p;
}

/// A problem alone as a scenario (what its result's to_html draws): its robot's URDF, if known.
std::shared_ptr<const Scenario> scenarioOf(const PyProblem& p) {
  auto sc = std::make_shared<Scenario>();
  sc->capture = p.problem;
  sc->robot_urdf = p.robot_source;
  return sc;
}

template <class C, class Get>
void vec6Property(C& cls, const char* name, Get get, const char* doc) {
  cls.def_property_readonly(name, [get](const typename C::type& x) { return toNumpy6(get(x)); }, doc);
}

void bindRigidTarget(py::module_& m) {
  py::class_<RigidTarget>(m, "RigidTarget", "A rigid target in a scenario's terms.")
      .def(py::init(&makeTarget), py::arg("mass"), py::arg("inertia"), py::arg("pose") = py::none(),
           py::arg("com") = py::none(), py::arg("twist") = py::none(),
           "mass [kg]; inertia about the CoM in the target frame (3, 3); pose of the target frame (4x4 or "
           "(position, rpy)); com in the target frame (3,); twist (v of the CoM; w), world frame, (6,).")
      .def_readonly("mass", &RigidTarget::mass, "[kg]")
      .def_property_readonly("inertia", [](const RigidTarget& t) { return toNumpy(t.inertia); }, "(3, 3), target axes.")
      .def_property_readonly("pose", [](const RigidTarget& t) { return frameToNumpy(t.pose); }, "(4, 4).")
      .def_property_readonly("com", [](const RigidTarget& t) { return toNumpy(t.com, true); }, "(3,), target frame.")
      .def_property_readonly("twist", [](const RigidTarget& t) { return toNumpy6(t.twist); }, "(6,) at the CoM.");
}

}  // namespace

void bindCapture(py::module_& m) {
  bindRigidTarget(m);

  py::class_<PyProblem>(m, "CaptureProblem", "A capture (or any impact) to solve: the robot at one instant, a target, a law.")
      .def(py::init(&makeProblem), py::arg("state"), py::arg("contact"), py::arg("target"), py::arg("law"),
           py::arg("response") = "free", py::arg("method") = "recursive",
           "state: the robot's State (pose, q, base twist, qdot); contact: Model.contact; target: RigidTarget; "
           "law: ImpactLaw; response: 'free', 'grounded' or 'locked'; method: 'recursive' or 'dense'.")
      .def_property_readonly("joint_names", [](const PyProblem& p) { return p.problem.robot.model->jointNames(); },
                             "The robot's joints.")
      .def_property_readonly("law", [](const PyProblem& p) { return PyImpactLaw{p.problem.law, p.problem.has_normal}; },
                             "The impact law.")
      .def_property_readonly("floating_target", [](const PyProblem& p) {
        return std::holds_alternative<FloatingSystem>(p.problem.target);
      }, "Whether the target is another free-floating system.")
      .def_property_readonly("state", [](const PyProblem& p) {
        const FloatingSystem& r = p.problem.robot;
        return PyState{r.model, r.state, r.velocity};
      }, "The robot's State before the impact.");

  py::class_<PyScenario>(m, "Scenario", "A scenario file, read and checked (load_scenario).")
      .def_property_readonly("file", [](const PyScenario& s) { return s.scenario.file; }, "The path it was read from.")
      .def_property_readonly("robot_urdf", [](const PyScenario& s) { return s.scenario.robot_urdf; }, "The robot's URDF.")
      .def_property_readonly("target_urdf", [](const PyScenario& s) { return s.scenario.target_urdf; },
                             "The target's URDF ('' for a rigid target given by numbers).")
      .def_property_readonly("impact", [](const PyScenario& s) { return s.scenario.impact; },
                             "False for a plain motion (no target, no law).")
      .def_property_readonly("robot", [](const PyScenario& s) { return Model{s.scenario.capture.robot.model, s.scenario.robot_urdf}; },
                             "The robot's Model.")
      .def_property_readonly("problem", [](const PyScenario& s) { return PyProblem{s.scenario.capture, s.scenario.robot_urdf}; },
                             "The CaptureProblem it holds.")
      .def_property_readonly("duration", [](const PyScenario& s) { return s.scenario.simulation.duration; },
                             "simulation.duration [s]: the motion's length.")
      .def_property_readonly("output_step", [](const PyScenario& s) { return s.scenario.simulation.output_step; },
                             "simulation.output_step [s]: the samples' spacing.")
      .def("__repr__", [](const PyScenario& s) { return "<kdl_space.Scenario '" + s.scenario.file + "'>"; });

  py::class_<PySide>(m, "SideResult", "One free-floating side before and after an impact (world frame).")
      .def_readonly("joint_names", &PySide::joint_names, "The order of qdot_before, qdot_after.")
      .def_property_readonly("base_twist_before", [](const PySide& s) { return toNumpy6(toEigen(s.side.before.base_twist)); },
                             "(v of the base origin; w), (6,).")
      .def_property_readonly("base_twist_after", [](const PySide& s) { return toNumpy6(toEigen(s.side.after.base_twist)); },
                             "(6,).")
      .def_property_readonly("qdot_before", [](const PySide& s) { return toNumpyVec(s.side.before.qdot.data); }, "(nj,).")
      .def_property_readonly("qdot_after", [](const PySide& s) { return toNumpyVec(s.side.after.qdot.data); }, "(nj,).")
      .def_property_readonly("contact_twist_before", [](const PySide& s) { return toNumpy6(s.side.contact_twist_before); }, "(6,).")
      .def_property_readonly("contact_twist_after", [](const PySide& s) { return toNumpy6(s.side.contact_twist_after); }, "(6,).")
      .def_property_readonly("centroid_twist_before", [](const PySide& s) { return toNumpy6(s.side.centroid_twist_before); },
                             "Locked twist at the CoM, M_a^-1 (P_g; L_g), (6,).")
      .def_property_readonly("centroid_twist_after", [](const PySide& s) { return toNumpy6(s.side.centroid_twist_after); }, "(6,).");

  py::class_<PyResult> result(m, "CaptureResult", "Everything about a solved impact (world frame; momentum about the origin).");
  result.def_property_readonly("impulse", [](const PyResult& x) { return x.r.impulse; }, "Impulse on the robot.")
      .def_readonly("robot", &PyResult::robot, "The robot before and after (SideResult).")
      .def_readonly("floating_target", &PyResult::floating_target, "The free-floating target's SideResult, or None.")
      .def_property_readonly("warnings", [](const PyResult& x) {
        py::list l;
        for (const Diagnostic& w : x.warnings) {
          py::dict d(py::arg("kind") = w.kind, py::arg("element") = w.element, py::arg("message") = w.message);
          for (const auto& [key, value] : w.details)
            std::visit([&d, &key](const auto& v) { d[py::str(key)] = v; }, value);
          l.append(d);
        }
        return l;
      }, "The robot's configuration at the capture: list of {kind, element, message} (joint_outside_limits, "
         "near_singular; overlap: a link that penetrates the target's box of inertia by more than 1 cm, with "
         "link, target, depth [m], moment 'capture' and geometry 'visuals' or 'inertia_box'; a CaptureProblem's "
         "robot is checked by its boxes of inertia, a Scenario's by its URDF visuals), as `kdl_space capture "
         "--json`'s `warnings`.")
      .def_property_readonly("contact_point", [](const PyResult& x) { return toNumpy(x.r.contact_point, true); }, "(3,) [m].")
      .def_property_readonly("G_robot", [](const PyResult& x) { return toNumpy(x.r.G_robot); }, "The robot's G (6, 6).")
      .def_property_readonly("G_target", [](const PyResult& x) { return toNumpy(x.r.G_target); }, "The target's G (6, 6).")
      .def_property_readonly("energy_before", [](const PyResult& x) { return x.r.energy_before; }, "Both sides [J].")
      .def_property_readonly("energy_after", [](const PyResult& x) { return x.r.energy_after; }, "Both sides [J].")
      .def_property_readonly("energy_lost", [](const PyResult& x) { return x.r.energyLost(); }, "[J].")
      .def_property_readonly("virtual_mass", [](const PyResult& x) { return x.r.virtual_mass; },
                             "The robot's mass along the law's normal [kg], or None.")
      .def_property_readonly("contact_body_pose", [](const PyResult& x) { return frameToNumpy(x.r.contact_body_pose); },
                             "World pose of the robot's contact body at the impact, (4, 4).");
  vec6Property(result, "target_twist_before", [](const PyResult& x) { return x.r.target_twist_before; }, "At the target's CoM, (6,).");
  vec6Property(result, "target_twist_after", [](const PyResult& x) { return x.r.target_twist_after; }, "(6,).");
  vec6Property(result, "momentum_before", [](const PyResult& x) { return x.r.momentum_before; }, "(P; L about the origin), both sides, (6,).");
  vec6Property(result, "momentum_after", [](const PyResult& x) { return x.r.momentum_after; }, "(6,).");
  result.def("to_html", &captureToHtml, py::arg("path"), py::arg("mesh_path") = py::none(),
             "Writes the capture's instant as the interactive 3-D page of `kdl_space capture --html` (one "
             "self-contained HTML file, the same writer): the robot at the impact, the target, the contact point, "
             "the grasp frame, the impulse's arrow; before and after. mesh_path: a folder or a list of folders where "
             "the URDFs' package:// meshes are found (the tool's --mesh-path), before ROS_PACKAGE_PATH's. ValueError "
             "for a path that is one of the scenario's inputs (its URDFs' meshes the page embeds too) or a mesh_path "
             "that is not a folder, OSError for a folder that cannot hold it or three.js missing; each names the path.");
  result.def("__repr__", [](const PyResult& x) {
    std::ostringstream s;
    s << "<kdl_space.CaptureResult F=[" << x.r.impulse.F.transpose() << "], energy lost " << x.r.energyLost() << " J>";
    return s.str();
  });

  m.def("load_scenario", [](const std::string& path) { return PyScenario{loadScenario(path)}; }, py::arg("path"),
        "Reads and checks a scenario file (YAML or JSON); InputError 'FILE[:LINE]: FIELD: what is wrong' (a URDF "
        "that loads no model: the loader's ModelError, with the same 'FILE:LINE: robot.urdf: ' in front).");
  m.def("solve_capture", [](const ScenarioArg& s) {
    const Scenario& sc = s.get();
    if (!sc.impact) throw py::value_error("scenario: '" + sc.file + "' has no target and no law (a plain motion)");
    return solve(sc.capture, std::make_shared<const Scenario>(sc), sc.robot_urdf);
  }, py::arg("scenario_or_problem"), "Solves a scenario's capture (GIL released): a CaptureResult; InputError (or a side's ModelError) naming "
     "the part.");
  m.def("solve_capture", [](const PyProblem& p) { return solve(p.problem, scenarioOf(p), ""); }, py::arg("scenario_or_problem"),
        "Solves a CaptureProblem (GIL released).");
  const auto attach = [](const CaptureProblem& p, const PyResult& r, const std::string& source) {
    return Model{attachTarget(p, r.r), source};  // an Error naming the part
  };
  m.def("attach_target", [attach](const ScenarioArg& s, const PyResult& r) { return attach(s.get().capture, r, s.get().robot_urdf); },
        py::arg("scenario_or_problem"), py::arg("result"),
        "The Model that moves on after the impact solved by `result`: after a rigid capture of a rigid target, the "
        "robot with the target merged into its contact link (the same joints); after a point impact, the robot's "
        "own. InputError for a translational capture or a free-floating target.");
  m.def("attach_target", [attach](const PyProblem& p, const PyResult& r) { return attach(p.problem, r, p.robot_source); },
        py::arg("scenario_or_problem"), py::arg("result"), "The same for a CaptureProblem.");
}

}  // namespace kdl_space::python
