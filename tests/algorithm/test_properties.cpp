// Physical properties the free-floating quantities must have (MATH.md, "Independent checks"):
// limits (heavy base -> grounded G, stiff joints -> locked G, no joints -> one rigid body),
// zero momentum motion checked by KDL forward kinematics, momentum and kinetic energy against
// the virtual-joint route, invariance under a change of base frame and of world pose, and a
// chain-built model against the same robot loaded from URDF. No expected value comes from the
// library itself.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <kdl/treefksolverpos_recursive.hpp>
#include <map>
#include <memory>
#include <random>

#include "kdl_space/impact/collision.hpp"
#include "kdl_space/algorithm/free_floating_solver.hpp"
#include "kdl_space/parsers/urdf/urdf_loader.hpp"
#include "test_util.hpp"
#include "virtual_joint_route.hpp"

namespace kdl_space::test {
namespace {

using ModelPtr = std::shared_ptr<const FloatingModel>;

struct Robot {
  std::string path;
  std::string tip;
  std::string mid_link;
};

std::vector<Robot> robots() {
  return {{urdfDir() + "/space_arm7.urdf", "end_effector", "link4"},
          {urdfDir() + "/dual_arm.urdf", "left_tool", "right_link2"},
          {urdfDir() + "/spacedyn_twolink.urdf", "hand", "link1"},
          {dataDir() + "/reference/models/arm6_public.urdf", "tool", "elbow"}};
}

ModelPtr load(const std::string& path) { return std::make_shared<const FloatingModel>(loadUrdfFile(path)); }

KDL::Vector randomVector(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return KDL::Vector(u(rng), u(rng), u(rng));
}

KDL::JntArray randomRates(unsigned int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  KDL::JntArray qdot(n);
  for (unsigned int j = 0; j < n; ++j) qdot(j) = u(rng);
  return qdot;
}

KDL::Frame randomFrame(std::mt19937& rng) {
  std::uniform_real_distribution<double> a(-M_PI, M_PI);
  return KDL::Frame(KDL::Rotation::RPY(a(rng), a(rng) / 2, a(rng)), randomVector(rng, 1.5));
}

Eigen::MatrixXd dense(const KDL::JntSpaceInertiaMatrix& m) { return m.data; }

Matrix6d blockDiag(const KDL::Rotation& R) {
  Matrix6d B = Matrix6d::Zero();
  B.topLeftCorner<3, 3>() = toEigen(R);
  B.bottomRightCorner<3, 3>() = toEigen(R);
  return B;
}

double relativeError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& ref) { return (a - ref).norm() / ref.norm(); }

// --- Limits ---------------------------------------------------------------------------------

TEST(Limits, HeavyBaseGivesGroundedG) {
  // Base mass and inertia scaled by s: G* = G + O(1/s) (MATH.md eq. 22). G from the KDL route.
  std::mt19937 rng(11);
  for (const Robot& r : robots()) {
    SCOPED_TRACE(r.path);
    const ModelPtr model = load(r.path);
    for (int s = 0; s < 3; ++s) {
      const State state = randomState(*model, rng);
      const LinkPoint p{r.tip, randomVector(rng, 0.2)};
      const Eigen::MatrixXd G = VirtualJointTree(*model, state).G_grounded(p);
      double err[2];
      const double scales[2] = {1e4, 1e8};
      for (int k = 0; k < 2; ++k) {
        const auto heavy = std::make_shared<const FloatingModel>(model->tree(), baseInertia(*model, scales[k]));
        FreeFloatingSolver solver(heavy);
        ASSERT_EQ(solver.compute(state), E_NOERROR);
        Matrix6d G_star;
        ASSERT_EQ(solver.G_star(heavy->contact(p.link, p.offset), G_star), E_NOERROR);
        err[k] = relativeError(G_star, G);
      }
      EXPECT_LT(err[1], 1e-6);
      // 1/s convergence: the errors at s = 1e4 and 1e8 differ by ~1e4 (within a factor of 10).
      EXPECT_GT(err[0] / err[1], 1e3) << err[0] << " " << err[1];
      EXPECT_LT(err[0] / err[1], 1e5) << err[0] << " " << err[1];
    }
  }
}

TEST(Limits, StiffJointsGiveLockedG) {
  // Armature a on every joint: H* grows like a, so G* = R_h M_a^-1 R_h^T + O(1/a) (eq. 20).
  // The locked G from the KDL route: the base block alone, J_b M_bb^-1 J_b^T. Armature does not
  // enter it (nor J*), so the gap is J* (H*_0 + a E)^-1 J*^T ~ ||J*||^2 / a, relative to
  // ||G_locked|| ~ 1/w: roughly w ||J*||^2 / a, i.e. up to ~1e-5 at a = 1e8 for these robots
  // (w ~ 500 kg, ||J*|| of a few metres); 1e-4 is the bound, the 1/a rate the sharper check.
  std::mt19937 rng(12);
  for (const Robot& r : robots()) {
    SCOPED_TRACE(r.path);
    const ModelPtr model = load(r.path);
    for (int s = 0; s < 3; ++s) {
      const State state = randomState(*model, rng);
      const LinkPoint p{r.tip, randomVector(rng, 0.2)};
      const VirtualJointTree route(*model, state);
      const Eigen::MatrixXd J_b = route.J_full(p).leftCols(6);
      const Eigen::MatrixXd M_bb = route.M_full().topLeftCorner(6, 6);
      const Eigen::MatrixXd G_locked = J_b * M_bb.ldlt().solve(J_b.transpose());
      double err[2];
      const double armatures[2] = {1e4, 1e8};
      for (int k = 0; k < 2; ++k) {
        const auto stiff = std::make_shared<const FloatingModel>(
            model->withArmature(std::vector<double>(model->nj(), armatures[k])));
        FreeFloatingSolver solver(stiff);
        ASSERT_EQ(solver.compute(state), E_NOERROR);
        Matrix6d G_star;
        ASSERT_EQ(solver.G_star(stiff->contact(p.link, p.offset), G_star), E_NOERROR);
        err[k] = relativeError(G_star, G_locked);
      }
      EXPECT_LT(err[1], 1e-4);
      EXPECT_GT(err[0] / err[1], 1e3) << err[0] << " " << err[1];
      EXPECT_LT(err[0] / err[1], 1e5) << err[0] << " " << err[1];
    }
  }
}

/// G* of a single rigid body at a contact point, computed independently: the inverse of its
/// spatial inertia at p_h (world axes).
Matrix6d rigidBodyG(double m, const KDL::Vector& com_base, const Matrix3d& I_com_base,
                    const KDL::Frame& world_T_base, const KDL::Vector& offset) {
  const Vector3d p_h = toEigen(world_T_base * offset);
  const Vector3d c = toEigen(world_T_base * com_base);
  const Matrix3d R = toEigen(world_T_base.M);
  const Matrix6d K = spatialInertia(m, c - p_h, R * I_com_base * R.transpose());
  return K.partialPivLu().solve(Matrix6d::Identity());
}

TEST(Limits, NoJointsIsOneRigidBody) {
  std::mt19937 rng(13);
  // (a) A one-link URDF, its inertial frame rotated and offset.
  const double m = 42.0;
  const KDL::Vector com(0.1, -0.2, 0.3);
  const KDL::Rotation R_in = KDL::Rotation::RPY(0.3, 0.2, 0.1);
  const Matrix3d I_principal = Vector3d(3.0, 4.0, 5.5).asDiagonal();
  const Matrix3d I_com = toEigen(R_in) * I_principal * toEigen(R_in).transpose();
  const std::string urdf = R"(<?xml version="1.0"?><robot name="rock"><link name="rock"><inertial>
      <origin xyz="0.1 -0.2 0.3" rpy="0.3 0.2 0.1"/><mass value="42"/>
      <inertia ixx="3" iyy="4" izz="5.5" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>)";
  const auto from_urdf = std::make_shared<const FloatingModel>(loadUrdfString(urdf, "rock.urdf"));
  // (b) A KDL tree with a root only, same body (inertia about the CoM, base axes).
  const auto from_tree = std::make_shared<const FloatingModel>(
      KDL::Tree("rock"), KDL::RigidBodyInertia(m, com,
                                               KDL::RotationalInertia(I_com(0, 0), I_com(1, 1), I_com(2, 2),
                                                                      I_com(0, 1), I_com(0, 2), I_com(1, 2))));
  for (const ModelPtr& model : {from_urdf, from_tree}) {
    ASSERT_EQ(model->nj(), 0u);
    FreeFloatingSolver solver(model);
    for (int s = 0; s < 10; ++s) {
      State state(*model);
      state.world_T_base = randomFrame(rng);
      ASSERT_EQ(solver.compute(state), E_NOERROR);
      const KDL::Vector offset = randomVector(rng, 1.0);
      const Matrix6d G_ref = rigidBodyG(m, com, I_com, state.world_T_base, offset);
      Matrix6d G;
      ASSERT_EQ(solver.G_star(model->contact("rock", offset), G), E_NOERROR);
      EXPECT_TRUE(near(G, G_ref, 1e-12, 1e-12 * G_ref.norm(), "G_star of one rigid body"));
      ASSERT_EQ(solver.G_locked(model->contact("rock", offset), G), E_NOERROR);
      EXPECT_TRUE(near(G, G_ref, 1e-12, 1e-12 * G_ref.norm(), "G_locked of one rigid body"));
    }
  }
}

// --- Zero momentum --------------------------------------------------------------------------

/// The frame F advanced by a constant twist t (linear velocity of F's origin, angular velocity,
/// world axes) over h: origin + v h, orientation Rot(w h) F.
///
/// Not KDL::addDelta: in KDL 1.5.1, KDL::Rot(rotvec) (used by addDelta) returns the identity
/// whenever |rotvec.x()| is the largest component and below KDL::epsilon = 1e-6, because
/// Vector::Norm() applies its epsilon cut-off in that branch only (KDL::Rot(Vector(5e-7, 1e-7,
/// 1e-7)) == Identity, KDL::Rot(Vector(1e-7, 5e-7, 1e-7)) is not). With dt = 1e-6 every base
/// rotation step is that small. Rotation::Rot2 (unit axis, angle) has no cut-off.
KDL::Frame advance(const KDL::Frame& F, const KDL::Twist& t, double h) {
  const double rate = std::sqrt(KDL::dot(t.rot, t.rot));
  const KDL::Rotation step = rate > 0.0 ? KDL::Rotation::Rot2(t.rot / rate, rate * h) : KDL::Rotation::Identity();
  return KDL::Frame(step * F.M, F.p + t.vel * h);
}

/// Angular velocity from two orientations 2h apart (world axes): the vee of the skew part of
/// R_plus R_minus^T = exp(2h [w]x) is sin(2h|w|) w/|w|, i.e. 2h w to O(h^3). (KDL::diff is not
/// used: Rotation::GetRot() returns zero below an angle of ~1e-6 rad, its epsilon.)
Vector3d angularRate(const KDL::Rotation& R_minus, const KDL::Rotation& R_plus, double h) {
  const Matrix3d D = toEigen(R_plus) * toEigen(R_minus).transpose();
  return Vector3d(D(2, 1) - D(1, 2), D(0, 2) - D(2, 0), D(1, 0) - D(0, 1)) / (2.0 * 2.0 * h);
}

TEST(ZeroMomentum, ContactPointMovesByJStarQdot) {
  // With the base twist that keeps (P_g; L_g) = 0, the contact point moves by J* qdot (eq. 4).
  // Positions by KDL forward kinematics only: base pose advanced by the base twist over +-dt
  // (advance() above), link pose from TreeFkSolverPos_recursive on the model's tree at
  // q +- dt qdot, premultiplied by the base pose, times the offset. Central difference,
  // dt = 1e-6: truncation O(dt^2) ~ 1e-12, round-off ~ eps |p| / dt ~ 1e-16 / 1e-6 = 1e-10, so
  // 1e-6 relative is a safe bound that still catches any error in J* above a millionth.
  std::mt19937 rng(14);
  const double dt = 1e-6;
  for (const Robot& r : robots()) {
    SCOPED_TRACE(r.path);
    const ModelPtr model = load(r.path);
    FreeFloatingSolver solver(model);
    KDL::TreeFkSolverPos_recursive fk(model->tree());
    for (int s = 0; s < 5; ++s) {
      const State state = randomState(*model, rng);
      ASSERT_EQ(solver.compute(state), E_NOERROR);
      const KDL::JntArray qdot = randomRates(model->nj(), rng);
      KDL::Twist base_twist;
      ASSERT_EQ(solver.baseTwist(Vector6d::Zero(), qdot, base_twist), E_NOERROR);
      const std::vector<LinkPoint> points{{r.tip, randomVector(rng, 0.3)}, {r.mid_link, randomVector(rng, 0.3)}};
      for (const LinkPoint& p : points) {
        SCOPED_TRACE(p.link);
        KDL::Frame at[2];
        for (int k = 0; k < 2; ++k) {
          const double h = k == 0 ? -dt : dt;
          KDL::JntArray q(model->nj());
          q.data = state.q.data + h * qdot.data;  // model order = the tree's q_nr
          KDL::Frame base_T_link;
          ASSERT_GE(fk.JntToCart(q, base_T_link, p.link), 0);
          at[k] = advance(state.world_T_base, base_twist, h) * base_T_link;
        }
        const Vector3d v_fd = toEigen((at[1] * p.offset - at[0] * p.offset) / (2 * dt));
        const Vector3d w_fd = angularRate(at[0].M, at[1].M, dt);
        KDL::Jacobian J_star(model->nj());
        ASSERT_EQ(solver.J_star(model->contact(p.link, p.offset), J_star), E_NOERROR);
        const Vector6d t = J_star.data * qdot.data;
        EXPECT_TRUE(near(v_fd, t.head<3>(), 1e-6, 1e-6 * t.head<3>().norm(), "linear velocity"));
        EXPECT_TRUE(near(w_fd, t.tail<3>(), 1e-6, 1e-6 * t.tail<3>().norm(), "angular velocity"));
        // handTwist with zero momentum is the same twist.
        KDL::Twist t_h;
        ASSERT_EQ(solver.handTwist(model->contact(p.link, p.offset), qdot, Vector6d::Zero(), t_h), E_NOERROR);
        EXPECT_TRUE(near(toEigen(t_h), (Vector6d() << v_fd, w_fd).finished(), 1e-6, 1e-6 * t.norm(), "handTwist"));
      }
    }
  }
}

// --- Momentum and kinetic energy ------------------------------------------------------------

TEST(Momentum, AgainstVirtualJointRouteAndRoundTrip) {
  std::mt19937 rng(15);
  for (const Robot& r : robots()) {
    SCOPED_TRACE(r.path);
    const ModelPtr model = load(r.path);
    const int n = static_cast<int>(model->nj());
    FreeFloatingSolver solver(model);
    for (int s = 0; s < 5; ++s) {
      const State state = randomState(*model, rng);
      ASSERT_EQ(solver.compute(state), E_NOERROR);
      const VirtualJointTree route(*model, state);
      const KDL::JntArray qdot = randomRates(model->nj(), rng);
      const KDL::Twist base_twist(randomVector(rng, 1.0), randomVector(rng, 0.5));
      Eigen::VectorXd v_full(6 + n);
      v_full << toEigen(base_twist), qdot.data;

      // Mass and CoM: a sum over the virtual tree's segments (KDL forward kinematics).
      double w = 0.0;
      Vector3d first_moment = Vector3d::Zero();
      for (const auto& [name, element] : route.tree().getSegments()) {
        const KDL::RigidBodyInertia& I = GetTreeElementSegment(element).getInertia();
        if (I.getMass() == 0.0) continue;
        w += I.getMass();
        first_moment += I.getMass() * toEigen(route.pose(name) * I.getCOG());
      }
      const Vector3d r_g = first_moment / w;
      // The virtual generalized momentum M_full v_full: (P; L about the base origin p_b).
      const Eigen::VectorXd gen = route.M_full() * v_full;
      const Vector3d P = gen.head<3>();
      const Vector3d p_b = toEigen(state.world_T_base.p);
      Vector6d PL_ref;
      PL_ref << P, gen.segment<3>(3) + (p_b - r_g).cross(P);  // moment moved to r_g

      Vector6d PL;
      ASSERT_EQ(solver.momentum(base_twist, qdot, PL), E_NOERROR);
      EXPECT_TRUE(near(PL, PL_ref, 1e-9, 1e-12 * PL_ref.norm(), "momentum (P_g; L_g)"));

      // Round trip with an arbitrary momentum.
      Vector6d PL_any;
      PL_any << toEigen(randomVector(rng, 100.0)), toEigen(randomVector(rng, 100.0));
      KDL::Twist back;
      ASSERT_EQ(solver.baseTwist(PL_any, qdot, back), E_NOERROR);
      Vector6d PL_again;
      ASSERT_EQ(solver.momentum(back, qdot, PL_again), E_NOERROR);
      EXPECT_TRUE(near(PL_again, PL_any, 1e-9, 1e-12 * PL_any.norm(), "momentum round trip"));
      ASSERT_EQ(solver.baseTwist(PL, qdot, back), E_NOERROR);
      EXPECT_TRUE(near(toEigen(back), toEigen(base_twist), 1e-9, 1e-12 * toEigen(base_twist).norm(),
                       "base twist round trip"));
    }
  }
}

TEST(KineticEnergy, AgainstVirtualJointRouteAndBodySum) {
  std::mt19937 rng(16);
  for (const Robot& r : robots()) {
    SCOPED_TRACE(r.path);
    const ModelPtr model = load(r.path);
    const int n = static_cast<int>(model->nj());
    FreeFloatingSolver solver(model);
    for (int s = 0; s < 5; ++s) {
      const State state = randomState(*model, rng);
      ASSERT_EQ(solver.compute(state), E_NOERROR);
      const VirtualJointTree route(*model, state);
      const KDL::JntArray qdot = randomRates(model->nj(), rng);
      const KDL::Twist base_twist(randomVector(rng, 1.0), randomVector(rng, 0.5));
      Eigen::VectorXd v_full(6 + n);
      v_full << toEigen(base_twist), qdot.data;

      // (a) 1/2 v^T M_full v.
      const double T_matrix = 0.5 * v_full.dot(route.M_full() * v_full);
      // (b) Sum over bodies of 1/2 t^T I t, each body's twist from the KDL Jacobian of its
      // frame, in its own axes, with its KDL inertia (about its frame origin).
      double T_bodies = 0.0;
      for (const auto& [name, element] : route.tree().getSegments()) {
        const KDL::RigidBodyInertia& I = GetTreeElementSegment(element).getInertia();
        if (I.getMass() == 0.0) continue;
        const Vector6d t_world = route.J_full({name, KDL::Vector::Zero()}) * v_full;
        const KDL::Twist t_body = route.pose(name).M.Inverse(toTwist(t_world));
        T_bodies += 0.5 * KDL::dot(t_body, I * t_body);
      }
      EXPECT_NEAR(T_matrix, T_bodies, 1e-12 * T_bodies);

      double T;
      ASSERT_EQ(solver.kineticEnergy(base_twist, qdot, T), E_NOERROR);
      EXPECT_NEAR(T, T_bodies, 1e-9 * T_bodies);
    }
  }
}

// --- Invariance -----------------------------------------------------------------------------

/// Adds, below `parent_name` of `dst`, a copy of every segment below `src`.
void copySubtree(const KDL::SegmentMap::const_iterator& src, const std::string& parent_name, KDL::Tree& dst) {
  for (const auto& child : GetTreeElementChildren(src->second)) {
    ASSERT_TRUE(dst.addSegment(GetTreeElementSegment(child->second), parent_name));
    copySubtree(child, child->first, dst);
  }
}

bool rotational(KDL::Joint::JointType t) {
  return t == KDL::Joint::RotAxis || t == KDL::Joint::RotX || t == KDL::Joint::RotY || t == KDL::Joint::RotZ;
}

/// The same robot with its base frame moved to B' = B * T: base inertia re-expressed, every
/// segment hanging on the base re-expressed in B'.
FloatingModel rebased(const FloatingModel& model, const KDL::Frame& T) {
  const KDL::Frame T_inv = T.Inverse();
  const auto root = model.tree().getRootSegment();
  KDL::Tree tree(root->first);
  for (const auto& child : GetTreeElementChildren(root->second)) {
    const KDL::Segment& seg = GetTreeElementSegment(child->second);
    const KDL::Joint& joint = seg.getJoint();
    const KDL::Joint moved =
        joint.getType() == KDL::Joint::None
            ? KDL::Joint(joint.getName(), KDL::Joint::None)
            : KDL::Joint(joint.getName(), T_inv * joint.JointOrigin(), T_inv.M * joint.JointAxis(),
                         rotational(joint.getType()) ? KDL::Joint::RotAxis : KDL::Joint::TransAxis);
    // KDL::Segment takes the tip pose at q = 0.
    EXPECT_TRUE(tree.addSegment(KDL::Segment(seg.getName(), moved, T_inv * seg.pose(0.0), seg.getInertia()),
                                root->first));
    copySubtree(child, child->first, tree);
  }
  return FloatingModel(tree, T_inv * baseInertia(model));
}

/// Column/row permutation: joint j of `a` is joint perm[j] of `b` (by name).
std::vector<int> byName(const FloatingModel& a, const FloatingModel& b) {
  std::vector<int> perm;
  for (const std::string& name : a.jointNames()) perm.push_back(b.jointIndex(name));
  return perm;
}

TEST(Invariance, BaseFrameChoice) {
  std::mt19937 rng(17);
  for (const Robot& r : robots()) {
    SCOPED_TRACE(r.path);
    const ModelPtr model = load(r.path);
    const int n = static_cast<int>(model->nj());
    for (int s = 0; s < 4; ++s) {
      const KDL::Frame T = randomFrame(rng);
      const auto moved = std::make_shared<const FloatingModel>(rebased(*model, T));
      ASSERT_EQ(moved->nj(), model->nj());
      const std::vector<int> perm = byName(*model, *moved);
      for (int j : perm) ASSERT_GE(j, 0);

      const State state = randomState(*model, rng);
      State state2(*moved);
      state2.world_T_base = state.world_T_base * T;
      for (int j = 0; j < n; ++j) state2.q(perm[j]) = state.q(j);
      FreeFloatingSolver a(model), b(moved);
      ASSERT_EQ(a.compute(state), E_NOERROR);
      ASSERT_EQ(b.compute(state2), E_NOERROR);

      Eigen::MatrixXd H_star_b(n, n);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) H_star_b(i, j) = b.H_star()(perm[i], perm[j]);
      EXPECT_TRUE(near(H_star_b, dense(a.H_star()), 1e-9, 1e-12 * dense(a.H_star()).norm(), "H_star"));

      const KDL::Vector base_offset = randomVector(rng, 0.5);
      const std::vector<std::pair<Contact, Contact>> contacts{
          {model->contact(r.tip, KDL::Vector(0.05, -0.1, 0.2)), moved->contact(r.tip, KDL::Vector(0.05, -0.1, 0.2))},
          {model->contact(r.mid_link), moved->contact(r.mid_link)},
          {model->contact(model->bodies()[0].name, base_offset),
           moved->contact(model->bodies()[0].name, T.Inverse() * base_offset)}};
      for (const auto& [ha, hb] : contacts) {
        SCOPED_TRACE(model->bodies()[ha.body].name);
        KDL::Jacobian Ja(n), Jb(n);
        ASSERT_EQ(a.J_star(ha, Ja), E_NOERROR);
        ASSERT_EQ(b.J_star(hb, Jb), E_NOERROR);
        Eigen::MatrixXd Jb_ordered(6, n);
        for (int j = 0; j < n; ++j) Jb_ordered.col(j) = Jb.data.col(perm[j]);
        EXPECT_TRUE(near(Jb_ordered, Ja.data, 1e-9, 1e-12 * Ja.data.norm(), "J_star"));
        Matrix6d Ga, Gb;
        ASSERT_EQ(a.G_star(ha, Ga), E_NOERROR);
        ASSERT_EQ(b.G_star(hb, Gb), E_NOERROR);
        EXPECT_TRUE(near(Gb, Ga, 1e-9, 1e-12 * Ga.norm(), "G_star"));
      }
    }
  }
}

TEST(Invariance, WorldPose) {
  // Moving the whole system by W: G*' = B G* B^T, J*' = B J*, H*' = H*, B = blockdiag(R, R).
  std::mt19937 rng(18);
  for (const Robot& r : robots()) {
    SCOPED_TRACE(r.path);
    const ModelPtr model = load(r.path);
    const int n = static_cast<int>(model->nj());
    FreeFloatingSolver a(model), b(model);
    for (int s = 0; s < 4; ++s) {
      const State state = randomState(*model, rng);
      const KDL::Frame W = randomFrame(rng);
      State state2 = state;
      state2.world_T_base = W * state.world_T_base;
      ASSERT_EQ(a.compute(state), E_NOERROR);
      ASSERT_EQ(b.compute(state2), E_NOERROR);
      const Matrix6d B = blockDiag(W.M);
      EXPECT_TRUE(near(dense(b.H_star()), dense(a.H_star()), 1e-9, 1e-12 * dense(a.H_star()).norm(), "H_star"));
      EXPECT_TRUE(near(b.r_g(), toEigen(W * toKDL(a.r_g())), 1e-9, 1e-12 * a.r_g().norm(), "r_g"));
      for (const Contact& h : {model->contact(r.tip, randomVector(rng, 0.3)), model->contact(r.mid_link)}) {
        KDL::Jacobian Ja(n), Jb(n);
        ASSERT_EQ(a.J_star(h, Ja), E_NOERROR);
        ASSERT_EQ(b.J_star(h, Jb), E_NOERROR);
        const Eigen::MatrixXd J_ref = B * Ja.data;
        EXPECT_TRUE(near(Jb.data, J_ref, 1e-9, 1e-12 * J_ref.norm(), "J_star"));
        Matrix6d Ga, Gb;
        ASSERT_EQ(a.G_star(h, Ga), E_NOERROR);
        ASSERT_EQ(b.G_star(h, Gb), E_NOERROR);
        const Matrix6d G_ref = B * Ga * B.transpose();
        EXPECT_TRUE(near(Gb, G_ref, 1e-9, 1e-12 * G_ref.norm(), "G_star"));
      }
    }
  }
}

// --- Tree vs chain --------------------------------------------------------------------------

TEST(TreeVsChain, SpaceArm7FromUrdfAndFromKdlChain) {
  const ModelPtr tree_model = load(urdfDir() + "/space_arm7.urdf");
  KDL::Chain chain;
  ASSERT_TRUE(tree_model->tree().getChain("satellite", "end_effector", chain));
  // The satellite's <inertial> as written in space_arm7.urdf (inertial frame not rotated).
  const KDL::RigidBodyInertia base(400.0, KDL::Vector(0.025, -0.018, 0.035),
                                   KDL::RotationalInertia(135.578, 152.433, 166.989, -0.467268, -4.29761, 2.559));
  const auto chain_model = std::make_shared<const FloatingModel>(chain, base, "satellite");
  ASSERT_EQ(chain_model->nj(), tree_model->nj());
  const int n = static_cast<int>(tree_model->nj());
  const std::vector<int> perm = byName(*tree_model, *chain_model);
  for (int j : perm) ASSERT_GE(j, 0);

  auto same = [](const Eigen::MatrixXd& x, const Eigen::MatrixXd& ref, const std::string& what) {
    return near(x, ref, 1e-12, 1e-12 * ref.norm(), what);
  };
  auto rows = [&](const Eigen::MatrixXd& m) {  // chain joint order -> tree joint order (rows)
    Eigen::MatrixXd o(m.rows(), m.cols());
    for (int j = 0; j < n; ++j) o.row(j) = m.row(perm[j]);
    return o;
  };
  auto cols = [&](const Eigen::MatrixXd& m) {
    Eigen::MatrixXd o(m.rows(), m.cols());
    for (int j = 0; j < n; ++j) o.col(j) = m.col(perm[j]);
    return o;
  };

  FreeFloatingSolver a(tree_model), b(chain_model);
  std::mt19937 rng(19);
  for (int s = 0; s < 10; ++s) {
    const State state = randomState(*tree_model, rng);
    State state2(*chain_model);
    state2.world_T_base = state.world_T_base;
    for (int j = 0; j < n; ++j) state2.q(perm[j]) = state.q(j);
    ASSERT_EQ(a.compute(state), E_NOERROR);
    ASSERT_EQ(b.compute(state2), E_NOERROR);
    EXPECT_NEAR(b.w(), a.w(), 1e-12 * a.w());
    EXPECT_TRUE(same(b.r_g(), a.r_g(), "r_g"));
    EXPECT_TRUE(same(b.I_g(), a.I_g(), "I_g"));
    EXPECT_TRUE(same(b.M_a(), a.M_a(), "M_a"));
    EXPECT_TRUE(same(cols(b.A_m()), a.A_m(), "A_m"));
    EXPECT_TRUE(same(rows(cols(dense(b.H()))), dense(a.H()), "H"));
    EXPECT_TRUE(same(rows(cols(dense(b.H_star()))), dense(a.H_star()), "H_star"));
    const KDL::Vector offset = randomVector(rng, 0.2);
    for (const char* link : {"end_effector", "link3", "satellite"}) {
      SCOPED_TRACE(link);
      const Contact ha = tree_model->contact(link, offset), hb = chain_model->contact(link, offset);
      KDL::Jacobian Ja(n), Jb(n);
      ASSERT_EQ(a.J(ha, Ja), E_NOERROR);
      ASSERT_EQ(b.J(hb, Jb), E_NOERROR);
      EXPECT_TRUE(same(cols(Jb.data), Ja.data, "J"));
      ASSERT_EQ(a.J_star(ha, Ja), E_NOERROR);
      ASSERT_EQ(b.J_star(hb, Jb), E_NOERROR);
      EXPECT_TRUE(same(cols(Jb.data), Ja.data, "J_star"));
      Matrix6d Ga, Gb;
      ASSERT_EQ(a.G_star(ha, Ga), E_NOERROR);
      ASSERT_EQ(b.G_star(hb, Gb), E_NOERROR);
      EXPECT_TRUE(same(Gb, Ga, "G_star"));
      ASSERT_EQ(a.G_grounded(ha, Ga), E_NOERROR);
      ASSERT_EQ(b.G_grounded(hb, Gb), E_NOERROR);
      EXPECT_TRUE(same(Gb, Ga, "G_grounded"));
      ASSERT_EQ(a.G_locked(ha, Ga), E_NOERROR);
      ASSERT_EQ(b.G_locked(hb, Gb), E_NOERROR);
      EXPECT_TRUE(same(Gb, Ga, "G_locked"));
    }
  }
}

}  // namespace
}  // namespace kdl_space::test
