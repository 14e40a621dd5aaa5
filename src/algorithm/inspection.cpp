#include "kdl_space/algorithm/inspection.hpp"

#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/algorithm/recursive_ex_iit.hpp"
#include "kdl_space/spatial/errors.hpp"

namespace kdl_space {
namespace {

int fail(Inspection& out, int at, const char* what, int rc) {
  out.failed_at = at;
  out.failed = what;
  return rc;
}

/// The quantities every route takes from a FreeFloatingSolver (of either extent): p_h, the frame,
/// J*, J, G_locked and their conditioning.
int jacobianFigures(FreeFloatingSolver& solver, const Contact& h, ContactInspection& c) {
  const unsigned int n = solver.model().nj();
  KDL::Jacobian J_star(n), J(n);
  int rc = solver.contactPoint(h, c.point);
  if (rc == E_NOERROR) rc = solver.J_star(h, J_star);
  if (rc == E_NOERROR) rc = solver.G_locked(h, c.G_locked);
  if (rc != E_NOERROR) return rc;
  c.J_star = J_star.data;
  c.frame = solver.bodyPose(h.body) * KDL::Frame(h.offset);
  return E_NOERROR;
}

int fixedBaseFigures(FreeFloatingSolver& solver, const Contact& h, ContactInspection& c) {
  KDL::Jacobian J(solver.model().nj());
  if (const int rc = solver.J(h, J)) return rc;
  c.J = J.data;
  c.conditioning = conditioning(c.J_star, c.J);
  return E_NOERROR;
}

/// G* (and, where H is positive definite, the grounded G) at h by `Solver`; both routes' solvers
/// answer the same calls.
template <class Solver>
int inertiaFigures(Solver& solver, const Contact& h, ContactInspection& c, Inspection& out, int at) {
  if (const int rc = solver.G_star(h, c.G_star)) return fail(out, at, "contact quantities", rc);
  Matrix6d G;
  const int rc = solver.G(h, Response::Grounded, G);
  if (rc == E_NOERROR) c.G_grounded = G;
  else if (rc != E_NOT_POSITIVE_DEFINITE) return fail(out, at, "grounded G", rc);
  return E_NOERROR;
}

/// G* over all contact points from the recursion: column by column, the twist jump at every
/// contact h_i (shifted from the base's jump, plus J_i dqdot) from a unit impulse at h_j (eq. 18).
int G_star_all(RecursiveExIITSolver& recursive, const Vector3d& p_b, const std::vector<Contact>& contacts,
               Inspection& out) {
  const Eigen::Index k = static_cast<Eigen::Index>(contacts.size());
  out.G_star_all.setZero(6 * k, 6 * k);
  KDL::JntArray dqdot(recursive.model().nj());
  for (Eigen::Index j = 0; j < k; ++j)
    for (int c = 0; c < 6; ++c) {
      Vector6d d_base;
      if (const int rc = recursive.velocityJump(contacts[j], Vector6d::Unit(c), d_base, dqdot)) return rc;
      for (Eigen::Index i = 0; i < k; ++i) {
        const ContactInspection& at = out.contacts[i];
        out.G_star_all.block<6, 1>(6 * i, 6 * j + c) = shiftTwist(d_base, at.point - p_b) + at.J * dqdot.data;
      }
    }
  symmetrize(out.G_star_all);
  return out.G_star_all.allFinite() ? E_NOERROR : E_NOT_FINITE;
}

void poll(const std::function<bool()>& cancelled, std::size_t i, std::size_t k) {
  if (cancelled && cancelled())
    throw Cancelled("inspect: cancelled at contact " + std::to_string(i + 1) + " of " + std::to_string(k));
}

}  // namespace

int inspect(const std::shared_ptr<const FloatingModel>& model, const State& state,
            const std::vector<Contact>& contacts, Inspection& out, const std::function<bool()>& cancelled,
            unsigned int dense_joints) {
  out = Inspection();
  out.dense = model->nj() <= dense_joints;
  const auto extent = out.dense ? FreeFloatingSolver::Extent::Full : FreeFloatingSolver::Extent::Jacobians;
  FreeFloatingSolver solver(model, extent);
  std::optional<RecursiveExIITSolver> recursive;  // the O(n) route's G*, above kDenseJoints
  if (!out.dense) recursive.emplace(model);
  int rc = solver.compute(state);
  if (rc == E_NOERROR && recursive) rc = recursive->compute(state);
  if (rc != E_NOERROR) return fail(out, -1, "free-floating quantities", rc);
  out.mass = solver.w();
  out.r_g = solver.r_g();
  out.I_g = solver.I_g();
  if (out.dense) out.H_star = solver.H_star().data;
  const int k = static_cast<int>(contacts.size());
  out.contacts.resize(contacts.size());
  for (int i = 0; i < k; ++i) {
    poll(cancelled, static_cast<std::size_t>(i), contacts.size());
    ContactInspection& c = out.contacts[i];
    if (const int rc_J = jacobianFigures(solver, contacts[i], c)) return fail(out, i, "contact quantities", rc_J);
    const int rc_G = out.dense ? inertiaFigures(solver, contacts[i], c, out, i)
                               : inertiaFigures(*recursive, contacts[i], c, out, i);
    if (rc_G != E_NOERROR) return rc_G;
    if (const int rc_J = fixedBaseFigures(solver, contacts[i], c)) return fail(out, i, "fixed-base J", rc_J);
  }
  if (out.dense) {
    out.G_star_all.resize(6 * k, 6 * k);
    rc = solver.G_star(contacts, out.G_star_all);
  } else {
    rc = G_star_all(*recursive, toEigen(state.world_T_base.p), contacts, out);
  }
  if (rc != E_NOERROR) return fail(out, k, "G* over all contact points", rc);
  return E_NOERROR;
}

}  // namespace kdl_space
