// kdl_space.Model, Contact, State, Finding, Diagnostic; load_urdf and check_urdf.
#include <map>
#include <sstream>

#include "conversions.hpp"
#include "kdl_space/parsers/formats/robot_file.hpp"
#include "kdl_space/parsers/urdf/urdf_check.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"

namespace kdl_space::python {

KDL::JntArray jointValues(const FloatingModel& model, py::handle obj, const char* name) {
  if (py::isinstance<py::dict>(obj)) {
    std::map<std::string, double> values;
    for (auto item : py::reinterpret_borrow<py::dict>(obj))
      values[argumentAs<std::string>(item.first, name, "joint names as keys")] =
          argumentAs<double>(item.second, std::string(name) + "[" + std::string(py::repr(item.first)) + "]", "a number");
    return jointsByName(model, values);  // ModelError naming an unknown joint
  }
  KDL::JntArray a(model.nj());
  a.data = fromNumpy(obj, name, model.nj());
  return a;
}

void checkContact(const FloatingModel& model, const PyContact& c) {
  if (c.model.get() != &model)
    throw py::value_error("contact: the contact at link '" + c.link +
                          "' belongs to another model (Model.contact of the solver's model)");
}

namespace {

const char* severityName(Severity s) {
  switch (s) {
    case Severity::Error: return "error";
    case Severity::Warning: return "warning";
    case Severity::Note: return "note";
  }
  return "?";
}

std::string quoted(const std::string& s) { return py::cast<std::string>(py::repr(py::str(s))); }

std::string findingRepr(const Finding& f) {
  return std::string("Finding(") + severityName(f.severity) + ", " + quoted(f.kind) + ", " + quoted(describe(f)) + ")";
}

PyState makeState(const Model& model, py::object q, py::object base_pose, py::object base_twist, py::object qdot) {
  PyState s{model.ptr, State(*model.ptr), FloatingVelocity(*model.ptr)};
  if (!q.is_none()) s.state.q = jointValues(*model.ptr, q, "q");
  if (!base_pose.is_none()) s.state.world_T_base = frameFromPython(base_pose, "base_pose");
  if (!base_twist.is_none()) s.velocity.base_twist = toTwist(vec6(base_twist, "base_twist"));
  if (!qdot.is_none()) s.velocity.qdot = jointValues(*model.ptr, qdot, "qdot");
  return s;
}

std::vector<std::string> bodyNames(const FloatingModel& m) {
  std::vector<std::string> names;
  for (const Body& b : m.bodies()) names.push_back(b.name);
  return names;
}

}  // namespace

void bindModel(py::module_& m) {
  py::enum_<Severity>(m, "Severity", "Whether a finding stops the model from being used.")
      .value("Error", Severity::Error).value("Warning", Severity::Warning).value("Note", Severity::Note);
  py::enum_<ElementType>(m, "ElementType", "What Finding.element names.")
      .value("File", ElementType::File).value("Robot", ElementType::Robot).value("Link", ElementType::Link)
      .value("Joint", ElementType::Joint).value("Tip", ElementType::Tip);

  py::class_<Finding>(m, "Finding", "One problem found in a URDF description (check_urdf).")
      .def_readonly("severity", &Finding::severity, "Severity: Error, Warning or Note.")
      .def_readonly("kind", &Finding::kind, "Short stable identifier, e.g. 'non_positive_mass'.")
      .def_readonly("element_type", &Finding::element_type, "What `element` names (ElementType).")
      .def_readonly("element", &Finding::element, "Link, joint or tip name; the robot's name; '' for the file.")
      .def_readonly("message", &Finding::message, "What is wrong, without the element.")
      .def("describe", &describe, "The element and the message in one line.")
      .def("__str__", &describe)
      .def("__repr__", &findingRepr);

  py::class_<Diagnostic>(m, "Diagnostic", "A problem that does not stop the computation, or what was assumed.")
      .def_readonly("element", &Diagnostic::element, "The link or joint concerned ('' for the model).")
      .def_readonly("message", &Diagnostic::message, "What was found and what the model does about it.")
      .def_readonly("kind", &Diagnostic::kind, "The Finding kind when it comes from a rule ('' otherwise).")
      .def_readonly("severity", &Diagnostic::severity, "Warning or Note.")
      .def("__repr__", [](const Diagnostic& d) {
        return std::string("Diagnostic(") + severityName(d.severity) + ", " + quoted(d.kind) + ", " +
               quoted(d.element) + ", " + quoted(d.message) + ")";
      });

  py::class_<PyContact>(m, "Contact", "A contact point: a link plus an offset in its frame (Model.contact).")
      .def_readonly("link", &PyContact::link, "The link's name.")
      .def_property_readonly("body", [](const PyContact& c) { return c.contact.body; }, "Index into Model.link_names.")
      .def_property_readonly("offset", [](const PyContact& c) { return toNumpy(toEigen(c.contact.offset), true); },
                             "Offset in the link's frame [m], (3,).")
      .def("__repr__", [](const PyContact& c) {
        std::ostringstream s;
        s << "Contact(" << quoted(c.link) << ", offset=(" << c.contact.offset.x() << ", " << c.contact.offset.y()
          << ", " << c.contact.offset.z() << "))";
        return s.str();
      });

  py::class_<Model>(m, "Model", "An immutable free-floating model (load_urdf): the base and the joints' order.")
      .def_readonly("source", &Model::source, "The file it was loaded from.")
      .def_property_readonly("joint_names", [](const Model& x) { return x.ptr->jointNames(); },
                             "Movable joints (the coordinates), in the order of every joint-indexed value.")
      .def_property_readonly("link_names", [](const Model& x) { return bodyNames(*x.ptr); },
                             "Links (bodies) in traversal order; the first is the base.")
      .def_property_readonly("nj", [](const Model& x) { return x.ptr->nj(); }, "Number of coordinates.")
      .def_property_readonly("total_mass", [](const Model& x) { return x.ptr->totalMass(); }, "Total mass [kg].")
      .def_property_readonly("diagnostics", [](const Model& x) { return x.ptr->diagnostics(); },
                             "What was assumed to read the description (list of Diagnostic).")
      .def_property_readonly("fixed_joints", [](const Model& x) {
        std::vector<std::pair<std::string, std::string>> r;
        for (const FixedJoint& f : x.ptr->fixedJoints()) r.emplace_back(f.joint, f.reason);
        return r;
      }, "Movable joints of the file treated as fixed at q = 0: list of (joint, reason).")
      .def("contact", [](const Model& x, const std::string& link, py::object offset) {
        const Vector3d o = offset.is_none() ? Vector3d::Zero() : vec3(offset, "offset");
        return PyContact{x.ptr, x.ptr->contact(link, toKDL(o)), link};
      }, py::arg("link"), py::arg("offset") = py::none(),
         "A contact point on `link` at `offset` (link frame, (3,)); ModelError for an unknown link.")
      .def("state", &makeState, py::arg("q") = py::none(), py::arg("base_pose") = py::none(),
           py::arg("base_twist") = py::none(), py::arg("qdot") = py::none(), "The same as State(model, ...).")
      .def("__repr__", [](const Model& x) {
        std::ostringstream s;
        s << "<kdl_space.Model " << quoted(x.source) << ": base " << quoted(x.ptr->bodies()[0].name) << ", "
          << x.ptr->nj() << " joints, " << x.ptr->bodies().size() << " bodies, " << x.ptr->totalMass() << " kg>";
        return s.str();
      });

  py::class_<PyState>(m, "State",
                      "Configuration and velocity of a model: base pose (world_T_base), joint positions q, base "
                      "twist (v of the base frame's origin; w, world frame), joint rates qdot.")
      .def(py::init(&makeState), py::arg("model"), py::kw_only(), py::arg("q") = py::none(),
           py::arg("base_pose") = py::none(), py::arg("base_twist") = py::none(), py::arg("qdot") = py::none(),
           "q, qdot: (nj,) arrays or dicts joint name -> value (others 0); base_pose: a 4x4 array or "
           "(position, rpy) (URDF roll-pitch-yaw); base_twist: (6,). Defaults: identity pose, at rest, 0.")
      .def_property_readonly("joint_names", [](const PyState& s) { return s.model->jointNames(); }, "The order of q, qdot.")
      .def_property_readonly("q", [](const PyState& s) { return toNumpyVec(s.state.q.data); }, "Joint positions (nj,).")
      .def_property_readonly("qdot", [](const PyState& s) { return toNumpyVec(s.velocity.qdot.data); }, "Joint rates (nj,).")
      .def_property_readonly("base_pose", [](const PyState& s) { return frameToNumpy(s.state.world_T_base); },
                             "world_T_base, (4, 4).")
      .def_property_readonly("base_twist", [](const PyState& s) { return toNumpy6(toEigen(s.velocity.base_twist)); },
                             "(v of the base origin; w), world frame, (6,).")
      .def("__repr__", [](const PyState& s) {
        return "<kdl_space.State of " + std::to_string(s.model->nj()) + " joints>";
      });

  m.def("load_urdf", [](const std::string& path) { return Model{std::make_shared<const FloatingModel>(loadRobotFile(path)), path}; },
        py::arg("path"), "Loads a robot description as a free-floating Model (root link = base): URDF, or SDF, MJCF, SpaceDyn LP (.m) read as their URDF document (urdf_document); ModelError or InputError naming the problem.");
  m.def("check_urdf", [](const std::string& path, const std::vector<std::string>& tips) {
    const UrdfReport r = checkRobotFile(path, tips);
    std::vector<Finding> all = r.errors;
    all.insert(all.end(), r.warnings.begin(), r.warnings.end());
    all.insert(all.end(), r.notes.begin(), r.notes.end());
    return all;
  }, py::arg("path"), py::arg("tips") = std::vector<std::string>{},
     "Every problem of a URDF file as a list of Finding (errors, then warnings, then notes); never raises.");
}

}  // namespace kdl_space::python
