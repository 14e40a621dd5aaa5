// kdl_space.ForwardDynamicsSolver (articulated-body, O(n)) and DenseForwardDynamicsSolver (the
// dense (6+n)^2 route, also for mimic joints): base and joint accelerations from a state, joint
// torques and external wrenches, with gravity, locked joints and a grounded base; GIL released.
#include <sstream>

#include "conversions.hpp"
#include "kdl_space/algorithm/dense_forward_dynamics.hpp"
#include "kdl_space/algorithm/forward_dynamics.hpp"
#include "simulation_types.hpp"

namespace kdl_space::python {

std::vector<bool> lockedJoints(const FloatingModel& model, py::handle obj) {
  std::vector<bool> locked(model.nj(), false);
  if (obj.is_none()) return locked;
  if (py::isinstance<py::str>(obj)) throw py::value_error("locked: expected a sequence of joint names or booleans (nj,)");
  const py::sequence s = py::reinterpret_borrow<py::sequence>(obj);
  bool all_bool = true;
  for (py::handle x : s) all_bool = all_bool && (py::isinstance<py::bool_>(x) || py::isinstance<py::int_>(x) ||
                                                 py::hasattr(x, "dtype"));
  if (all_bool && s.size() == model.nj() && s.size() > 0) {
    for (std::size_t j = 0; j < s.size(); ++j) locked[j] = argumentAs<bool>(s[j], "locked[" + std::to_string(j) + "]", "a boolean");
    return locked;
  }
  for (py::handle x : s) locked[jointArgument(model, x, "locked")] = true;
  return locked;
}

unsigned int jointArgument(const FloatingModel& model, py::handle obj, const char* name) {
  if (py::isinstance<py::str>(obj)) {
    const std::string joint = argumentAs<std::string>(obj, name, "a joint name or index");
    const int j = model.jointIndex(joint);
    if (j < 0) throw ModelError(std::string(name) + ": no joint named '" + joint + "' (Model.joint_names)");
    return static_cast<unsigned int>(j);
  }
  const long j = argumentAs<long>(obj, name, "a joint name or index");
  if (j < 0 || j >= static_cast<long>(model.nj()))
    throw py::index_error(std::string(name) + ": joint index " + std::to_string(j) + " out of range (" +
                          std::to_string(model.nj()) + " joints)");
  return static_cast<unsigned int>(j);
}

unsigned int bodyArgument(const FloatingModel& model, py::handle obj, const char* name) {
  if (py::isinstance<py::str>(obj)) {
    const std::string link = argumentAs<std::string>(obj, name, "a link name or index");
    const int b = model.bodyIndex(link);
    if (b < 0) throw ModelError(std::string(name) + ": no link named '" + link + "' (Model.link_names)");
    return static_cast<unsigned int>(b);
  }
  const long b = argumentAs<long>(obj, name, "a link name or index");
  if (b < 0 || b >= static_cast<long>(model.bodies().size()))
    throw py::index_error(std::string(name) + ": body index " + std::to_string(b) + " out of range (" +
                          std::to_string(model.bodies().size()) + " bodies)");
  return static_cast<unsigned int>(b);
}

namespace {

/// External wrenches per body: None, a dict link name -> (6,), or an array (bodies, 6).
std::vector<KDL::Wrench> wrenchesOf(const FloatingModel& model, py::handle obj) {
  if (obj.is_none()) return {};
  std::vector<KDL::Wrench> f(model.bodies().size(), KDL::Wrench::Zero());
  if (py::isinstance<py::dict>(obj)) {
    for (auto item : py::reinterpret_borrow<py::dict>(obj)) {
      const unsigned int b = bodyArgument(model, item.first, "wrenches");
      f[b] = toWrench(vec6(item.second, "wrenches[link]"));
    }
    return f;
  }
  const Eigen::MatrixXd W = fromNumpy(obj, "wrenches", static_cast<long>(f.size()), 6);
  for (std::size_t b = 0; b < f.size(); ++b) f[b] = toWrench(W.row(static_cast<long>(b)).transpose());
  return f;
}

template <class Solver>
struct FD {
  FD(const Model& m, py::handle gravity, bool grounded, py::handle locked) : model(m), solver(m.ptr) {
    setGravity(gravity);
    setGrounded(grounded);
    setLocked(locked);
  }
  Model model;
  Solver solver;
  Vector3d gravity = Vector3d::Zero();
  bool grounded = false;
  std::vector<bool> locked;
  std::mutex mutex;

  void setGravity(py::handle g) {
    const Vector3d v = g.is_none() ? Vector3d::Zero() : vec3(g, "gravity");
    withoutGil(mutex, [&] { solver.setGravity(v); });  // ModelError naming the value
    gravity = v;
  }
  void setGrounded(bool g) {
    withoutGil(mutex, [&] { solver.setGrounded(g); });
    grounded = g;
  }
  void setLocked(py::handle obj) {
    const std::vector<bool> l = lockedJoints(*model.ptr, obj);
    withoutGil(mutex, [&] { solver.setLocked(l); });
    locked = l;
  }
  py::tuple accelerations(const PyState& s, py::handle tau_obj, py::handle wrenches, const char* who) {
    if (s.model->nj() != model.ptr->nj())
      throw py::value_error("state: a state of another model (" + std::to_string(s.model->nj()) + " joints, this one has " +
                            std::to_string(model.ptr->nj()) + ")");
    KDL::JntArray tau(model.ptr->nj());
    if (!tau_obj.is_none()) tau = jointValues(*model.ptr, tau_obj, "tau");
    const std::vector<KDL::Wrench> f = wrenchesOf(*model.ptr, wrenches);
    FloatingAcceleration a;
    a.qddot.resize(model.ptr->nj());
    const State state = s.state;
    const FloatingVelocity velocity = s.velocity;
    check(withoutGil(mutex, [&] { return solver.CartToJnt(state, velocity, tau, f, a); }), who);
    return py::make_tuple(toNumpy6(a.base), toNumpyVec(a.qddot.data));
  }
};

template <class Solver>
void bindFD(py::module_& m, const char* name, const char* doc) {
  using W = FD<Solver>;
  const std::string who = std::string(name) + ".accelerations";
  py::class_<W>(m, name, doc)
      .def(py::init([](const Model& model, py::object gravity, bool grounded, py::object locked) {
             return std::make_unique<W>(model, gravity, grounded, locked);
           }),
           py::arg("model"), py::kw_only(), py::arg("gravity") = py::none(), py::arg("grounded") = false,
           py::arg("locked") = py::none(),
           "gravity: (3,) world frame [m/s^2] (None: orbit, zero); grounded: the base held still (its twist "
           "must be zero); locked: joints whose brakes are on, names or booleans (nj,).")
      .def_property_readonly("joint_names", [](const W& w) { return w.model.ptr->jointNames(); },
                             "The order of tau and qddot.")
      .def_property("gravity", [](const W& w) { return toNumpy(w.gravity, true); },
                    [](W& w, py::object g) { w.setGravity(g); }, "Gravity (3,) [m/s^2], world frame.")
      .def_property("grounded", [](const W& w) { return w.grounded; }, [](W& w, bool g) { w.setGrounded(g); },
                    "Whether the base is held still (fixed-base dynamics).")
      .def_property("locked", [](const W& w) {
        std::vector<std::string> names;
        for (std::size_t j = 0; j < w.locked.size(); ++j)
          if (w.locked[j]) names.push_back(w.model.ptr->jointNames()[j]);
        return names;
      }, [](W& w, py::object l) { w.setLocked(l); }, "Names of the joints whose brakes are on (qddot = 0).")
      .def("accelerations", [who](W& w, const PyState& s, py::object tau, py::object wrenches) {
        return w.accelerations(s, tau, wrenches, who.c_str());
      }, py::arg("state"), py::arg("tau") = py::none(), py::arg("wrenches") = py::none(),
         "(base_acceleration (6,), qddot (nj,)) at `state` (pose, q, base twist, qdot) under joint torques `tau` "
         "((nj,) or a dict by name; None: zero) and external `wrenches` (dict link name -> (f; n) (6,), or an "
         "array (links, 6); world axes, the moment about the link frame's origin). The base's is (acceleration "
         "of its origin; angular acceleration), world frame. GIL released; ComputeError on failure.")
      .def("__repr__", [name](const W& w) {
        std::ostringstream s;
        s << "<kdl_space." << name << " of " << w.model.source << ": " << w.model.ptr->nj() << " joints"
          << (w.grounded ? ", grounded" : "") << ">";
        return s.str();
      });
}

}  // namespace

void bindForwardDynamics(py::module_& m) {
  bindFD<ForwardDynamicsSolver>(
      m, "ForwardDynamicsSolver",
      "Free-floating forward dynamics in O(n) (Featherstone's articulated-body algorithm with a floating base): "
      "base and joint accelerations from a state, joint torques and external wrenches, with the velocity "
      "products, gravity, brakes and a grounded base. One thread at a time per solver.");
  bindFD<DenseForwardDynamicsSolver>(
      m, "DenseForwardDynamicsSolver",
      "The same accelerations by the composite-rigid-body route: the dense (6+n)^2 system, O(n^3); models with "
      "mimic joints too. One thread at a time per solver.");
}

}  // namespace kdl_space::python
