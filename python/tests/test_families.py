"""Every public entry of the module over every model family (issue 34; the families of
tests/support/model_families.hpp, tests/data/families/*.urdf: no movable joint, one prismatic
joint, a chain, continuous joints, a tree, a mimic gripper, a massless base with zero-mass and
frame-only links). Each is checked against a route that shares no code with kdl_space: the URDF
read here with ElementTree and the free-floating system's mass matrix and Jacobians composed in
NumPy (G* = J M^-1 J^T over the base's six coordinates and the joints, the mimic joints turning
with their leaders), the rigid families' G* by the hand formula of one rigid body, the target's
momentum by hand, the forward kinematics of urdf_numpy.py; or it is refused with a message that
says why: a robot without joints has no inverse kinematics and nothing to plan (InputError, "no
movable joint"), but its G*, its capture, its motion and its studies are ordinary."""
import collections
import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import kdl_space
from conftest import SOURCE_DIR
from urdf_numpy import homogeneous, rpy_matrix, urdf_fk, urdf_limits

Family = collections.namedtuple("Family", "name contact offset other_contact joints mimic")

# Mirrors tests/support/model_families.hpp.
FAMILIES = [
    Family("rigid_body", "body", (0.4, 0.1, -0.2), "", 0, False),
    Family("rigid_bus", "grapple_fixture", (0, 0, 0.05), "sensor_frame", 0, False),
    Family("one_prismatic", "tool", (0, 0, 0), "", 1, False),
    Family("chain3", "tool", (0, 0, 0), "", 3, False),
    Family("continuous_chain", "tip", (0, 0, 0), "", 2, False),
    Family("two_arms", "left_tool", (0, 0, 0), "right_tool", 4, False),
    Family("mimic_gripper", "tool", (0, 0, 0), "right_finger", 4, True),
    Family("massless_parts", "a_tool", (0, 0, 0), "b_fore", 5, False),
]
IDS = [f.name for f in FAMILIES]
RIGID = [f for f in FAMILIES if f.joints == 0]
JOINTED = [f for f in FAMILIES if f.joints > 0]

LAWS = {
    "capture": "{type: capture}",
    "translational": "{type: translational}",
    "point": "{type: point, normal: [1, 0, 0], restitution: 0.5}",
    "friction": "{type: friction, normal: [1, 0, 0], restitution: 0.2, friction: 0.3}",
}

# The scenario's base and box (tests/families/test_families.cpp's writeScenario).
BASE_RPY = (0.1, -0.2, 0.3)
BASE_TWIST = np.array([0.01, 0, 0.02, 0.001, -0.002, 0.003])
TARGET_MASS = 40.0
TARGET_INERTIA = np.diag([2.0, 3.0, 4.0])
TARGET_POSITION = np.array([2.5, 0.5, 0.3])
TARGET_RPY = (0.2, 0.1, -0.3)
TARGET_TWIST = np.array([-0.05, 0.01, 0.02, 0.03, -0.02, 0.04])


def urdf_path(family):
    return SOURCE_DIR / "tests" / "data" / "families" / f"{family.name}.urdf"


def write_scenario(tmp_path, family, law="{type: capture}", link=None, offset=None, tag="scenario"):
    link = link or family.contact
    offset = family.offset if offset is None else offset
    path = tmp_path / f"{family.name}_{tag}.yaml"
    path.write_text(
        f"robot:\n  urdf: {urdf_path(family)}\n  contact: {{link: {link}, offset: [{float(offset[0])!r}, {float(offset[1])!r}, {float(offset[2])!r}]}}\n"
        "  base: {position: [0, 0, 0], rpy: [0.1, -0.2, 0.3], twist: [0.01, 0, 0.02, 0.001, -0.002, 0.003]}\n"
        "target:\n  mass: 40\n  inertia: [[2, 0, 0], [0, 3, 0], [0, 0, 4]]\n"
        "  pose: {position: [2.5, 0.5, 0.3], rpy: [0.2, 0.1, -0.3]}\n"
        "  twist: [-0.05, 0.01, 0.02, 0.03, -0.02, 0.04]\n"
        f"law: {law}\n"
        "simulation: {duration: 0.3, output_step: 0.1, integrator: dopri5, rtol: 1.0e-10, atol: 1.0e-12}\n")
    return path


def skew(r):
    return np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])


def _numbers(text, default):
    return [float(v) for v in text.split()] if text else default


class NumpyRobot:
    """The free-floating system of a URDF, composed in NumPy from its XML: link poses, each link's
    mass, CoM and inertia in the world, and Jacobians over the coordinates nu = (v of the base
    origin, w of the base, joint rates in `coordinates` order), world axes. A <mimic> joint's rate
    is multiplier times its leader's; a movable joint that is no coordinate nor mimic stays at 0."""

    def __init__(self, path, coordinates):
        root = ET.parse(path).getroot()
        self.coordinates = list(coordinates)
        self.links = {}
        for link in root.findall("link"):
            inertial = link.find("inertial")
            if inertial is None:
                self.links[link.get("name")] = None
                continue
            origin = inertial.find("origin")
            xyz = _numbers(origin.get("xyz") if origin is not None else None, [0, 0, 0])
            rpy = _numbers(origin.get("rpy") if origin is not None else None, [0, 0, 0])
            m = float(inertial.find("mass").get("value"))
            i = inertial.find("inertia")
            g = lambda k: float(i.get(k, 0))  # noqa: E731
            I = np.array([[g("ixx"), g("ixy"), g("ixz")], [g("ixy"), g("iyy"), g("iyz")], [g("ixz"), g("iyz"), g("izz")]])
            self.links[link.get("name")] = (m, np.array(xyz), rpy_matrix(*rpy), I)
        self.joints = root.findall("joint")
        children = {j.find("child").get("link") for j in self.joints}
        self.root = next(name for name in self.links if name not in children)

    def walk(self, q_by_name, world_T_base):
        """Each link's world pose and the motions above it: [(column, multiplier, type, axis, origin)]."""
        poses, motions = {self.root: world_T_base}, {self.root: []}
        pending = list(self.joints)
        while pending:
            j = next(j for j in pending if j.find("parent").get("link") in poses)
            pending.remove(j)
            parent, child = j.find("parent").get("link"), j.find("child").get("link")
            origin = j.find("origin")
            xyz = _numbers(origin.get("xyz") if origin is not None else None, [0, 0, 0])
            rpy = _numbers(origin.get("rpy") if origin is not None else None, [0, 0, 0])
            axis = np.array(_numbers(j.find("axis").get("xyz") if j.find("axis") is not None else None, [1, 0, 0]))
            axis = axis / np.linalg.norm(axis)
            name, kind = j.get("name"), j.get("type")
            column, multiplier, value = None, 1.0, q_by_name.get(name, 0.0)
            if name in self.coordinates:
                column = self.coordinates.index(name)
            mimic = j.find("mimic")
            if mimic is not None:
                multiplier = float(mimic.get("multiplier", 1))
                column = self.coordinates.index(mimic.get("joint"))
                value = multiplier * q_by_name.get(mimic.get("joint"), 0.0) + float(mimic.get("offset", 0))
            frame = poses[parent] @ homogeneous(rpy_matrix(*rpy), xyz)
            motion = np.eye(4)
            here = list(motions[parent])
            if kind in ("revolute", "continuous", "prismatic") and column is not None:
                a = frame[:3, :3] @ axis
                here.append((column, multiplier, kind, a, frame[:3, 3].copy()))
                if kind == "prismatic":
                    motion[:3, 3] = value * axis
                else:
                    c, s = math.cos(value), math.sin(value)
                    K = skew(axis)
                    motion[:3, :3] = np.eye(3) + s * K + (1 - c) * K @ K
            poses[child], motions[child] = frame @ motion, here
        return poses, motions

    def point_jacobian(self, poses, motions, link, p):
        """6 x (6 + n): (v of the point p; w of the link) per unit coordinate rate."""
        n = len(self.coordinates)
        J = np.zeros((6, 6 + n))
        J[:3, :3] = np.eye(3)
        J[:3, 3:6] = -skew(p - poses[self.root][:3, 3])
        J[3:, 3:6] = np.eye(3)
        for column, multiplier, kind, a, o in motions[link]:
            if kind == "prismatic":
                J[:3, 6 + column] += multiplier * a
            else:
                J[:3, 6 + column] += multiplier * np.cross(a, p - o)
                J[3:, 6 + column] += multiplier * a
        return J

    def bodies(self, poses):
        """(link, mass, CoM in the world, inertia about the CoM in world axes) of the massive links."""
        out = []
        for name, inertial in self.links.items():
            if inertial is None:
                continue
            m, xyz, R, I = inertial
            T = poses[name]
            out.append((name, m, T[:3, :3] @ xyz + T[:3, 3], T[:3, :3] @ R @ I @ R.T @ T[:3, :3].T))
        return out

    def at(self, q_by_name, world_T_base):
        poses, motions = self.walk(q_by_name, world_T_base)
        n = len(self.coordinates)
        M = np.zeros((6 + n, 6 + n))
        for name, m, c, I in self.bodies(poses):
            J = self.point_jacobian(poses, motions, name, c)
            M += m * J[:3].T @ J[:3] + J[3:].T @ I @ J[3:]
        return poses, motions, M

    def G(self, q_by_name, world_T_base, link, offset):
        poses, motions, M = self.at(q_by_name, world_T_base)
        p = poses[link][:3, :3] @ np.asarray(offset, dtype=float) + poses[link][:3, 3]
        J = self.point_jacobian(poses, motions, link, p)
        return J @ np.linalg.solve(M, J.T)

    def momentum(self, q_by_name, world_T_base, nu):
        """(P; L about the world origin) for the coordinate rates nu."""
        poses, motions = self.walk(q_by_name, world_T_base)
        h = np.zeros(6)
        for name, m, c, I in self.bodies(poses):
            J = self.point_jacobian(poses, motions, name, c)
            v, w = J[:3] @ nu, J[3:] @ nu
            h[:3] += m * v
            h[3:] += I @ w + np.cross(c, m * v)
        return h

    def composite(self, world_T_base):
        """Mass, CoM and inertia about the CoM of all links as one rigid body (joints at 0)."""
        poses, _ = self.walk({}, world_T_base)
        bodies = self.bodies(poses)
        w = sum(m for _, m, _, _ in bodies)
        r_g = sum(m * c for _, m, c, _ in bodies) / w
        I_g = sum(I + m * (np.dot(c - r_g, c - r_g) * np.eye(3) - np.outer(c - r_g, c - r_g)) for _, m, c, I in bodies)
        return w, r_g, I_g


def in_limits(model, path, variant=0):
    """Joint values inside the URDF's limits (read here), the same every run; continuous joints at
    angles of their own."""
    limits = urdf_limits(path)
    fractions = [0.7, 0.3, 0.62, 0.45, 0.8, 0.25, 0.55]
    angles = [1.1, -0.8, 2.2, -1.7]
    q = {}
    for j, name in enumerate(model.joint_names):
        if name in limits:
            lo, hi, _ = limits[name]
            q[name] = lo + fractions[(j + 3 * variant) % 7] * (hi - lo)
        else:
            q[name] = angles[(j + variant) % 4]
    return q


def rotation_angle(Ra, Rb):
    R = Ra.T @ Rb
    s = 0.5 * np.linalg.norm([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    return math.atan2(s, 0.5 * (np.trace(R) - 1))


def link_names(path):
    return [l.get("name") for l in ET.parse(path).getroot().findall("link")]


@pytest.mark.parametrize("family", FAMILIES, ids=IDS)
def test_g_star_at_every_link_is_the_numpy_routes(family):
    """G* (dense and recursive) at every link of the file, with an offset, at a configuration
    inside the limits and a turned, moved base: J M^-1 J^T of the NumPy route (1e-10 of its norm);
    J* is 6 x n, a robot without joints' 6 x 0 with no singular values."""
    path = urdf_path(family)
    model = kdl_space.load_urdf(str(path))
    assert model.nj == family.joints == len(model.joint_names)
    assert set(link_names(path)) <= set(model.link_names)
    q = in_limits(model, path)
    base = ([0.3, -0.1, 0.2], [0.4, -0.3, 0.2])
    state = kdl_space.State(model, q=q, base_pose=base)
    solver, recursive = kdl_space.FreeFloatingSolver(model), kdl_space.RecursiveExIITSolver(model)
    light = kdl_space.FreeFloatingSolver(model, extent="jacobians")  # J* without an n x n matrix
    for s in (solver, recursive, light):
        s.compute(state)
    route = NumpyRobot(path, model.joint_names)
    world_T_base = homogeneous(rpy_matrix(*base[1]), base[0])
    offset = (0.05, -0.02, 0.1)
    for link in link_names(path):
        contact = model.contact(link, offset)
        G_ref = route.G(q, world_T_base, link, offset)
        scale = np.linalg.norm(G_ref)
        for G in (solver.G_star(contact), recursive.G_star(contact)):
            assert G.shape == (6, 6)
            assert np.abs(G - G_ref).max() <= 1e-10 * scale, (family.name, link, G - G_ref)
        assert solver.J_star(contact).shape == (6, family.joints)
        assert solver.J(contact).shape == (6, family.joints)
        assert np.array_equal(light.J_star(contact), solver.J_star(contact))
        assert np.array_equal(light.J(contact), solver.J(contact))
        with pytest.raises(kdl_space.ComputeError, match="extent='jacobians'"):
            light.G_star(contact)
        figures = kdl_space.inspect_contact(state, contact)
        assert len(figures["J_star_singular_values"]) == min(6, family.joints)
    assert solver.w == pytest.approx(route.composite(world_T_base)[0], rel=1e-12)
    assert solver.H_star.shape == (family.joints, family.joints)
    assert light.H_star.shape == (0, 0)
    with pytest.raises(ValueError, match="extent: 'sparse' is not one of"):
        kdl_space.FreeFloatingSolver(model, extent="sparse")


@pytest.mark.parametrize("family", RIGID, ids=[f.name for f in RIGID])
def test_a_robot_without_joints_has_the_rigid_bodys_inverse_inertia(family):
    """No joints: G* at a point is one rigid body's, by hand from the URDF's links composed here:
    an impulse (f; n) at p, r = p - r_g: G = [[E/w - [r]x Ig^-1 [r]x, -[r]x Ig^-1], [Ig^-1 [r]x, Ig^-1]]."""
    path = urdf_path(family)
    model = kdl_space.load_urdf(str(path))
    base = ([0.3, -0.1, 0.2], [0.4, -0.3, 0.2])
    world_T_base = homogeneous(rpy_matrix(*base[1]), base[0])
    w, r_g, I_g = NumpyRobot(path, []).composite(world_T_base)
    solver = kdl_space.FreeFloatingSolver(model)
    solver.compute(kdl_space.State(model, base_pose=base))
    assert solver.w == pytest.approx(w, rel=1e-12)
    assert np.allclose(solver.r_g, r_g, rtol=0, atol=1e-12)
    assert np.allclose(solver.I_g, I_g, rtol=0, atol=1e-12 * np.linalg.norm(I_g))
    Ii = np.linalg.inv(I_g)
    for link in link_names(path):
        contact = model.contact(link, (0.1, 0.2, -0.1))
        p = solver.contact_point(contact)
        T = urdf_fk(path, {}, world_T_base)[link]
        assert np.allclose(p, T[:3, :3] @ [0.1, 0.2, -0.1] + T[:3, 3], rtol=0, atol=1e-12)
        rx = skew(p - r_g)
        G_hand = np.block([[np.eye(3) / w - rx @ Ii @ rx, -rx @ Ii], [Ii @ rx, Ii]])
        G = solver.G_star(contact)
        assert np.abs(G - G_hand).max() <= 1e-12 * np.abs(G_hand).max(), (link, G - G_hand)
        assert solver.J_star(contact).shape == (6, 0)
        figures = kdl_space.inspect_contact(kdl_space.State(model, base_pose=base), contact)
        assert len(figures["J_star_singular_values"]) == 0


def momentum_before(family, model):
    """The robot's momentum by the NumPy route (joints at rest at 0, the base moving with the
    scenario's twist) plus the box's by hand: (P; L about the world origin)."""
    path = urdf_path(family)
    nu = np.concatenate([BASE_TWIST, np.zeros(model.nj)])
    h = NumpyRobot(path, model.joint_names).momentum({}, homogeneous(rpy_matrix(*BASE_RPY), [0, 0, 0]), nu)
    R = rpy_matrix(*TARGET_RPY)
    v, w = TARGET_TWIST[:3], TARGET_TWIST[3:]
    h[:3] += TARGET_MASS * v
    h[3:] += R @ TARGET_INERTIA @ R.T @ w + np.cross(TARGET_POSITION, TARGET_MASS * v)
    return h


@pytest.mark.parametrize("law", list(LAWS), ids=list(LAWS))
@pytest.mark.parametrize("family", FAMILIES, ids=IDS)
def test_capture_conserves_momentum(tmp_path, family, law):
    """Each law: the momentum after is the momentum before (1e-12), which is the NumPy route's
    robot plus the box by hand (1e-10); the energy does not grow; a rigid capture leaves the hand
    moving with the box's point."""
    scenario = kdl_space.load_scenario(str(write_scenario(tmp_path, family, LAWS[law])))
    r = kdl_space.solve_capture(scenario)
    h = momentum_before(family, scenario.robot)
    assert np.abs(r.momentum_after - r.momentum_before).max() <= 1e-12 * np.linalg.norm(r.momentum_before)
    assert np.abs(r.momentum_before - h).max() <= 1e-10 * np.linalg.norm(h), (r.momentum_before, h)
    assert r.energy_after <= r.energy_before * (1 + 1e-12)
    assert r.robot.qdot_after.shape == (family.joints,)
    if law == "capture":
        w = r.target_twist_after[3:]
        point = np.concatenate([r.target_twist_after[:3] + np.cross(w, r.contact_point - TARGET_POSITION), w])
        assert np.abs(r.robot.contact_twist_after - point).max() <= 1e-12 * (np.linalg.norm(point) + 1)


@pytest.mark.parametrize("family", FAMILIES, ids=IDS)
def test_the_operation_runs_and_keeps_the_momentum(tmp_path, family):
    """run_operation: the capture, then 0.3 s of the joined motion; every sample carries the
    momentum after the capture (1e-9), the last at t = 0.3."""
    scenario = kdl_space.load_scenario(str(write_scenario(tmp_path, family)))
    r = kdl_space.run_operation(scenario, duration=0.3)
    assert r["capture"] is not None and r["simulation"] is not None
    samples = r["samples"]
    h0 = np.asarray(r["capture"]["momentum_after"])
    assert len(samples["t"]) >= 4
    assert samples["t"][-1] == pytest.approx(0.3, abs=1e-12)
    assert samples["q"].shape == (len(samples["t"]), len(r["simulation"]["joint_names"]))
    assert np.abs(samples["momentum"] - h0).max() <= 1e-9 * (np.linalg.norm(h0) + 1)


@pytest.mark.parametrize("family", FAMILIES, ids=IDS)
def test_reaction_wheels_take_momentum_and_keep_the_total(tmp_path, family):
    """run_operation with four weak reaction wheels holding the bus (robot.base_actuators): the
    momentum of the links with the wheels is the capture's momentum after at every sample (1e-9);
    the wheels' momentum, turned into world axes here (R A h from the samples' quaternions), is
    not zero; none passes its capacity; the JSON's wheels say the same peaks."""
    path = write_scenario(tmp_path, family, tag="wheels")
    text = path.read_text().replace(
        "  contact:", "  base_actuators: {wheels: {axes: [[1, 0, 0], [0, 0.6, 0.8], [0, -0.8, 0.6], [1, 1, 1]], "
        "torque_limit: 0.05, capacity: 0.01}}\n  contact:", 1).replace(
        "simulation: {", "simulation: {base_control: {attitude: {kp: 5, kd: 40, set_point: hold}}, ", 1)
    path.write_text(text)
    with pytest.warns(RuntimeWarning, match="wheel_saturated"):  # so weak they saturate
        r = kdl_space.run_operation(kdl_space.load_scenario(str(path)))
    samples = r["samples"]
    h0 = np.asarray(r["capture"]["momentum_after"])
    assert np.abs(samples["momentum"] - h0).max() <= 1e-9 * (np.linalg.norm(h0) + 1)
    h = samples["wheel_momentum"]
    assert h.shape == (len(samples["t"]), 4)
    assert np.abs(h).max() <= 0.01 * (1 + 1e-6)
    A = np.array([[1, 0, 0], [0, 0.6, 0.8], [0, -0.8, 0.6], [1, 1, 1]], float).T
    A /= np.linalg.norm(A, axis=0)
    world = []
    for (x, y, z, w), hk in zip(samples["base_quaternion"], h):
        R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                      [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                      [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
        world.append(R @ A @ hk)
    assert np.linalg.norm(world, axis=1).max() > 1e-6
    wheels = r["simulation"]["wheels"]["wheels"]
    np.testing.assert_allclose([w["peak_momentum"] for w in wheels], np.abs(h).max(axis=0), rtol=0, atol=1e-15)


@pytest.mark.parametrize("family", FAMILIES, ids=IDS)
def test_momentum_distribution_keeps_the_momentum_or_says_why_not(tmp_path, family):
    """run_operation under simulation.after_capture's momentum_distribution with three wheels:
    the momentum of links and wheels is the NumPy route's before the capture (1e-9 at every
    sample); a robot without joints is refused, naming simulation.joints."""
    path = write_scenario(tmp_path, family, tag="distribution")
    text = path.read_text().replace(
        "  contact:", "  base_actuators: {wheels: {torque_limit: 10, capacity: 10}}\n  contact:", 1)
    text = text[:text.index("simulation:")] + (
        "simulation:\n  duration: 0.3\n  output_step: 0.1\n  rtol: 1.0e-10\n  atol: 1.0e-12\n"
        "  joints: {\"*\": {pd: {kp: 50, kd: 20, set_point: hold}}}\n"
        "  base_control: {attitude: {kp: 5, kd: 40, set_point: hold}}\n"
        "  after_capture: {law: momentum_distribution}\n")
    path.write_text(text)
    if family.joints == 0:
        with pytest.raises(kdl_space.InputError, match="simulation.joints"):
            kdl_space.load_scenario(str(path))
        return
    scenario = kdl_space.load_scenario(str(path))
    r = kdl_space.run_operation(scenario)
    h = momentum_before(family, scenario.robot)
    assert np.abs(r["samples"]["momentum"] - h).max() <= 1e-9 * (np.linalg.norm(h) + 1)
    assert abs(r["simulation"]["energy_split"]["residual"]) <= 1e-9 * (r["simulation"]["energy"] + 1)


def contact_pose(path, q_by_name, world_T_base, link, offset):
    return urdf_fk(path, q_by_name, world_T_base)[link] @ homogeneous(np.eye(3), offset)


@pytest.mark.parametrize("family", FAMILIES, ids=IDS)
def test_ik_reaches_a_pose_or_says_there_is_no_movable_joint(tmp_path, family):
    """ik at the family's contact and at its other one (a mimic joint on the chain; the other arm):
    a pose of another in-limit configuration by urdf_numpy's forward kinematics (the mimic joints
    where their leaders put them) is reached to 1e-9 m and 1e-9 rad inside the limits, by state and
    by scenario; a robot without joints raises InputError saying it has no movable joint."""
    path = urdf_path(family)
    model = kdl_space.load_urdf(str(path))
    limits = urdf_limits(path)
    world_T_base = homogeneous(rpy_matrix(*BASE_RPY), [0, 0, 0])
    cases = [(family.contact, np.asarray(family.offset, dtype=float))]
    if family.other_contact:
        cases.append((family.other_contact, np.array([0.01, 0.02, 0.03])))
    for variant, (link, offset) in enumerate(cases, start=1):
        scenario = kdl_space.load_scenario(str(write_scenario(tmp_path, family, link=link, offset=offset, tag=f"ik_{link}")))
        seed = kdl_space.State(model, base_pose=world_T_base)
        truth = in_limits(model, path, variant)
        goal = contact_pose(path, truth, world_T_base, link, offset)
        if family.joints == 0:
            with pytest.raises(kdl_space.InputError, match="no movable joint"):
                kdl_space.ik(seed, model.contact(link, offset), goal)
            with pytest.raises(kdl_space.InputError, match="no movable joint"):
                kdl_space.ik(scenario, goal)
            continue
        for r in (kdl_space.ik(seed, model.contact(link, offset), goal), kdl_space.ik(scenario, goal)):
            reached = contact_pose(path, r["q_by_name"], world_T_base, link, offset)
            assert np.linalg.norm(reached[:3, 3] - goal[:3, 3]) <= 1e-9, (family.name, link)
            assert rotation_angle(reached[:3, :3], goal[:3, :3]) <= 1e-9, (family.name, link)
            assert sorted(r["q_by_name"]) == sorted(model.joint_names)
            for name, v in r["q_by_name"].items():
                if name in limits:
                    assert limits[name][0] <= v <= limits[name][1], (family.name, name, v)


@pytest.mark.parametrize("family", FAMILIES, ids=IDS)
def test_plan_finds_an_optimum_or_says_why_not(tmp_path, family):
    """plan_capture: an optimum inside the limits no worse than the scenario as written, or the
    library's refusal (kdl_space.Error) with a message; a robot without joints: InputError, "no
    movable joint"."""
    path = write_scenario(tmp_path, family)
    if family.joints == 0:
        with pytest.raises(kdl_space.InputError, match="no movable joint"):
            kdl_space.plan_capture(str(path), scan=5)
        with pytest.raises(kdl_space.InputError, match="no movable joint"):
            kdl_space.plan_capture(kdl_space.load_scenario(str(path)), scan=5)
        return
    try:
        plan = kdl_space.plan_capture(kdl_space.load_scenario(str(path)), scan=5)
    except kdl_space.Error as e:  # the library's refusal (the tool's exit 3), with its reason
        assert str(e), family.name
        return
    assert math.isfinite(plan.objective)
    assert plan.objective <= plan.nominal_objective + 1e-12
    for name, (lower, upper, _) in urdf_limits(urdf_path(family)).items():
        if name in plan.q_by_name:
            assert lower <= plan.q_by_name[name] <= upper, (family.name, name)
    assert sorted(plan.q_by_name) == sorted(plan.joint_names)


@pytest.mark.parametrize("family", FAMILIES, ids=IDS)
def test_an_operation_plan_measures_the_motion(tmp_path, family):
    """plan_capture over the motion after the capture (peak_base_rate, horizon 0.5 s): every family
    with joints gets its optimum and nominal measured; a robot without joints: "no movable joint"."""
    path = write_scenario(tmp_path, family)
    if family.joints == 0:
        with pytest.raises(kdl_space.InputError, match="no movable joint"):
            kdl_space.plan_capture(str(path), objective="peak_base_rate", horizon=0.5, scan=3)
        return
    plan = kdl_space.plan_capture(str(path), objective="peak_base_rate", horizon=0.5, scan=3, polish_starts=1)
    m = plan.optimum["motion"]
    assert plan.objective == m["peak_base_rate"] <= plan.nominal["motion"]["peak_base_rate"] + 1e-12
    assert m["peak_base_rate"] >= m["final_base_rate"]
    assert math.isfinite(plan.momentum_rate)
    assert sorted(m["peak_torque_by_name"]) == sorted(plan.joint_names)


@pytest.mark.parametrize("family", FAMILIES, ids=IDS)
def test_a_study_computes_every_sample(tmp_path, family):
    """kdl_space.study: four samples of the box's mass and spin, every status 0."""
    scenario = write_scenario(tmp_path, family)
    study = tmp_path / "study.yaml"
    study.write_text(f"scenario: {scenario}\nsamples: 4\nseed: 34\ninputs:\n  target.mass: {{uniform: [20, 60]}}\n"
                     "  target.twist.wx: {normal: {mean: 0.03, std: 0.01}}\n")
    r = kdl_space.study(str(study), threads=1)
    assert len(r) == 4
    assert list(r["status"]) == [0, 0, 0, 0], r.summary
    assert r.failed == 0


@pytest.mark.parametrize("family", FAMILIES, ids=IDS)
def test_a_study_of_the_targets_shape_with_a_sampler_computes_every_sample(tmp_path, family):
    """The target's principal moments and tumble cone, and a sampler's correlated factors: every status 0,
    the sampler's values in the rows."""
    scenario = write_scenario(tmp_path, family)
    study = tmp_path / "shape.yaml"
    study.write_text(f"scenario: {scenario}\nsamples: 4\nseed: 35\ninputs:\n  target.inertia.I1: {{uniform: [0.9, 1.1]}}\n"
                     "  target.inertia.I2: {uniform: [0.9, 1.1]}\n  target.inertia.tilt: {deg: {uniform: [0, 10]}}\n"
                     "  target.tumble_cone: {deg: {uniform: [0, 10]}}\n")

    def sampler(rng, i):
        f = rng.uniform(0.95, 1.05)
        return {"target.inertia.I1": f, "target.inertia.I2": f}

    r = kdl_space.study(str(study), sampler=sampler)
    assert list(r["status"]) == [0, 0, 0, 0], r.summary
    assert np.array_equal(r["target.inertia.I1"], r["target.inertia.I2"])


@pytest.mark.parametrize("family", FAMILIES, ids=IDS)
def test_check_finds_no_error(family):
    findings = kdl_space.check_urdf(str(urdf_path(family)))
    assert [f.describe() for f in findings if f.severity == kdl_space.Severity.Error] == []
