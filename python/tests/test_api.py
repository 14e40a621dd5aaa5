"""Shapes, names, reprs and every error path of the bindings."""
import math

import numpy as np
import pytest

import kdl_space
from conftest import ARM, CAPTURE_SCENARIO, SOURCE_DIR


@pytest.fixture
def computed(arm):
    solver = kdl_space.FreeFloatingSolver(arm)
    solver.compute(kdl_space.State(arm, q={"joint2": 0.7, "joint4": 0.8}))
    return solver


def test_model(arm):
    assert arm.nj == 7 and len(arm.joint_names) == 7
    assert arm.joint_names[0] == "joint1"
    assert "end_effector" in arm.link_names
    assert arm.total_mass > 0
    assert isinstance(arm.diagnostics, list)
    assert "space_arm7.urdf" in repr(arm) and "7 joints" in repr(arm) and "bodies" in repr(arm)
    c = arm.contact("end_effector", (0, 0, 0.05))
    assert c.link == "end_effector" and np.array_equal(c.offset, [0, 0, 0.05])
    assert "end_effector" in repr(c)


def test_state_inputs(arm):
    q = np.arange(7) * 0.1
    s = kdl_space.State(arm, q=q, base_pose=([1, 2, 3], [0, 0, math.pi / 2]), base_twist=np.ones(6), qdot={"joint3": 2})
    assert np.array_equal(s.q, q) and s.q.shape == (7,) and s.q.dtype == np.float64
    assert s.joint_names == arm.joint_names
    assert np.allclose(s.base_pose[:3, 3], [1, 2, 3]) and np.allclose(s.base_pose[:3, 0], [0, 1, 0])
    assert np.array_equal(kdl_space.State(arm, base_pose=s.base_pose).base_pose, s.base_pose)
    assert np.array_equal(s.qdot, [0, 0, 2, 0, 0, 0, 0])
    assert np.array_equal(s.base_twist, np.ones(6))
    assert np.array_equal(arm.state(q=q).q, q)


def test_shapes(arm, computed):
    c = arm.contact("end_effector")
    assert computed.joint_names == arm.joint_names
    shapes = {"r_g": (3,), "I_g": (3, 3), "M_a": (6, 6), "A_m": (6, 7), "H": (7, 7), "H_star": (7, 7)}
    for name, shape in shapes.items():
        a = getattr(computed, name)
        assert a.shape == shape and a.dtype == np.float64, name
    for f in (computed.J, computed.J_star):
        assert f(c).shape == (6, 7)
    for f in (computed.G_star, computed.G_grounded, computed.G_locked):
        G = f(c)
        assert G.shape == (6, 6) and np.allclose(G, G.T, atol=1e-12)
    assert computed.momentum(kdl_space.State(arm)).shape == (6,)
    assert computed.w == pytest.approx(arm.total_mass)


def test_generalized_jacobian_and_inertia_formulas(arm, computed):
    """J* = J - R_h M_a^-1 A_m and G* = J* H*^-1 J*^T + R_h M_a^-1 R_h^T from the bound pieces."""
    c = arm.contact("end_effector", (0, 0, 0.05))
    r = computed.contact_point(c) - computed.r_g
    R = np.eye(6)
    R[:3, 3:] = -np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    Minv = np.linalg.inv(computed.M_a)
    J_star = computed.J(c) - R @ Minv @ computed.A_m
    assert np.allclose(computed.J_star(c), J_star, atol=1e-12)
    G = J_star @ np.linalg.solve(computed.H_star, J_star.T) + R @ Minv @ R.T
    assert np.allclose(computed.G_star(c), G, rtol=1e-9, atol=1e-12)
    assert np.allclose(computed.G_locked(c), R @ Minv @ R.T, rtol=1e-9, atol=1e-12)
    assert np.allclose(computed.H_star, computed.H - computed.A_m.T @ Minv @ computed.A_m, atol=1e-10)


def test_multi_contact(arm, computed):
    a, b = arm.contact("end_effector"), arm.contact("link3", (0.1, 0, 0))
    G = computed.G_star([a, b])
    assert G.shape == (12, 12)
    assert np.allclose(G[:6, :6], computed.G_star(a), atol=1e-12)
    assert np.allclose(G[6:, 6:], computed.G_star(b), atol=1e-12)
    assert np.allclose(G[:6, 6:], G[6:, :6].T, atol=1e-12)
    assert computed.G_star([a, b, a]).shape == (18, 18)


def test_recursive_matches_dense(arm, computed):
    s = kdl_space.State(arm, q={"joint2": 0.7, "joint4": 0.8})
    rec = kdl_space.RecursiveExIITSolver(arm)
    rec.compute(s)
    c = arm.contact("end_effector", (0, 0, 0.05))
    assert np.allclose(rec.G_star(c), computed.G_star(c), rtol=1e-9, atol=1e-12)


def test_wrong_shapes_name_the_argument(arm, computed):
    with pytest.raises(ValueError, match=r"q: expected shape \(7,\), got \(3,\)"):
        kdl_space.State(arm, q=[1, 2, 3])
    with pytest.raises(ValueError, match=r"base_twist: expected shape \(6,\), got \(2, 3\)"):
        kdl_space.State(arm, base_twist=np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"base_pose: expected shape \(4, 4\)"):
        kdl_space.State(arm, base_pose=np.eye(3))
    # A pose is a rotation and a position: a matrix of ones, a scale or a mirror is refused, saying
    # how far it is from a rotation; the last row is (0, 0, 0, 1); no complex numbers.
    for T, far in ((np.ones((4, 4)), "3, det R = 0"), (np.diag([2.0, 2, 2, 1]), "3, det R = 8"),
                   (np.diag([1.0, 1, -1, 1]), "0, det R = -1")):
        with pytest.raises(ValueError, match=r"base_pose: the upper-left 3x3 is no rotation: max \|R\^T R - I\| = " + far):
            kdl_space.State(arm, base_pose=T)
    tilted = np.eye(4)
    tilted[3, 0] = 0.5
    with pytest.raises(ValueError, match=r"base_pose: the last row of a 4x4 pose is \(0, 0, 0, 1\), got \(0.5, 0, 0, 1\)"):
        kdl_space.State(arm, base_pose=tilted)
    with pytest.raises(ValueError, match="base_pose: expected real numbers, got a complex array"):
        kdl_space.State(arm, base_pose=np.eye(4) + 0j)
    with pytest.raises(ValueError, match="base_twist: expected real numbers, got a complex array"):
        kdl_space.State(arm, base_twist=np.zeros(6, dtype=complex))
    # A rotation to round-off is a rotation.
    c, s_ = math.cos(0.3), math.sin(0.3)
    R = np.array([[c, -s_, 0, 1], [s_, c, 0, 2], [0, 0, 1, 3], [0, 0, 0, 1]])
    assert np.allclose(kdl_space.State(arm, base_pose=R).base_pose, R, atol=1e-15)
    with pytest.raises(TypeError, match=r"qdot: expected an array of numbers of shape \(7,\)"):
        kdl_space.State(arm, qdot="fast")
    with pytest.raises(ValueError, match=r"offset: expected shape \(3,\)"):
        arm.contact("end_effector", (0, 0))
    with pytest.raises(ValueError, match=r"G_B: expected shape \(6, 6\), got \(5, 5\)"):
        kdl_space.solve_impact(np.eye(6), np.eye(5), np.zeros(6), np.zeros(6), kdl_space.ImpactLaw())
    with pytest.raises(ValueError, match=r"t_A: expected shape \(6,\)"):
        kdl_space.solve_impact(np.eye(6), np.eye(6), np.zeros(7), np.zeros(6), kdl_space.ImpactLaw())
    with pytest.raises(ValueError, match="kind: expected 'capture'"):
        kdl_space.ImpactLaw("glue")
    with pytest.raises(ValueError, match="normal"):
        kdl_space.ImpactLaw("point")


def test_nan_is_e_not_finite(arm):
    solver = kdl_space.FreeFloatingSolver(arm)
    q = np.zeros(7)
    q[3] = np.nan
    with pytest.raises(kdl_space.ComputeError, match="compute") as e:
        solver.compute(kdl_space.State(arm, q=q))
    assert e.value.code == kdl_space.E_NOT_FINITE == -102
    assert kdl_space.str_error(kdl_space.E_NOT_FINITE) in str(e.value)
    with pytest.raises(kdl_space.ComputeError) as e:  # the failed compute discarded the result
        solver.G_star(arm.contact("end_effector"))
    assert e.value.code == kdl_space.E_NOT_COMPUTED
    with pytest.raises(kdl_space.ComputeError) as e:
        solver.r_g
    assert e.value.code == kdl_space.E_NOT_COMPUTED
    with pytest.raises(kdl_space.ComputeError) as e:
        kdl_space.RecursiveExIITSolver(arm).compute(kdl_space.State(arm, base_pose=([np.inf, 0, 0], [0, 0, 0])))
    assert e.value.code == kdl_space.E_NOT_FINITE
    with pytest.raises(kdl_space.ComputeError) as e:
        kdl_space.solve_impact(np.eye(6), np.eye(6), np.full(6, np.nan), np.zeros(6), kdl_space.ImpactLaw())
    assert e.value.code == kdl_space.E_NOT_FINITE
    assert isinstance(e.value, kdl_space.Error) and isinstance(e.value, RuntimeError)


def test_model_and_input_errors(arm, computed, tmp_path):
    with pytest.raises(kdl_space.ModelError, match="no_such_link"):
        arm.contact("no_such_link")
    with pytest.raises(kdl_space.ModelError, match="no_such_joint"):
        kdl_space.State(arm, q={"no_such_joint": 1.0})
    with pytest.raises(kdl_space.ModelError, match="missing.urdf"):
        kdl_space.load_urdf(str(tmp_path / "missing.urdf"))
    broken = SOURCE_DIR / "tests" / "data" / "broken_scenarios" / "approach_zero_gain.yaml"
    with pytest.raises(kdl_space.InputError, match="approach_zero_gain.yaml"):
        kdl_space.load_scenario(str(broken))
    # a scenario whose URDF loads no model: the loader's ModelError, the scenario's file and field in front
    broken_urdf = broken.parent / "broken_urdf.yaml"
    with pytest.raises(kdl_space.ModelError, match=r"broken_urdf.yaml:3: robot.urdf: .*not_a_robot.urdf: ") as e:
        kdl_space.load_scenario(str(broken_urdf))
    assert isinstance(e.value, kdl_space.Error) and not isinstance(e.value, kdl_space.InputError)
    assert issubclass(kdl_space.InputError, kdl_space.Error) and issubclass(kdl_space.ModelError, kdl_space.Error)
    other = kdl_space.load_urdf(str(ARM))
    with pytest.raises(ValueError, match="another model"):
        computed.G_star(other.contact("end_effector"))


def test_check_urdf():
    broken = SOURCE_DIR / "tests" / "data" / "broken_urdf" / "base_without_mass.urdf"
    findings = kdl_space.check_urdf(str(broken))
    errors = [f for f in findings if f.severity == kdl_space.Severity.Error]
    assert any(f.kind == "base_without_mass" for f in errors), findings
    f = errors[0]
    assert isinstance(f.message, str) and isinstance(f.element, str) and isinstance(f.element_type, kdl_space.ElementType)
    assert repr(f).startswith("Finding(error, ") and f.kind in repr(f)
    assert not [f for f in kdl_space.check_urdf(str(ARM)) if f.severity == kdl_space.Severity.Error]


def test_impact_laws():
    G_A = np.diag([1.0, 2, 3, 4, 5, 6])
    G_B = np.eye(6) * 0.5
    t_A, t_B = np.array([0.1, 0, 0, 0, 0.2, 0]), np.zeros(6)
    i = kdl_space.solve_impact(G_A, G_B, t_A, t_B, kdl_space.ImpactLaw("capture"))
    assert i.F.shape == (6,)
    assert np.allclose(t_A + G_A @ i.F, t_B - G_B @ i.F)  # both contact twists equal afterwards
    n = np.array([1.0, 0, 0])
    p = kdl_space.solve_impact(G_A, G_B, t_A, t_B, kdl_space.ImpactLaw("point", normal=n, restitution=1.0))
    assert not p.separating and p.F[0] < 0 and np.allclose(p.F[1:], 0)
    u_after = n @ ((t_A + G_A @ p.F) - (t_B - G_B @ p.F))[:3]
    assert u_after == pytest.approx(-0.1)
    law = kdl_space.ImpactLaw("friction", normal=n, restitution=0.5, friction=0.3)
    assert law.kind == "friction" and np.array_equal(law.normal, n) and "friction=0.3" in repr(law)
    assert kdl_space.solve_impact(G_A, G_B, t_A, t_B, law).F.shape == (6,)
    with pytest.raises(kdl_space.ComputeError) as e:
        kdl_space.solve_impact(G_A, G_B, t_A, t_B, kdl_space.ImpactLaw("point", normal=n, restitution=2.0))
    assert e.value.code == kdl_space.E_BAD_ARGUMENT
    assert kdl_space.virtual_mass(G_A, n) == pytest.approx(1.0)


def test_capture_result(arm):
    r = kdl_space.solve_capture(kdl_space.load_scenario(str(CAPTURE_SCENARIO)))
    assert r.robot.joint_names == arm.joint_names and r.robot.qdot_after.shape == (7,)
    assert r.G_robot.shape == (6, 6) and r.G_target.shape == (6, 6) and r.contact_body_pose.shape == (4, 4)
    assert r.energy_lost == pytest.approx(r.energy_before - r.energy_after) and r.energy_lost > 0
    assert np.allclose(r.momentum_before, r.momentum_after, rtol=1e-9, atol=1e-12)
    assert np.allclose(r.robot.contact_twist_after[3:], r.target_twist_after[3:])
    assert "CaptureResult" in repr(r)


def test_names_in_an_iso_8859_1_urdf_are_str(tmp_path):
    """A URDF that declares ISO-8859-1 (a joint 'Handgelenk_ä' in one byte): read, its names in
    UTF-8, so joint_names is a list of str (it raised UnicodeDecodeError); the same bytes
    undeclared are refused at load with the line (issue 35, item 5)."""
    text = ARM.read_bytes().replace(b'"joint3"', '"Handgelenk_ä"'.encode("latin-1"))
    if text.startswith(b"<?xml"):
        text = text[text.index(b"?>") + 2:]
    declared = tmp_path / "latin1.urdf"
    declared.write_bytes(b'<?xml version="1.0" encoding="ISO-8859-1"?>' + text)
    model = kdl_space.load_urdf(str(declared))
    assert "Handgelenk_ä" in model.joint_names
    undeclared = tmp_path / "undeclared.urdf"
    undeclared.write_bytes(text)
    with pytest.raises(kdl_space.ModelError, match=r"undeclared.urdf: line \d+ \(near .*Handgelenk_\\xE4.*not UTF-8"):
        kdl_space.load_urdf(str(undeclared))
