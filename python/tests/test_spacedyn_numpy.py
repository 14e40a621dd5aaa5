"""The SpaceDyn reference evaluator (spacedyn_numpy) checked on its own: its reader on small .m
files, its conventions (rpy2dc), closed forms derived by hand (a planar revolute link and a
prismatic link on a free base, a fixed-base planar 2R arm), and, on a 3-D tree of revolute and
prismatic joints, symmetry and positive definiteness of HH, the momentum and energy HH gives
against finite differences of the kinematics, the Jacobians against finite differences, and J*'s
zero-momentum meaning. No kdl_space."""
import math

import numpy as np
import pytest

import spacedyn_numpy as sd

TOL = dict(rtol=1e-12, atol=1e-12)
FD = dict(rtol=1e-6, atol=1e-7)


# ----------------------------------------------------------------------------------------------
# fixtures: .m text in the format the exporter writes

def g(x):
    return "%.17g" % float(x)


def row(v):
    return "[" + " ".join(g(x) for x in np.ravel(v)) + "]"


def col(v):
    return "[" + "; ".join(g(x) for x in np.ravel(v)) + "]"


def mat(M, multiline=False):
    M = np.atleast_2d(np.asarray(M, dtype=float))
    sep = ";\n    " if multiline else "; "
    return "[" + sep.join(" ".join(g(x) for x in r) for r in M) + "]"


def lp_text(name, n, BB, J_type, c0, cc, Qi, m0, m, inertia0, inertia, SE, ce, Qe):
    """A SpaceDyn LP function file; cc a 3xnxn array (nonzero columns written one by one)."""
    S0 = [1 if b == 0 else 0 for b in BB]
    SS = -np.eye(n)
    for j, b in enumerate(BB):
        if b:
            SS[b - 1, j] = 1
    L = [f"% {name}: written for the test", f"function LP = {name}_LP()", "",
         f"LP.num_q = {n};   % joints"]
    if n == 0:
        L += ["LP.BB = zeros(1,0);", "LP.J_type = '';", "LP.S0 = zeros(1,0);", "LP.SS = zeros(0,0);",
              "LP.SE = zeros(1,0);", "LP.c0 = zeros(3,0);", "LP.cc = zeros(3,0,0);", "LP.ce = zeros(3,0);",
              "LP.Qi = zeros(3,0);", "LP.Qe = zeros(3,0);", "LP.m = zeros(1,0);", "LP.inertia = zeros(3,0);"]
    else:
        L += [f"LP.BB = {row(BB)};", f"LP.J_type = '{J_type}';  % 'R' revolute, 'P' prismatic",
              f"LP.S0 = {row(S0)};", f"LP.SS = {mat(SS, multiline=True)};", f"LP.SE = {row(SE)};",
              f"LP.c0 = {mat(c0)};", f"LP.cc = zeros(3, {n}, {n});"]
        for i in range(n):
            for j in range(n):
                if np.any(cc[:, i, j]):
                    L.append(f"LP.cc(:,{i + 1},{j + 1}) = {col(cc[:, i, j])};")
        L += [f"LP.ce = {mat(ce)};", f"LP.Qi = {mat(Qi)};", f"LP.Qe = {mat(Qe)};", f"LP.m = {row(m)};",
              f"LP.inertia = {mat(np.hstack(inertia), multiline=True)};"]
    L += [f"LP.m0 = {g(m0)};", f"LP.inertia0 = {mat(inertia0, multiline=True)};",
          "LP.mass = LP.m0 + sum(LP.m);", "end", ""]
    return "\n".join(L)


def sv_text(name, R0, Q0, v0, w0, q, qd):
    A0 = sd.rpy2dc(Q0).T
    qs = col(q) if len(q) else "zeros(0,1)"
    qds = col(qd) if len(qd) else "zeros(0,1)"
    return "\n".join([f"function SV = {name}_SV()", f"SV.R0 = {col(R0)};", f"SV.A0 = {mat(A0)};",
                      f"SV.Q0 = {col(Q0)};", f"SV.v0 = {col(v0)};", f"SV.w0 = {col(w0)};",
                      f"SV.q = {qs};", f"SV.qd = {qds};", "end", ""])


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def Rx(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def Ry(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def Rz(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rodrigues(w):
    t = np.linalg.norm(w)
    if t == 0:
        return np.eye(3)
    K = sd.tilde(np.asarray(w) / t)
    return np.eye(3) + math.sin(t) * K + (1 - math.cos(t)) * K @ K


def moved(SV, x, h):
    """The state after moving for time h at generalized velocity x = (v0, w0, qd) (first order)."""
    n = len(x) - 6
    out = dict(SV)
    out["R0"] = np.ravel(SV["R0"]) + h * x[:3]
    out["A0"] = rodrigues(h * x[3:6]) @ np.asarray(SV["A0"])
    out["q"] = np.ravel(SV["q"]) + h * x[6:] if n else np.zeros(0)
    return out


def skew_part(M):
    return np.array([M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1]]) / 2


def body_velocities(LP, SV, x, h=1e-6):
    """[(centroid velocity, angular velocity)] of the base and the links, by central differences
    of kinematics along x (independent of the Jacobians)."""
    plus, minus = moved(SV, x, h), moved(SV, x, -h)
    Ap, Rp = sd.kinematics(LP, plus)[:2]
    Am, Rm = sd.kinematics(LP, minus)[:2]
    A0 = sd.kinematics(LP, SV)[0]
    out = [((np.ravel(plus["R0"]) - np.ravel(minus["R0"])) / (2 * h),
            skew_part((plus["A0"] - minus["A0"]) / (2 * h) @ np.asarray(SV["A0"]).T))]
    for i in range(len(A0)):
        out.append(((Rp[:, i] - Rm[:, i]) / (2 * h), skew_part((Ap[i] - Am[i]) / (2 * h) @ A0[i].T)))
    return out


def end_point_twist(LP, SV, k, x, h=1e-6):
    (pp, Op), (pm, Om), (_, O) = (sd.end_points(LP, moved(SV, x, h))[k - 1],
                                  sd.end_points(LP, moved(SV, x, -h))[k - 1], sd.end_points(LP, SV)[k - 1])
    return np.concatenate([(pp - pm) / (2 * h), skew_part((Op - Om) / (2 * h) @ O.T)])


def random_inertia(rng, scale):
    Q = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    d = rng.uniform(0.5, 1.5, 3) * scale
    d[2] = min(d[2], 0.9 * (d[0] + d[1]))  # the triangle inequality of a real body
    return Q @ np.diag(d) @ Q.T


@pytest.fixture
def tree(tmp_path):
    """A 3-D tree: two branches on the base, revolute and prismatic joints, random geometry."""
    rng = np.random.default_rng(7)
    n, BB, J_type = 6, [0, 1, 2, 1, 0, 5], "RPRRPR"
    c0 = np.zeros((3, n))
    cc = np.zeros((3, n, n))
    for j, b in enumerate(BB):
        if b == 0:
            c0[:, j] = rng.normal(size=3)
        else:
            cc[:, b - 1, j] = rng.normal(size=3) * 0.5
        cc[:, j, j] = rng.normal(size=3) * 0.3
    Qi = rng.uniform(-1, 1, (3, n))
    m = rng.uniform(0.5, 3, n)
    inertia = [random_inertia(rng, 0.2) for _ in range(n)]
    SE = [0, 0, 1, 1, 0, 1]
    ce, Qe = rng.normal(size=(3, n)) * 0.4, rng.uniform(-1, 1, (3, n))
    lp = write(tmp_path, "tree_LP.m", lp_text("tree", n, BB, J_type, c0, cc, Qi, 40.0, m,
                                             random_inertia(rng, 5.0), inertia, SE, ce, Qe))
    sv = write(tmp_path, "tree_SV.m", sv_text("tree", rng.normal(size=3), rng.uniform(-1, 1, 3),
                                             rng.normal(size=3), rng.normal(size=3),
                                             rng.uniform(-1, 1, n), rng.normal(size=n)))
    return sd.parse_m_file(lp), sd.parse_m_file(sv)


# ----------------------------------------------------------------------------------------------
# conventions

def test_rpy2dc_convention():
    t = 0.7
    assert np.allclose(sd.rpy2dc(0, 0, t).T, [[math.cos(t), -math.sin(t), 0], [math.sin(t), math.cos(t), 0], [0, 0, 1]], **TOL)
    assert np.allclose(sd.cx(t).T @ [0, 1, 0], [0, math.cos(t), math.sin(t)], **TOL)  # positive about x
    assert np.allclose(sd.cy(t).T @ [0, 0, 1], [math.sin(t), 0, math.cos(t)], **TOL)  # positive about y
    r, p, y = 0.3, -1.1, 2.0
    assert np.allclose(sd.rpy2dc(r, p, y).T, Rx(r) @ Ry(p) @ Rz(y), **TOL)
    assert np.allclose(sd.rpy2dc([r, p, y]), sd.rpy2dc(r, p, y), **TOL)
    assert np.allclose(sd.tilde([1, 2, 3]) @ [4, 5, 6], np.cross([1, 2, 3], [4, 5, 6]), **TOL)


# ----------------------------------------------------------------------------------------------
# the reader

def test_reader_reads_the_subset(tmp_path):
    path = write(tmp_path, "r_LP.m", "\n".join([
        "% header comment",
        "function LP = r_LP()",
        "  % indented comment",
        "LP.num_q = 2;",
        "LP.J_type = 'RP';   % 'a % in a comment'",
        "LP.note = 'it''s 100% fine';",
        "LP.BB = [0 1];",
        "LP.m = [1.2345678901234567e-05, -0];",
        "LP.inertia = [1 0 0 2 0 0   % first row",
        "              0 1 0 0 2 0",
        "              0 0 1 0 0 2];",
        "LP.A = [1 2 3; 4 5 6];",
        "LP.c = [1; 2; 3];",
        "LP.cc = zeros(3, 2, 2);",
        "LP.cc(:,1,2) = [0.1; 0.2; 0.3];",
        "LP.cc(:,2,2) = [4 5 6];",
        "LP.c0 = zeros(3,2);",
        "LP.c0(:,2) = [7; 8; 9];",
        "LP.m0 = 3;",
        "LP.mass = LP.m0 + sum(LP.m);",
        "end",
        "% trailing comment"]))
    LP = sd.parse_m_file(path)
    assert LP["__var__"] == "LP" and LP["__name__"] == "r_LP"
    assert LP["num_q"] == 2 and sd.num_q(LP) == 2
    assert LP["J_type"] == "RP" and LP["note"] == "it's 100% fine"
    assert LP["BB"].shape == (1, 2) and LP["c"].shape == (3, 1)
    assert LP["m"][0, 0] == 1.2345678901234567e-05 and LP["m"][0, 1] == 0 and math.copysign(1, LP["m"][0, 1]) < 0
    assert np.array_equal(LP["inertia"], np.hstack([np.eye(3), 2 * np.eye(3)]))
    assert np.array_equal(LP["A"], [[1, 2, 3], [4, 5, 6]])
    assert LP["cc"].shape == (3, 2, 2)
    assert np.array_equal(LP["cc"][:, 0, 1], [0.1, 0.2, 0.3]) and np.array_equal(LP["cc"][:, 1, 1], [4, 5, 6])
    assert not LP["cc"][:, :, 0].any() and not LP["cc"][:, 1, 0].any()
    assert np.array_equal(LP["c0"], [[0, 7], [0, 8], [0, 9]])
    assert LP["mass"] == 3 + 1.2345678901234567e-05 and sd.total_mass(LP) == LP["mass"]


@pytest.mark.parametrize("bad, line", [
    ("LP.x = foo(3);", 4),            # an unknown function
    ("x = 3;", 4),                    # not a field of LP
    ("SV.x = 3;", 4),                 # another variable
    ("LP.x = [1 2; 3];", 4),          # ragged rows
    ("LP.x = [1 inf];", 4),           # not a finite number
    ("LP.x = [1 2*3];", 4),           # an expression
    ("LP.x = 1; LP.y = 2;", 4),       # two statements
    ("LP.num_q = 4;", 4),             # assigned twice
    ("LP.cc(:,3,1) = [1; 2; 3];", 4),  # index out of range
    ("LP.cc(:,1) = [1; 2; 3];", 4),    # wrong number of indices
    ("LP.cc(:,1,1) = [1; 2];", 4),     # wrong size
    ("LP.y(:,1) = [1; 2; 3];", 4),     # indexed before it exists
    ("LP.x = zeros(3);", 4),          # zeros needs 2 or 3 sizes
    ("LP.x = [1 2", 4),               # never closed
    ("LP.x = 'abc;", 4),              # unterminated string
    ("LP.mass = LP.m0 + sum(LP.m);", 4),  # derived before m0, m
])
def test_reader_refuses_with_the_line(tmp_path, bad, line):
    text = "function LP = bad_LP()\nLP.num_q = 1;\nLP.cc = zeros(3,1,1);\n"
    path = write(tmp_path, "bad_LP.m", text + bad + "\nend\n")
    with pytest.raises(sd.SpaceDynParseError, match=rf"bad_LP\.m:{line}:"):
        sd.parse_m_file(path)


def test_reader_refuses_a_missing_function_line_and_text_after_end(tmp_path):
    with pytest.raises(sd.SpaceDynParseError, match=r":1:.*function"):
        sd.parse_m_file(write(tmp_path, "a.m", "LP.num_q = 1;\n"))
    with pytest.raises(sd.SpaceDynParseError, match=r":4:.*after 'end'"):
        sd.parse_m_file(write(tmp_path, "b.m", "function LP = b()\nLP.num_q = 0;\nend\nLP.m0 = 1;\n"))
    with pytest.raises(sd.SpaceDynParseError, match=r":3:"):
        sd.parse_m_file(write(tmp_path, "c.m", "function LP = c()\nLP.num_q = 0;\nLP.x = [1 2]]; \nend\n"))


# ----------------------------------------------------------------------------------------------
# closed forms

def planar_revolute(tmp_path, q, th0=0.4, gamma=0.3, a=0.8, b=0.6, e=0.5, m0=30.0, m1=4.0, I0=5.0, I1=0.7):
    lp = lp_text("pr", 1, [0], "R", np.array([[a], [0], [0]]), np.array([[[-b]], [[0]], [[0]]]),
                 np.array([[0], [0], [gamma]]), m0, [m1], np.diag([7.0, 8.0, I0]), [np.diag([0.9, 1.1, I1])],
                 [1], np.array([[e], [0], [0]]), np.zeros((3, 1)))
    sv = sv_text("pr", [1.0, -2.0, 0.0], [0, 0, th0], [0, 0, 0], [0, 0, 0], [q], [0])
    return sd.parse_m_file(write(tmp_path, "pr_LP.m", lp)), sd.parse_m_file(write(tmp_path, "pr_SV.m", sv))


@pytest.mark.parametrize("q", [0.0, 0.9, -2.5, math.pi])
def test_planar_revolute_link_closed_form(tmp_path, q):
    """Base (m0, I0 about z) and one link (m1, I1), joint at a along the base's x, link centroid
    at b along the link's x, relative angle phi = gamma + q (gamma = Qi's yaw). With zero linear
    momentum the centroid G is fixed and the translational energy is (mu/2)|d'|^2 with
    d = a e(th0) + b e(th0 + phi), mu = m0 m1 / (m0 + m1). With w = th0', T = 1/2 [A w^2 +
    B (w + q')^2 + 2 C w (w + q')], A = I0 + mu a^2, B = I1 + mu b^2, C = mu a b cos(phi). Zero
    angular momentum: w = alpha q', alpha = -(B + C)/(A + B + 2C), leaving
    H* = (A B - C^2) / (A + B + 2C). End point at e beyond the link centroid along its x:
    p_e = G + (m0/M) d + e e(th1), so J*_v = (m0 a/M) alpha e'(th0) + (m0 b/M + e)(1 + alpha) e'(th1),
    J*_w = (0, 0, 1 + alpha), e'(t) = (-sin t, cos t, 0)."""
    th0, gamma, a, b, e, m0, m1, I0, I1 = 0.4, 0.3, 0.8, 0.6, 0.5, 30.0, 4.0, 5.0, 0.7
    LP, SV = planar_revolute(tmp_path, q)
    M, mu, phi = m0 + m1, m0 * m1 / (m0 + m1), gamma + q
    A, B, C = I0 + mu * a * a, I1 + mu * b * b, mu * a * b * math.cos(phi)
    Hs = sd.generalized_inertia(LP, SV)
    assert Hs.shape == (1, 1)
    assert np.allclose(Hs[0, 0], (A * B - C * C) / (A + B + 2 * C), **TOL)

    e0 = np.array([math.cos(th0), math.sin(th0), 0])
    e1 = np.array([math.cos(th0 + phi), math.sin(th0 + phi), 0])
    R0 = np.array([1.0, -2.0, 0.0])
    AA, RR, JP, JA = sd.kinematics(LP, SV)
    assert np.allclose(RR[:, 0], R0 + a * e0 + b * e1, **TOL)
    assert np.allclose(JP[:, 0], R0 + a * e0, **TOL) and np.allclose(JA[:, 0], [0, 0, 1], **TOL)
    assert np.allclose(AA[0], Rz(th0 + phi), **TOL)
    (pe, Oe), = sd.end_points(LP, SV)
    assert np.allclose(pe, R0 + a * e0 + (b + e) * e1, **TOL) and np.allclose(Oe, Rz(th0 + phi), **TOL)

    alpha = -(B + C) / (A + B + 2 * C)
    perp = lambda t: np.array([-math.sin(t), math.cos(t), 0])  # noqa: E731
    v = (m0 * a / M) * alpha * perp(th0) + (m0 * b / M + e) * (1 + alpha) * perp(th0 + phi)
    Js = sd.generalized_jacobian(LP, SV, 1)
    assert Js.shape == (6, 1)
    assert np.allclose(Js[:, 0], np.concatenate([v, [0, 0, 1 + alpha]]), **TOL)


@pytest.mark.parametrize("h, q", [(0.0, 0.0), (0.0, 0.7), (0.25, 0.0), (-0.4, -0.3)])
def test_prismatic_link_closed_form(tmp_path, h, q):
    """A link sliding along the base's x: c0 = (a, h, 0), Qi = (0, pi/2, 0) so the link's z (the
    slide) is the base's x and the link's x is the base's -z (its inertia about the inertial z is
    the link's Ixx), link centroid b ahead of the joint on the slide (cc = (0, 0, -b)). Relative
    position d = (s, h), s = a + b + q, in the base frame; with zero linear momentum
    T = mu/2 [(q' - w h)^2 + w^2 s^2] + (I0 + I1)/2 w^2; zero angular momentum gives
    w = mu h q' / (mu (h^2 + s^2) + I0 + I1) and H* = mu - (mu h)^2 / (mu (h^2 + s^2) + I0 + I1):
    the reduced mass m0 m1/(m0 + m1) when the slide passes through both centroids (h = 0)."""
    a, b, m0, m1, I0, I1, th0 = 0.5, 0.2, 20.0, 3.0, 4.0, 0.6, -0.8
    lp = lp_text("pp", 1, [0], "P", np.array([[a], [h], [0]]), np.array([[[0]], [[0]], [[-b]]]),
                 np.array([[0], [math.pi / 2], [0]]), m0, [m1], np.diag([9.0, 9.5, I0]),
                 [np.diag([I1, 0.3, 0.4])], [0], np.zeros((3, 1)), np.zeros((3, 1)))
    R0 = np.array([0.3, 0.2, -1.0])
    sv = sv_text("pp", R0, [0, 0, th0], [0, 0, 0], [0, 0, 0], [q], [0])
    LP, SV = sd.parse_m_file(write(tmp_path, "pp_LP.m", lp)), sd.parse_m_file(write(tmp_path, "pp_SV.m", sv))
    mu, s = m0 * m1 / (m0 + m1), a + b + q
    expected = mu - (mu * h) ** 2 / (mu * (h * h + s * s) + I0 + I1)
    assert np.allclose(sd.generalized_inertia(LP, SV), [[expected]], **TOL)
    if h == 0:
        assert np.allclose(expected, mu, **TOL)
    AA, RR, JP, JA = sd.kinematics(LP, SV)
    x0 = Rz(th0)
    assert np.allclose(JA[:, 0], x0[:, 0], **TOL)
    assert np.allclose(JP[:, 0], R0 + x0 @ [a, h, 0], **TOL)  # fixed in the base, whatever q
    assert np.allclose(RR[:, 0], R0 + x0 @ [a + b + q, h, 0], **TOL)
    assert sd.end_points(LP, SV) == []


def test_fixed_base_planar_2r_arm(tmp_path):
    """With the base at rest, HH's joint block is the fixed-base inertia of the planar 2R arm
    (l1, lc1, lc2 along the links' x): H11 = I1 + I2 + m1 lc1^2 + m2 (l1^2 + lc2^2 + 2 l1 lc2 c2),
    H12 = I2 + m2 (lc2^2 + l1 lc2 c2), H22 = I2 + m2 lc2^2; the end point at l2 along link 2 has
    J_v = [-l1 s1 - l2 s12, -l2 s12; l1 c1 + l2 c12, l2 c12], J_w = [1 1] about z. With a base
    10^9 times heavier H* and J* tend to those."""
    l1, lc1, l2, lc2, m1, m2, I1, I2 = 1.0, 0.4, 0.8, 0.3, 2.0, 1.5, 0.2, 0.1
    q1, q2 = 0.6, -1.2
    cc = np.zeros((3, 2, 2))
    cc[:, 0, 0], cc[:, 0, 1], cc[:, 1, 1] = [-lc1, 0, 0], [l1 - lc1, 0, 0], [-lc2, 0, 0]

    def load(m0, I0):
        lp = lp_text("arm", 2, [0, 1], "RR", np.zeros((3, 2)), cc, np.zeros((3, 2)), m0, [m1, m2],
                     I0 * np.eye(3), [np.diag([0.5, 0.5, I1]), np.diag([0.4, 0.4, I2])], [0, 1],
                     np.array([[0, l2 - lc2], [0, 0], [0, 0]]), np.zeros((3, 2)))
        sv = sv_text("arm", [0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0], [q1, q2], [0, 0])
        return (sd.parse_m_file(write(tmp_path, "arm_LP.m", lp)), sd.parse_m_file(write(tmp_path, "arm_SV.m", sv)))

    c2, s1, c1, s12, c12 = math.cos(q2), math.sin(q1), math.cos(q1), math.sin(q1 + q2), math.cos(q1 + q2)
    H = np.array([[I1 + I2 + m1 * lc1 ** 2 + m2 * (l1 ** 2 + lc2 ** 2 + 2 * l1 * lc2 * c2), I2 + m2 * (lc2 ** 2 + l1 * lc2 * c2)],
                  [I2 + m2 * (lc2 ** 2 + l1 * lc2 * c2), I2 + m2 * lc2 ** 2]])
    J = np.array([[-l1 * s1 - l2 * s12, -l2 * s12], [l1 * c1 + l2 * c12, l2 * c12], [0, 0], [0, 0], [0, 0], [1, 1]])
    LP, SV = load(10.0, 3.0)
    assert np.allclose(sd.system_inertia(LP, SV)[6:, 6:], H, **TOL)
    assert np.allclose(sd.end_point_jacobian(LP, SV, 1)[:, 6:], J, **TOL)
    LP, SV = load(1e9, 1e9)
    assert np.allclose(sd.generalized_inertia(LP, SV), H, rtol=1e-7, atol=0)
    assert np.allclose(sd.generalized_jacobian(LP, SV, 1), J, rtol=0, atol=1e-7)


# ----------------------------------------------------------------------------------------------
# properties on a 3-D tree

def state_vector(SV):
    return np.concatenate([np.ravel(SV["v0"]), np.ravel(SV["w0"]), np.ravel(SV["qd"])])


def test_topology_and_mass(tree):
    LP, _ = tree
    S0, SS = sd.connectivity(LP)
    assert np.array_equal(S0, [1, 0, 0, 0, 1, 0])
    assert np.array_equal(SS, [[-1, 1, 0, 1, 0, 0], [0, -1, 1, 0, 0, 0], [0, 0, -1, 0, 0, 0],
                               [0, 0, 0, -1, 0, 0], [0, 0, 0, 0, -1, 1], [0, 0, 0, 0, 0, -1]])
    assert np.array_equal(SS, LP["SS"]) and np.array_equal(S0, np.ravel(LP["S0"]))
    assert sd.chain(LP, 3) == [1, 2, 3] and sd.chain(LP, 4) == [1, 4] and sd.chain(LP, 6) == [5, 6]
    assert sd.total_mass(LP) == pytest.approx(40.0 + np.sum(LP["m"]), rel=1e-15) == LP["mass"]


def test_base_orientation_is_A0(tree):
    _, SV = tree
    assert np.allclose(sd.rpy2dc(np.ravel(SV["Q0"])).T, SV["A0"], **TOL)


def test_joint_points_and_axes(tree):
    """Joint i lies at R0 + A0 c0(:,i) or RR_BB + A_BB cc(:,BB,i) (fixed in the parent); a
    revolute joint's point is fixed in its own link too, a prismatic link moves along A_i Ez."""
    LP, SV = tree
    AA, RR, JP, JA = sd.kinematics(LP, SV)
    R0, A0 = np.ravel(SV["R0"]), SV["A0"]
    BB = np.ravel(LP["BB"]).astype(int)
    for i in range(6):
        b = BB[i]
        expected = R0 + A0 @ LP["c0"][:, i] if b == 0 else RR[:, b - 1] + AA[b - 1] @ LP["cc"][:, b - 1, i]
        assert np.allclose(JP[:, i], expected, **TOL)
        assert np.allclose(np.linalg.norm(JA[:, i]), 1, **TOL)
        assert np.allclose(AA[i].T @ AA[i], np.eye(3), **TOL) and np.linalg.det(AA[i]) > 0
        own = RR[:, i] + AA[i] @ LP["cc"][:, i, i]
        if LP["J_type"][i] == "R":
            assert np.allclose(JP[:, i], own, **TOL)
        else:
            assert np.allclose(own - JP[:, i], np.ravel(SV["q"])[i] * JA[:, i], **TOL)
    shifted = dict(SV, q=np.ravel(SV["q"]) + np.eye(6)[1] * 0.37)  # the prismatic joint 2
    _, RR2, JP2, _ = sd.kinematics(LP, shifted)
    assert np.allclose(RR2[:, 1] - RR[:, 1], 0.37 * JA[:, 1], **TOL)
    assert np.allclose(JP2[:, 1], JP[:, 1], **TOL)  # joint 2 itself stays; its descendant joint 3 slides
    assert np.allclose(JP2[:, 2] - JP[:, 2], 0.37 * JA[:, 1], **TOL)


def test_system_inertia_structure(tree):
    """HH symmetric positive definite; HH(1:3,1:3) = M E, HH(1:3,4:6) = -M tilde(rg - R0)."""
    LP, SV = tree
    HH = sd.system_inertia(LP, SV)
    assert HH.shape == (12, 12)
    assert np.allclose(HH, HH.T, **TOL)
    assert np.linalg.eigvalsh(HH).min() > 1e-6
    M = sd.total_mass(LP)
    _, RR, _, _ = sd.kinematics(LP, SV)
    R0 = np.ravel(SV["R0"])
    rg = (40.0 * R0 + RR @ np.ravel(LP["m"])) / M
    assert np.allclose(HH[:3, :3], M * np.eye(3), **TOL)
    assert np.allclose(HH[:3, 3:6], -M * sd.tilde(rg - R0), rtol=1e-12, atol=1e-11)
    Hs = sd.generalized_inertia(LP, SV)
    assert np.allclose(Hs, Hs.T, rtol=1e-10, atol=1e-12) and np.linalg.eigvalsh(Hs).min() > 0


def test_momentum_and_energy_against_finite_differences(tree):
    """HH x's first rows are the linear momentum and the angular momentum about R0 of the system,
    and x' HH x / 2 its kinetic energy, with every body's velocities from finite differences."""
    LP, SV = tree
    x = state_vector(SV)
    HH = sd.system_inertia(LP, SV)
    AA = [SV["A0"]] + sd.kinematics(LP, SV)[0]
    RR = np.column_stack([np.ravel(SV["R0"]), sd.kinematics(LP, SV)[1]])
    masses = [40.0] + list(np.ravel(LP["m"]))
    inertias = [LP["inertia0"]] + [LP["inertia"][:, 3 * i:3 * i + 3] for i in range(6)]
    P, L, T = np.zeros(3), np.zeros(3), 0.0
    for (v, w), m, A, I, r in zip(body_velocities(LP, SV, x), masses, AA, inertias, RR.T):
        Iw = A @ I @ A.T
        P += m * v
        L += np.cross(r - np.ravel(SV["R0"]), m * v) + Iw @ w
        T += 0.5 * (m * v @ v + w @ Iw @ w)
    assert np.allclose((HH @ x)[:3], P, **FD)
    assert np.allclose((HH @ x)[3:6], L, **FD)
    assert np.allclose(0.5 * x @ HH @ x, T, **FD)


def test_jacobians_against_finite_differences(tree):
    LP, SV = tree
    jac = sd.link_jacobians(LP, SV)
    for k in range(12):
        x = np.eye(12)[k]
        for (v, w), (JT, JR) in zip(body_velocities(LP, SV, x), jac):
            assert np.allclose(JT[:, k], v, **FD) and np.allclose(JR[:, k], w, **FD)
        for e in (1, 2, 3):
            assert np.allclose(sd.end_point_jacobian(LP, SV, e)[:, k], end_point_twist(LP, SV, e, x), **FD)


def test_end_points(tree):
    LP, SV = tree
    AA, RR, _, _ = sd.kinematics(LP, SV)
    ends = sd.end_points(LP, SV)
    assert len(ends) == 3
    for (p, O), i in zip(ends, [2, 3, 5]):  # links 3, 4, 6
        assert np.allclose(p, RR[:, i] + AA[i] @ LP["ce"][:, i], **TOL)
        assert np.allclose(O, AA[i] @ Rx(LP["Qe"][0, i]) @ Ry(LP["Qe"][1, i]) @ Rz(LP["Qe"][2, i]), **TOL)
    with pytest.raises(IndexError):
        sd.generalized_jacobian(LP, SV, 0)  # numbered from 1, as SpaceDyn's num_e
    with pytest.raises(IndexError):
        sd.generalized_jacobian(LP, SV, 4)


def test_generalized_jacobian_is_the_zero_momentum_motion(tree):
    """With the base moving as momentum conservation from rest requires (x_b = -H_b^-1 H_bm qd),
    the momentum is zero, the end points move (finite differences) by J* qd and the energy is
    qd' H* qd / 2."""
    LP, SV = tree
    qd = np.ravel(SV["qd"])
    HH = sd.system_inertia(LP, SV)
    xb = -np.linalg.solve(HH[:6, :6], HH[:6, 6:] @ qd)
    x = np.concatenate([xb, qd])
    assert np.allclose(HH[:6] @ x, 0, atol=1e-10)
    for e in (1, 2, 3):
        Js = sd.generalized_jacobian(LP, SV, e)
        assert Js.shape == (6, 6)
        assert np.allclose(Js @ qd, end_point_twist(LP, SV, e, x), **FD)
    assert np.allclose(0.5 * x @ HH @ x, 0.5 * qd @ sd.generalized_inertia(LP, SV) @ qd, rtol=1e-10)


# ----------------------------------------------------------------------------------------------
# no joints

def test_single_body(tmp_path):
    I0 = np.array([[2.0, 0.1, 0.0], [0.1, 3.0, 0.2], [0.0, 0.2, 4.0]])
    lp = write(tmp_path, "b_LP.m", lp_text("b", 0, [], "", None, None, None, 12.5, [], I0, [], [], None, None))
    Q0 = [0.2, -0.4, 1.0]
    sv = write(tmp_path, "b_SV.m", sv_text("b", [1, 2, 3], Q0, [0, 0, 1], [1, 0, 0], [], []))
    LP, SV = sd.parse_m_file(lp), sd.parse_m_file(sv)
    assert LP["J_type"] == "" and LP["cc"].shape == (3, 0, 0) and SV["q"].shape == (0, 1)
    AA, RR, JP, JA = sd.kinematics(LP, SV)
    assert AA == [] and RR.shape == JP.shape == JA.shape == (3, 0)
    assert sd.end_points(LP, SV) == []
    assert sd.total_mass(LP) == 12.5 == LP["mass"]
    A0 = sd.rpy2dc(Q0).T
    HH = sd.system_inertia(LP, SV)
    assert np.allclose(HH, np.block([[12.5 * np.eye(3), np.zeros((3, 3))], [np.zeros((3, 3)), A0 @ I0 @ A0.T]]), **TOL)
    assert sd.generalized_inertia(LP, SV).shape == (0, 0)
    assert sd.connectivity(LP)[1].shape == (0, 0)
    with pytest.raises(IndexError):
        sd.generalized_jacobian(LP, SV, 1)
