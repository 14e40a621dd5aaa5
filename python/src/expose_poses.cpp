// Model.link_pose (forward kinematics of any link) and inspect_contact: the contact frame's pose,
// J*'s conditioning, the joints' margins to their limits and the warnings about the configuration
// (what `kdl_space inspect` prints, as a dict).
#include "conversions.hpp"
#include "kdl_space/algorithm/conditioning.hpp"
#include "kdl_space/multibody/poses.hpp"

namespace kdl_space::python {
namespace {

/// A State of `model`, or one built from joint values q (array or dict; base at the identity).
State stateOf(const Model& model, py::handle state_or_q) {
  if (py::isinstance<PyState>(state_or_q)) {
    const PyState& s = py::cast<const PyState&>(state_or_q);
    if (s.model.get() != model.ptr.get() && s.model->nj() != model.ptr->nj())
      throw py::value_error("state: a state of another model (" + std::to_string(s.model->nj()) + " joints, this one has " +
                            std::to_string(model.ptr->nj()) + ")");
    return s.state;
  }
  State s(*model.ptr);
  s.q = jointValues(*model.ptr, state_or_q, "q");
  return s;
}

py::dict poseDict(const PoseFigures& f) {
  py::dict d;
  d["position"] = toNumpy(f.position, true);
  d["rotation"] = toNumpy(f.rotation);
  d["quaternion"] = toNumpy(f.quaternion, true);
  d["rpy"] = toNumpy(f.rpy, true);
  return d;
}

py::list warningList(const std::vector<Diagnostic>& warnings) {
  py::list l;
  for (const Diagnostic& w : warnings) {
    py::dict d;
    d["kind"] = w.kind;
    d["element"] = w.element;
    d["message"] = w.message;
    l.append(d);
  }
  return l;
}

py::dict inspectContact(const PyState& s, const PyContact& c) {
  checkContact(*c.model, c);
  if (s.model.get() != c.model.get() && s.model->nj() != c.model->nj())
    throw py::value_error("state: a state of another model than the contact's");
  const State state = s.state;
  Kinematics kin(*c.model);
  check(forwardKinematics(*c.model, state, kin), "inspect_contact");
  Conditioning cond;
  std::vector<Diagnostic> warnings;
  check(checkConfiguration(c.model, state, c.contact, cond, warnings), "inspect_contact at '" + c.link + "'");
  py::dict d = poseDict(poseFigures(contactFrame(kin, c.contact)));
  d["J_star_singular_values"] = toNumpyVec(cond.sigma_J_star);
  d["J_star_condition_number"] = cond.condition_number;  // inf when singular
  d["J_star_manipulability"] = cond.manipulability_J_star;
  d["J_manipulability"] = cond.manipulability_J;
  py::dict margins;
  for (const JointMargin& m : jointMargins(*c.model, state.q))
    margins[py::str(c.model->jointNames()[m.joint])] = m.limited ? py::cast(m.margin()) : py::none();
  d["joint_margins"] = margins;
  d["warnings"] = warningList(warnings);
  return d;
}

}  // namespace

void bindPoses(py::module_& m) {
  auto model = py::reinterpret_borrow<py::class_<Model>>(m.attr("Model"));
  model.def("link_pose", [](const Model& x, py::object state_or_q, const std::string& link) {
    const int body = x.ptr->bodyIndex(link);
    if (body < 0) throw ModelError("link_pose: the model has no link '" + link + "' (Model.link_names lists them)");
    const State state = stateOf(x, state_or_q);
    KDL::Frame world_T_link;
    check(linkPose(*x.ptr, state, body, world_T_link), "link_pose of '" + link + "'");
    const PoseFigures f = poseFigures(world_T_link);
    return py::make_tuple(toNumpy(f.position, true), toNumpy(f.rotation));
  }, py::arg("state"), py::arg("link"),
     "World pose of `link` at `state` (a State, the base where it puts it; or q, an (nj,) array or a dict "
     "joint name -> value, base at the identity): (position (3,) [m], rotation world_R_link (3, 3)).");
  m.def("inspect_contact", &inspectContact, py::arg("state"), py::arg("contact"),
        "What `kdl_space inspect` reports of a contact, as a dict: the contact frame's pose (position (3,), "
        "rotation (3, 3), quaternion (x, y, z, w) with w >= 0, rpy (3,) URDF roll-pitch-yaw), "
        "J_star_singular_values (largest first), J_star_condition_number (inf when singular), "
        "J_star_manipulability and J_manipulability (product of the singular values), joint_margins (joint "
        "name -> distance to the nearer limit, negative outside; None for a continuous joint) and warnings "
        "(list of {kind, element, message}: joint_outside_limits, near_singular when sigma_min / sigma_max "
        "of J* < 1e-3).");
  m.attr("NEAR_SINGULAR_RATIO") = kNearSingularRatio;
}

}  // namespace kdl_space::python
