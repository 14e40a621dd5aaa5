"""Poses and conditioning (issue 26, item 1): every link's pose (Model.link_pose), the contact
frame's pose (inspect_contact, `kdl_space inspect --json`) against a forward kinematics written
here in NumPy from the URDF's XML; J*'s singular values, condition number and manipulability
against NumPy's SVD and determinant of the J* and J the library returns; the joints' margins
against the URDF's limits; the warnings for a joint outside its limits and a near-singular J*."""
import json
import math
import pathlib
import subprocess

import numpy as np
import pytest

import kdl_space
from conftest import ARM, CAPTURE_SCENARIO, SOURCE_DIR
from urdf_numpy import homogeneous, rpy_matrix, urdf_fk, urdf_limits

DUAL_ARM = SOURCE_DIR / "urdf" / "dual_arm.urdf"          # a tree: two arms on one base
ARM6 = SOURCE_DIR / "tests" / "data" / "reference" / "models" / "arm6_public.urdf"


def quaternion_matrix(x, y, z, w):
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def close(actual, expected, what, tol=1e-12):
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, what
    scale = max(1.0, float(np.max(np.abs(expected))))
    assert np.max(np.abs(actual - expected), initial=0.0) <= tol * scale, f"{what}: {actual} vs {expected}"


def random_configuration(model, path, seed):
    """Joint values inside the URDF's limits (continuous joints in [-pi, pi]) and a base pose."""
    rng = np.random.default_rng(seed)
    limits = urdf_limits(path)
    q = {}
    for name in model.joint_names:
        lo, hi = limits.get(name, (-math.pi, math.pi, 0))[:2]
        q[name] = float(rng.uniform(lo, hi))
    position, rpy = rng.uniform(-2, 2, 3), rng.uniform(-1.2, 1.2, 3)
    return q, position, rpy


MODELS = [ARM, DUAL_ARM, ARM6]


@pytest.mark.parametrize("path", MODELS, ids=lambda p: pathlib.Path(p).stem)
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_every_link_pose_matches_numpy_forward_kinematics(path, seed):
    model = kdl_space.load_urdf(str(path))
    q, position, rpy = random_configuration(model, path, seed)
    state = kdl_space.State(model, q=q, base_pose=(position, rpy))
    expected = urdf_fk(path, q, homogeneous(rpy_matrix(*rpy), position))
    assert set(model.link_names) <= set(expected)
    for link in model.link_names:
        p, R = model.link_pose(state, link)
        close(p, expected[link][:3, 3], f"{path.name} {link} position")
        close(R, expected[link][:3, :3], f"{path.name} {link} rotation")


def test_link_pose_from_q_puts_the_base_at_the_identity(arm):
    q = {"joint2": 0.7, "joint4": -0.4}
    p, R = arm.link_pose(q, "end_effector")
    expected = urdf_fk(ARM, q, np.eye(4))["end_effector"]
    close(p, expected[:3, 3], "position")
    close(R, expected[:3, :3], "rotation")
    with pytest.raises(kdl_space.ModelError, match="no link 'nowhere'"):
        arm.link_pose(q, "nowhere")


@pytest.mark.parametrize("path,link", [(ARM, "end_effector"), (DUAL_ARM, "right_tool"), (ARM6, None)],
                         ids=["arm7", "dual_arm", "arm6"])
def test_contact_frame_pose_matches_numpy(path, link):
    model = kdl_space.load_urdf(str(path))
    link = link or model.link_names[-1]
    q, position, rpy = random_configuration(model, path, 7)
    offset = np.array([0.03, -0.02, 0.05])
    state = kdl_space.State(model, q=q, base_pose=(position, rpy))
    r = kdl_space.inspect_contact(state, model.contact(link, offset))
    T = urdf_fk(path, q, homogeneous(rpy_matrix(*rpy), position))[link]
    close(r["position"], T[:3, :3] @ offset + T[:3, 3], "position")
    close(r["rotation"], T[:3, :3], "rotation")
    x, y, z, w = r["quaternion"]
    assert w >= 0
    close(quaternion_matrix(x, y, z, w), T[:3, :3], "quaternion (x, y, z, w)")
    close(rpy_matrix(*r["rpy"]), T[:3, :3], "rpy")


def inspect_json(cli, *args):
    out = subprocess.run([cli, "inspect", *map(str, args), "--json"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def test_inspect_prints_the_contact_frame_pose(cli):
    model = kdl_space.load_urdf(str(DUAL_ARM))
    q, position, rpy = random_configuration(model, DUAL_ARM, 11)
    j = inspect_json(cli, "--urdf", DUAL_ARM, "--tip", "left_tool", "--offset", 0.1, 0, 0.02, "--tip", "right_link4",
                     "--q", *[f"{k}={v!r}" for k, v in q.items()], "--base-pos", *map(repr, position),
                     "--base-rpy", *map(repr, rpy))
    poses = urdf_fk(DUAL_ARM, q, homogeneous(rpy_matrix(*rpy), position))
    for contact, offset in zip(j["contacts"], ([0.1, 0, 0.02], [0, 0, 0])):
        T = poses[contact["link"]]
        pose = contact["pose"]
        close(pose["position"], T[:3, :3] @ offset + T[:3, 3], "position")
        close(pose["position"], contact["point"], "position = point")
        close(pose["rotation"], T[:3, :3], "rotation")
        close(quaternion_matrix(*pose["quaternion"]), T[:3, :3], "quaternion (x, y, z, w)")
        close(rpy_matrix(*pose["rpy"]), T[:3, :3], "rpy")


def test_singular_values_match_numpy_svd(cli):
    model = kdl_space.load_urdf(str(ARM))
    q = {"joint2": 0.7, "joint3": 0.9, "joint4": 0.8, "joint6": -0.6}
    state = kdl_space.State(model, q=q)
    contact = model.contact("end_effector", [0, 0, 0.05])
    solver = kdl_space.FreeFloatingSolver(model)
    solver.compute(state)
    J_star, J = solver.J_star(contact), solver.J(contact)
    sigma = np.linalg.svd(J_star, compute_uv=False)
    r = kdl_space.inspect_contact(state, contact)
    close(r["J_star_singular_values"], sigma, "singular values")
    close(r["J_star_condition_number"], sigma[0] / sigma[-1], "condition number", 1e-10)
    # 7 joints: J J^T is 6 x 6 and regular, sqrt(det) is Yoshikawa's measure.
    close(r["J_star_manipulability"], math.sqrt(np.linalg.det(J_star @ J_star.T)), "manipulability of J*", 1e-10)
    close(r["J_manipulability"], math.sqrt(np.linalg.det(J @ J.T)), "manipulability of J", 1e-10)
    j = inspect_json(cli, "--urdf", ARM, "--tip", "end_effector", "--offset", 0, 0, 0.05,
                     "--q", *[f"{k}={v!r}" for k, v in q.items()])
    c = j["contacts"][0]["conditioning"]
    close(c["J_star_singular_values"], np.linalg.svd(np.array(j["contacts"][0]["J_star"]), compute_uv=False),
          "inspect: singular values of its own J_star")
    close(c["J_star_condition_number"], sigma[0] / sigma[-1], "inspect: condition number", 1e-10)
    close(c["J_manipulability"], math.sqrt(np.linalg.det(J @ J.T)), "inspect: manipulability of J", 1e-10)


def test_joint_margins_are_the_distances_to_the_urdf_limits(cli):
    model = kdl_space.load_urdf(str(ARM6))
    q, _, _ = random_configuration(model, ARM6, 5)
    limits = urdf_limits(ARM6)
    r = kdl_space.inspect_contact(kdl_space.State(model, q=q), model.contact(model.link_names[-1]))
    j = inspect_json(cli, "--urdf", ARM6, "--tip", model.link_names[-1], "--q", *[f"{k}={v!r}" for k, v in q.items()])
    for name in model.joint_names:
        if name in limits:
            lo, hi, _ = limits[name]
            close(r["joint_margins"][name], min(q[name] - lo, hi - q[name]), name)
            close(j["joint_margins"][name]["margin"], min(q[name] - lo, hi - q[name]), name)
        else:  # continuous
            assert r["joint_margins"][name] is None and j["joint_margins"][name] is None


# --- Warnings ------------------------------------------------------------------------------------

def kinds(warnings):
    return [(w["kind"], w["element"]) for w in warnings]


def test_a_joint_outside_its_limits_is_warned_about(cli, arm, tmp_path):
    q = {"joint2": 0.7, "joint3": 0.9, "joint4": 3.0, "joint6": -0.6}  # joint4's limit: 2.79253
    r = kdl_space.inspect_contact(kdl_space.State(arm, q=q), arm.contact("end_effector"))
    assert ("joint_outside_limits", "joint4") in kinds(r["warnings"])
    close(r["joint_margins"]["joint4"], 2.79253 - 3.0, "margin, negative outside")
    j = inspect_json(cli, "--urdf", ARM, "--tip", "end_effector", "--q", *[f"{k}={v}" for k, v in q.items()])
    assert ("joint_outside_limits", "joint4") in kinds(j["warnings"])
    text = subprocess.run([cli, "inspect", "--urdf", str(ARM), "--tip", "end_effector",
                           "--q", *[f"{k}={v}" for k, v in q.items()]], check=True, capture_output=True, text=True).stdout
    assert "warning: joint4: at 3, outside its limits" in text
    # The capture and the simulation of a scenario whose arm is outside its limits at the capture.
    scenario = tmp_path / "outside.yaml"
    scenario.write_text(CAPTURE_SCENARIO.read_text().replace("../urdf/", str(SOURCE_DIR / "urdf") + "/")
                        .replace("joint4: 0.8, joint6", "joint4: 3.0, joint6"))
    out = subprocess.run([cli, "capture", str(scenario), "--json"], check=True, capture_output=True, text=True)
    assert ("joint_outside_limits", "joint4") in kinds(json.loads(out.stdout)["warnings"])
    out = subprocess.run([cli, "capture", str(scenario)], check=True, capture_output=True, text=True)
    assert "Warning: joint4: at 3, outside its limits" in out.stdout
    assert ("joint_outside_limits", "joint4") in kinds(kdl_space.solve_capture(kdl_space.load_scenario(str(scenario))).warnings)
    run = kdl_space.run_operation(kdl_space.load_scenario(str(scenario)), duration=0.05)
    assert ("joint_outside_limits", "joint4") in kinds(run["warnings"])


def test_inside_the_limits_away_from_singularities_nothing_is_warned(cli, arm):
    q = {"joint2": 0.7, "joint3": 0.9, "joint4": 0.8, "joint6": -0.6}
    r = kdl_space.inspect_contact(kdl_space.State(arm, q=q), arm.contact("end_effector"))
    assert r["warnings"] == []
    assert kdl_space.solve_capture(kdl_space.load_scenario(str(CAPTURE_SCENARIO))).warnings == []
    out = subprocess.run([cli, "capture", str(CAPTURE_SCENARIO), "--json"], check=True, capture_output=True, text=True)
    assert json.loads(out.stdout)["warnings"] == []


def test_a_near_singular_configuration_is_warned_about(cli):
    # The dual arm's wrist (roll-pitch-roll) with its pitch left_joint5 at 0: the two roll axes
    # nearly line up (only the links' small offsets keep them apart), sigma_min / sigma_max of J*
    # below 1e-3 by NumPy's own SVD; at left_joint5 = 0.8 it is well above.
    model = kdl_space.load_urdf(str(DUAL_ARM))
    contact = model.contact("left_tool")
    solver = kdl_space.FreeFloatingSolver(model)
    for wrist, singular in ((0.0, True), (0.8, False)):
        q = {"left_joint2": 0.5, "left_joint3": -1.0, "left_joint5": wrist}
        state = kdl_space.State(model, q=q)
        solver.compute(state)
        sigma = np.linalg.svd(solver.J_star(contact), compute_uv=False)
        assert (sigma[-1] / sigma[0] < kdl_space.NEAR_SINGULAR_RATIO == 1e-3) == singular
        r = kdl_space.inspect_contact(state, contact)
        assert (("near_singular", "contact 'left_tool'") in kinds(r["warnings"])) == singular
        j = inspect_json(cli, "--urdf", DUAL_ARM, "--tip", "left_tool", "--q", *[f"{k}={v}" for k, v in q.items()])
        assert (("near_singular", "contact 'left_tool'") in kinds(j["warnings"])) == singular
