"""SpaceDyn's LP and SV as kdl_space writes them, checked by an evaluation written from SpaceDyn's
own definitions (spacedyn_numpy: its calc_aa/calc_pos kinematics, the system inertia from the link
Jacobians; no kdl_space): the system inertia HH (6 + n, SpaceDyn's coordinates), the generalized
inertia H*, the generalized Jacobian J* of the contact's
end point, the mass and the contact point; then the LP read back (import) gives the same J*, H*, G*.
Every bundled robot, at random states."""
import glob
import os

import numpy as np
import pytest

import kdl_space
import spacedyn_numpy as sd

DATA = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data")
ROOT = os.path.join(os.path.dirname(__file__), "..", "..")
ROBOTS = sorted(glob.glob(os.path.join(DATA, "models", "*.urdf")) + glob.glob(os.path.join(DATA, "families", "*.urdf"))
                + glob.glob(os.path.join(ROOT, "urdf", "*.urdf")))
ROBOTS = [r for r in ROBOTS if "<mimic" not in open(r).read()]  # refused: SpaceDyn has no coupled joints (below)
MIMIC = [r for d in ("models", "families") for r in sorted(glob.glob(os.path.join(DATA, d, "*.urdf"))) if "<mimic" in open(r).read()]


def close(a, b, tol=1e-12):
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape
    if a.size:
        scale = max(1.0, np.abs(b).max())
        assert np.abs(a - b).max() <= tol * scale, np.abs(a - b).max() / scale


def random_state(model, rng):
    q = rng.uniform(-1.0, 1.0, model.nj)
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    R *= np.sign(np.linalg.det(R))
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, rng.normal(size=3)
    return model.state(q=q, base_pose=T, base_twist=rng.normal(size=6) * 0.1, qdot=rng.normal(size=model.nj) * 0.1)


def last_link_contact(model):
    return model.contact(model.link_names[-1], [0.03, -0.02, 0.05])


def export(tmp_path, state, contact):
    f = kdl_space.spacedyn_files(state, contact=contact, name="robot")
    lp, sv = tmp_path / (f["name"] + "_LP.m"), tmp_path / (f["name"] + "_SV.m")
    lp.write_text(f["lp"])
    sv.write_text(f["sv"])
    return lp, sd.parse_m_file(str(lp)), sd.parse_m_file(str(sv))


def in_spacedyn_order(model, LP):
    """Column k of SpaceDyn's joints is our joint order[k]."""
    names = list(LP["joint_names"]) if model.nj else []
    return [model.joint_names.index(n) for n in names]


def skew(a):
    return np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


def system_inertia_at(solver, SV, order):
    """Our system inertia in SpaceDyn's coordinates (v0 of the base centroid R0, w0, qd): momentum (P; L
    about R0) per unit velocity, from our centroid terms: the mass w, the CoM r_g, I_g, A_m (momentum
    about r_g per joint rate, base still) and the fixed-base H. With d = r_g - R0:
    P = w v0 - w [d]x w0 + A_m,P qd, L_R0 = L_rg + d x P."""
    w, d = solver.w, np.asarray(solver.r_g) - np.asarray(SV["R0"]).reshape(3)
    A_m = np.asarray(solver.A_m)[:, order] if order else np.zeros((6, 0))
    n = A_m.shape[1]
    HH = np.zeros((6 + n, 6 + n))
    HH[0:3, 0:3] = w * np.eye(3)
    HH[0:3, 3:6] = -w * skew(d)
    HH[3:6, 0:3] = w * skew(d)
    HH[3:6, 3:6] = np.asarray(solver.I_g) - w * skew(d) @ skew(d)
    HH[0:3, 6:] = A_m[0:3]
    HH[3:6, 6:] = A_m[3:6] + skew(d) @ A_m[0:3]
    HH[6:, :6] = HH[:6, 6:].T
    if n:
        HH[6:, 6:] = np.asarray(solver.H)[np.ix_(order, order)]
    return HH


@pytest.mark.parametrize("urdf", ROBOTS, ids=os.path.basename)
def test_the_written_lp_has_our_dynamics_by_spacedyn_definitions(urdf, tmp_path):
    model = kdl_space.load_urdf(urdf)
    rng = np.random.default_rng(7)
    for _ in range(3):
        state = random_state(model, rng)
        contact = last_link_contact(model)
        _, LP, SV = export(tmp_path, state, contact)
        order = in_spacedyn_order(model, LP)
        solver = kdl_space.FreeFloatingSolver(model)
        solver.compute(state)
        assert sd.total_mass(LP) == pytest.approx(model.total_mass, rel=1e-13)
        H_star = np.asarray(solver.H_star)[np.ix_(order, order)]
        close(sd.generalized_inertia(LP, SV), H_star)
        close(sd.system_inertia(LP, SV), system_inertia_at(solver, SV, order))
        if model.nj == 0:
            # one body: SpaceDyn's system inertia at the base centroid is the centroid inertia M_a
            close(sd.system_inertia(LP, SV), solver.M_a)
            continue
        ends = list(LP["end_names"])
        if "contact" in ends:  # the contact's end point (not on the base): its place and J*
            k = ends.index("contact")
            position, _ = sd.end_points(LP, SV)[k]
            close(position, solver.contact_point(contact))
            close(sd.generalized_jacobian(LP, SV, k + 1), np.asarray(solver.J_star(contact))[:, order])


@pytest.mark.parametrize("urdf", ROBOTS, ids=os.path.basename)
def test_import_of_the_export_is_the_same_system(urdf, tmp_path):
    model = kdl_space.load_urdf(urdf)
    rng = np.random.default_rng(11)
    state = random_state(model, rng)
    contact = last_link_contact(model)
    lp_path, LP, SV = export(tmp_path, state, contact)
    back = kdl_space.load_urdf(str(lp_path))  # the LP read as its URDF document
    assert sorted(back.joint_names) == sorted(model.joint_names)
    assert back.total_mass == pytest.approx(model.total_mass, rel=1e-13)
    # the imported base frame is SpaceDyn's: at the base centroid R0, axes A0
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = np.asarray(SV["A0"]), np.asarray(SV["R0"]).reshape(3)
    q = {n: float(state.q[model.joint_names.index(n)]) for n in model.joint_names}
    back_state = back.state(q=q, base_pose=T)
    ours, theirs = kdl_space.FreeFloatingSolver(model), kdl_space.FreeFloatingSolver(back)
    ours.compute(state)
    theirs.compute(back_state)
    perm = [back.joint_names.index(n) for n in model.joint_names]
    close(np.asarray(theirs.H_star)[np.ix_(perm, perm)], ours.H_star)
    if "contact" in list(LP["end_names"]):
        c = back.contact("contact")
        close(theirs.contact_point(c), ours.contact_point(contact))
        close(np.asarray(theirs.J_star(c))[:, perm], ours.J_star(contact))
        close(theirs.G_star(c), ours.G_star(contact))


@pytest.mark.parametrize("urdf", MIMIC, ids=os.path.basename)
def test_a_model_with_mimic_joints_is_refused_naming_the_joint(urdf):
    model = kdl_space.load_urdf(urdf)
    with pytest.raises(kdl_space.ModelError, match=r"joint '.*' follows another \(mimic\)"):
        kdl_space.spacedyn_files(model.state(), name="gripper")


def test_an_lp_statement_that_is_not_read_is_refused_with_its_line(tmp_path):
    lp = tmp_path / "bad_LP.m"
    lp.write_text("function LP = bad_LP()\nLP.num_q = 1;\nLP.BB = [0];\nx = LP.BB * 2;\nend\n")
    with pytest.raises(kdl_space.InputError, match=r"bad_LP\.m:4: .*not read"):
        kdl_space.load_urdf(str(lp))
    lp.write_text("function LP = bad_LP()\nLP.num_q = 2;\nLP.BB = [0 2];\nLP.J_type = 'RR';\n"
                  "LP.c0 = zeros(3,2);\nLP.cc = zeros(3,2,2);\nLP.Qi = zeros(3,2);\nLP.m0 = 1;\nLP.m = [1 1];\n"
                  "LP.inertia0 = [1 0 0; 0 1 0; 0 0 1];\nLP.inertia = [1 0 0 1 0 0; 0 1 0 0 1 0; 0 0 1 0 0 1];\nend\n")
    with pytest.raises(kdl_space.InputError, match=r"bad_LP\.m:3: LP\.BB: BB\(2\) = 2"):
        kdl_space.load_urdf(str(lp))
    lp.write_text("function LP = bad_LP()\nLP.num_q = 2;\nLP.BB = [0 1 2];\nend\n")
    with pytest.raises(kdl_space.InputError, match=r"bad_LP\.m:3: LP\.BB: is 1x3, expected 1x2"):
        kdl_space.load_urdf(str(lp))


@pytest.mark.parametrize("line, message", [
    ("LP.BB = [1-2];", r"an operator"),
    ("LP.BB = ;", r"no value after '='"),
    ("LP.BB = zeros(1e20, 3);", r"not a whole number in \[0, 100000\]"),
    ("LP.BB = zeros(   , 3);", r"a size or index is missing"),
    ("LP.BB = zeros(3000, 3000, 3000);", r"more than 3 dimensions or 1e7 numbers"),
    ("LP.BB(:,1e300) = [1];", r"assigned before LP\.BB has a size"),
    ("LP.BB = zeros(1, 2);\nLP.BB(:,1e300) = [1];", r"not a whole number in \[1, 100000\]"),
    ("LP.BB = zeros(1, 2);\nLP.BB(:,1 = [1];", r"only a column"),
])
def test_hostile_lp_lines_are_refused_with_their_line_never_a_crash(tmp_path, line, message):
    lp = tmp_path / "h_LP.m"
    lp.write_text("function LP = h_LP()\nLP.num_q = 2;\n" + line + "\nend\n")
    with pytest.raises(kdl_space.InputError, match=r"h_LP\.m:\d+: .*" + message):
        kdl_space.load_urdf(str(lp))
