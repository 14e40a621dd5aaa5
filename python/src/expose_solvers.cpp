// kdl_space.FreeFloatingSolver and RecursiveExIITSolver: compute(state) with the GIL released,
// then the centroid terms, J, J*, H, H*, G* (one or several contacts), grounded and locked G.
#include <kdl/jacobian.hpp>

#include "conversions.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/recursive_ex_iit.hpp"

namespace kdl_space::python {
namespace {

/// A solver with its model, whether its last compute succeeded, and the lock of one thread at a time.
template <class Solver>
struct Wrapped {
  template <class... Options>
  explicit Wrapped(const Model& m, Options... options) : model(m), solver(m.ptr, options...) {}
  Model model;
  Solver solver;
  bool computed = false;
  std::mutex mutex;

  void compute(const PyState& s, const char* who) {
    if (s.model.get() != model.ptr.get() && s.model->nj() != model.ptr->nj())
      throw py::value_error(std::string("state: a state of another model (") + std::to_string(s.model->nj()) +
                            " joints, this one has " + std::to_string(model.ptr->nj()) + ")");
    const State state = s.state;
    const int code = withoutGil(mutex, [&] {
      const int c = solver.compute(state);
      computed = c == 0;
      return c;
    });
    check(code, who);
  }
  void ready(const char* who) const {
    if (!computed) check(E_NOT_COMPUTED, who);
  }
};
using FFS = Wrapped<FreeFloatingSolver>;
using Rec = Wrapped<RecursiveExIITSolver>;

/// A 6x6 contact query (G*, grounded G, locked G) with the GIL released.
template <class W, class Query>
py::array_t<double> contact6(W& w, const PyContact& c, const char* who, Query q) {
  checkContact(*w.model.ptr, c);
  Matrix6d G;
  const int code = withoutGil(w.mutex, [&] { return q(w.solver, c.contact, G); });
  check(code, std::string(who) + " at '" + c.link + "'");
  return toNumpy(G);
}

template <class Jac>
py::array_t<double> jacobian(FFS& w, const PyContact& c, const char* who, Jac q) {
  checkContact(*w.model.ptr, c);
  KDL::Jacobian J(w.model.ptr->nj());
  const int code = withoutGil(w.mutex, [&] { return q(w.solver, c.contact, J); });
  check(code, std::string(who) + " at '" + c.link + "'");
  return toNumpy(J.data);
}

/// A query of H or H* on a solver built with extent 'jacobians' (it forms neither): say so.
void needsMassMatrix(const FFS& w, const std::string& who) {
  if (w.solver.extent() == FreeFloatingSolver::Extent::Jacobians)
    throw ComputeError(E_NOT_COMPUTED, who + ": this solver was built with extent='jacobians' and forms no H or H* "
                                             "(build FreeFloatingSolver(model) for it, or use RecursiveExIITSolver)");
}

template <class Get>
auto result(FFS& w, const char* who, Get get) {
  w.ready(who);
  return withoutGil(w.mutex, [&] { return Eigen::MatrixXd(get(w.solver)); });
}

}  // namespace

void bindSolvers(py::module_& m) {
  py::class_<FFS>(m, "FreeFloatingSolver",
                  "The paper's dense quantities at one state: w, r_g, I_g, M_a, A_m, H, H* and, per contact, "
                  "J, J*, G*, grounded and locked G (world frame; joint-indexed rows and columns in "
                  "`joint_names` order). compute(state) first; one thread at a time per solver.")
      .def(py::init([](const Model& m, const std::string& extent) {
             if (extent != "full" && extent != "jacobians")
               throw py::value_error("extent: '" + extent + "' is not one of 'full', 'jacobians'");
             return std::make_unique<FFS>(m, extent == "full" ? FreeFloatingSolver::Extent::Full
                                                              : FreeFloatingSolver::Extent::Jacobians);
           }), py::arg("model"), py::arg("extent") = "full",
           "A solver for `model` (build one per thread). extent 'jacobians': compute forms the centroid terms "
           "and A_m only, O(n) with no n x n matrix (J, J*, momentum, G_locked answer; H and H* are empty; "
           "G_star, G_grounded raise ComputeError E_NOT_COMPUTED): for J* of a robot of thousands of links.")
      .def_property_readonly("joint_names", [](const FFS& w) { return w.model.ptr->jointNames(); },
                             "The order of joint-indexed values.")
      .def("compute", [](FFS& w, const PyState& s) { w.compute(s, "FreeFloatingSolver.compute"); }, py::arg("state"),
           "Centroid terms, H and H* at `state` (GIL released); ComputeError (e.g. E_NOT_FINITE) on failure.")
      .def_property_readonly("w", [](FFS& w) { w.ready("w"); return w.solver.w(); }, "Total mass [kg].")
      .def_property_readonly("r_g", [](FFS& w) { return toNumpy(result(w, "r_g", [](auto& s) { return s.r_g(); }), true); },
                             "System CoM [m], (3,).")
      .def_property_readonly("I_g", [](FFS& w) { return toNumpy(result(w, "I_g", [](auto& s) { return s.I_g(); })); },
                             "Locked inertia about the CoM (eq. 3), (3, 3).")
      .def_property_readonly("M_a", [](FFS& w) { return toNumpy(result(w, "M_a", [](auto& s) { return s.M_a(); })); },
                             "Centroid inertia diag(w E, I_g) (eq. 12), (6, 6).")
      .def_property_readonly("A_m", [](FFS& w) { return toNumpy(result(w, "A_m", [](auto& s) { return s.A_m(); })); },
                             "Momentum about r_g per unit joint rate, base still, (6, nj).")
      .def_property_readonly("H", [](FFS& w) { return toNumpy(result(w, "H", [](auto& s) { return s.H().data; })); },
                             "Fixed-base joint-space inertia, (nj, nj).")
      .def_property_readonly("H_star", [](FFS& w) {
        return toNumpy(result(w, "H_star", [](auto& s) { return s.H_star().data; }));
      }, "Generalized inertia H* = H - A_m^T M_a^-1 A_m (eq. 7), (nj, nj).")
      .def("contact_point", [](FFS& w, const PyContact& c) {
        checkContact(*w.model.ptr, c);
        Vector3d p;
        check(withoutGil(w.mutex, [&] { return w.solver.contactPoint(c.contact, p); }), "contact_point");
        return toNumpy(p, true);
      }, py::arg("contact"), "World position of the contact point [m], (3,).")
      .def("J", [](FFS& w, const PyContact& c) {
        return jacobian(w, c, "J", [](FreeFloatingSolver& s, const Contact& h, KDL::Jacobian& J) { return s.J(h, J); });
      }, py::arg("contact"), "Fixed-base Jacobian of the contact point, (6, nj).")
      .def("J_star", [](FFS& w, const PyContact& c) {
        return jacobian(w, c, "J_star", [](FreeFloatingSolver& s, const Contact& h, KDL::Jacobian& J) { return s.J_star(h, J); });
      }, py::arg("contact"), "Generalized Jacobian J* = J - R_h M_a^-1 A_m (eq. 4), (6, nj).")
      .def("G_star", [](FFS& w, const PyContact& c) {
        needsMassMatrix(w, "G_star");
        return contact6(w, c, "G_star", [](FreeFloatingSolver& s, const Contact& h, Matrix6d& G) { return s.G_star(h, G); });
      }, py::arg("contact"), "Ex-IIT G* (eq. 11), twist per impulse, (6, 6).")
      .def("G_star", [](FFS& w, const std::vector<PyContact>& cs) {
        needsMassMatrix(w, "G_star");
        std::vector<Contact> contacts;
        for (const PyContact& c : cs) {
          checkContact(*w.model.ptr, c);
          contacts.push_back(c.contact);
        }
        const long k = static_cast<long>(contacts.size());
        if (k == 0) throw py::value_error("contacts: expected at least one contact");
        Eigen::MatrixXd G(6 * k, 6 * k);
        const int code = withoutGil(w.mutex, [&] {
          w.solver.reserveContacts(contacts.size());
          return w.solver.G_star(contacts, G);
        });
        check(code, "G_star of " + std::to_string(k) + " contacts");
        return toNumpy(G);
      }, py::arg("contacts"), "The (6k, 6k) G* over k contacts: blocks J*_i H*^-1 J*_j^T + R_i M_a^-1 R_j^T.")
      .def("G_grounded", [](FFS& w, const PyContact& c) {
        needsMassMatrix(w, "G_grounded");
        return contact6(w, c, "G_grounded", [](FreeFloatingSolver& s, const Contact& h, Matrix6d& G) { return s.G_grounded(h, G); });
      }, py::arg("contact"), "Grounded G = J H^-1 J^T (eq. 22), base held; may be singular, (6, 6).")
      .def("G_locked", [](FFS& w, const PyContact& c) {
        return contact6(w, c, "G_locked", [](FreeFloatingSolver& s, const Contact& h, Matrix6d& G) { return s.G_locked(h, G); });
      }, py::arg("contact"), "Joints locked: R_h M_a^-1 R_h^T (eq. 20), (6, 6).")
      .def("momentum", [](FFS& w, const PyState& s) {
        Vector6d PL;
        const KDL::Twist t = s.velocity.base_twist;
        const KDL::JntArray qdot = s.velocity.qdot;
        check(withoutGil(w.mutex, [&] { return w.solver.momentum(t, qdot, PL); }), "momentum");
        return toNumpy6(PL);
      }, py::arg("state"), "Momentum (P_g; L_g) about r_g from the state's base twist and qdot, (6,).")
      .def("__repr__", [](const FFS& w) { return "<kdl_space.FreeFloatingSolver of " + w.model.source + ">"; });

  py::class_<Rec>(m, "RecursiveExIITSolver",
                  "G* at one contact in O(n) by the articulated-body recursion (no n x n matrix): the same "
                  "values as FreeFloatingSolver.G_star. compute(state) first; one thread at a time per solver.")
      .def(py::init<const Model&>(), py::arg("model"), "A solver for `model` (build one per thread).")
      .def("compute", [](Rec& w, const PyState& s) { w.compute(s, "RecursiveExIITSolver.compute"); }, py::arg("state"),
           "Articulated-body inertias at `state` (GIL released); ComputeError on failure.")
      .def("G_star", [](Rec& w, const PyContact& c) {
        return contact6(w, c, "G_star", [](RecursiveExIITSolver& s, const Contact& h, Matrix6d& G) { return s.G_star(h, G); });
      }, py::arg("contact"), "Ex-IIT G* (eq. 11), (6, 6).")
      .def("__repr__", [](const Rec& w) { return "<kdl_space.RecursiveExIITSolver of " + w.model.source + ">"; });
}

}  // namespace kdl_space::python
