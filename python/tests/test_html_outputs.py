"""The 3-D page from every entry point: `kdl_space capture --html`, `kdl_space study --html` (its
nominal sample), CaptureResult.to_html and OperationResult.to_html (run_operation's), opened in
headless Chromium through the page's hook (test_html.py's helpers). What they must show of the
target and the grasp: the grasp frame riding on the target (checked against the scenario's numbers
and the hand's contact point), a free-floating target's links (against its scenario's base pose
and the arm's contact point), and how close a failed approach came (against the CSV of the run).
The size of a 20 s run of a 44-joint humanoid's page is bounded here; how fast it opens is
measured, not asserted (tools/bench.sh)."""
import base64
import json
import math
import pickle
import re
import subprocess

import numpy as np
import pytest

from conftest import ARM, SOURCE_DIR
from test_html import csv_rows, needs_browser, page_data, selftest
from urdf_numpy import urdf_fk

SCENARIOS = SOURCE_DIR / "scenarios"

# A robot that holds the rigid target's grasp frame (robot.place: grasp): the numbers the test
# composes the grasp frame's world pose from.
TARGET_POSITION, TARGET_RPY = [0.3, -2.9, 1.7], [0.3, -0.2, 0.5]
GRASP_POSITION, GRASP_RPY = [0.1, 0.0, -0.2], [3.0, 0.1, 0.2]
GRASP_SCENARIO = f"""
robot:
  urdf: {ARM}
  contact: {{link: end_effector, offset: [0, 0, 0.05]}}
  base: {{position: [0.1, -0.2, 0.3], rpy: [0.1, 0.2, -0.3]}}
  q: {{joint2: 0.7, joint3: 0.9, joint4: 0.8, joint6: -0.6}}
  grasp: {{target_frame: {{position: {GRASP_POSITION}, rpy: {GRASP_RPY}}}}}
  place: grasp
target:
  mass: 50
  inertia: [[2.1, 0, 0], [0, 2.6, 0], [0, 0, 3.0]]
  pose: {{position: {TARGET_POSITION}, rpy: {TARGET_RPY}}}
law: {{type: capture}}
"""


def rpy_matrix(r, p, y):
    """URDF's rpy: R = Rz(y) Ry(p) Rx(r)."""
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def quat_matrix(x, y, z, w):
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def run_cli(cli, *args):
    return subprocess.run([cli, *map(str, args)], capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def grasp_capture(tmp_path_factory, cli):
    d = tmp_path_factory.mktemp("grasp")
    scenario = d / "grasp.yaml"
    scenario.write_text(GRASP_SCENARIO)
    page = d / "grasp.html"
    done = run_cli(cli, "capture", scenario, "--html", page, "--json")
    assert done.returncode == 0, done.stderr
    return {"dir": d, "scenario": scenario, "page": page, "json": json.loads(done.stdout)}


def test_capture_page_holds_the_grasp_frame(grasp_capture):
    data = page_data(grasp_capture["page"])
    assert grasp_capture["json"]["html"] == str(grasp_capture["page"])
    pose = data["grasp"]["pose"]
    assert np.allclose(pose[:3], GRASP_POSITION, atol=1e-15)
    R = quat_matrix(*pose[3:])
    assert np.allclose(R, rpy_matrix(*GRASP_RPY), atol=1e-12)


@needs_browser
@pytest.mark.parametrize("frame", [0, 1])
def test_grasp_frame_rides_on_the_target_where_the_hand_holds_it(grasp_capture, frame):
    got = selftest(grasp_capture["page"], frame)
    assert got["errors"] == [], got["errors"]
    assert got["frameCount"] == 2 and got["impactFrame"] == 0
    # The grasp frame's world pose: the target's pose (the scenario's) times the grasp frame.
    expected_R = rpy_matrix(*TARGET_RPY) @ rpy_matrix(*GRASP_RPY)
    expected_p = np.array(TARGET_POSITION) + rpy_matrix(*TARGET_RPY) @ np.array(GRASP_POSITION)
    g = got["graspFrame"]
    assert g is not None
    assert np.allclose(g[:3], expected_p, atol=2e-6), (g[:3], expected_p)  # float32 of metres
    assert np.allclose(quat_matrix(*g[3:]), expected_R, atol=2e-6)
    # The hand holds it: the contact point is the grasp frame's origin, to the solve's residual.
    residual = grasp_capture["json"]["grasp"]["residual_position"]
    assert np.linalg.norm(np.array(g[:3]) - got["contactPoint"]) < residual + 2e-6


@pytest.fixture(scope="module")
def robot_capture(tmp_path_factory, cli):
    page = tmp_path_factory.mktemp("robots") / "robots.html"
    done = run_cli(cli, "capture", SCENARIOS / "robot_to_robot_capture.yaml", "--html", page)
    assert done.returncode == 0, done.stderr
    return page


@needs_browser
def test_a_free_floating_target_is_drawn_link_by_link(robot_capture):
    data = page_data(robot_capture)
    names = [link["name"] for link in data["targetLinks"]]
    got = selftest(robot_capture, 0)
    assert got["errors"] == [], got["errors"]
    assert got["objectCount"] == len(data["links"]) + len(names) + 4  # base axes, contact, path, impulse
    poses = got["targetLinkPoses"]
    assert len(poses) == len(names) and all(p is not None for p in poses)
    # Its base where the scenario puts it (no rpy: unturned) ...
    base = poses[0]
    assert np.allclose(base[:3], [-4.6810623747200945, -2.5837731448252454, 1.6935908031971343], atol=2e-6)
    assert np.allclose(np.abs(base[6]), 1.0, atol=1e-7)
    # ... and its hand (the target's contact link, no offset) at the arm's contact point.
    hand = poses[names.index("hand")]
    assert np.allclose(hand[:3], got["contactPoint"], atol=1e-5), (hand[:3], got["contactPoint"])


@needs_browser
def test_failed_approach_page_shows_how_close_it_came(tmp_path, cli):
    """The approach cut short (1 s): the page opens, its note and its closest distance are those of
    the refusal, and at every frame the grasp frame's distance from the hand is the CSV's."""
    scenario = tmp_path / "short.yaml"
    scenario.write_text((SCENARIOS / "approach_tumbling_box.yaml").read_text()
                        .replace("../urdf/space_arm7.urdf", str(ARM)).replace("max_duration: 30", "max_duration: 1"))
    page, csv = tmp_path / "failed.html", tmp_path / "failed.csv"
    done = run_cli(cli, "simulate", scenario, "--html", page, "--csv", csv)
    assert done.returncode == 3 and page.exists(), done.stderr
    m = re.search(r"closest ([0-9.e+-]+) m at t = ([0-9.e+-]+) s", done.stderr)
    assert m, done.stderr
    closest, when = float(m.group(1)), float(m.group(2))
    data = page_data(page)
    last = selftest(page, data["frameCount"] - 1)
    assert last["errors"] == [], last["errors"]
    assert last["note"].startswith("The approach failed") and "Closest to the grasp point" in last["note"]
    assert last["impactFrame"] == -1, "no contact, no impact to step to"
    assert abs(last["closest"]["distance"] - closest) <= 1e-5 * closest  # the message's 6 digits
    assert abs(last["closest"]["time"] - when) <= 1e-5 * max(when, 1e-3)
    head, rows = csv_rows(csv)
    for k in sorted({0, last["closest"]["frame"], data["frameCount"] // 2, data["frameCount"] - 1}):
        got = selftest(page, k)
        row = min(rows, key=lambda r: abs(float(r[0]) - got["time"]))
        assert abs(float(row[0]) - got["time"]) < 1e-9
        distance = np.linalg.norm(np.array(got["graspFrame"][:3]) - got["contactPoint"])
        assert abs(distance - float(row[head.index("grasp_distance")])) < 1e-5, (k, distance, row)


@needs_browser
def test_study_page_of_its_nominal_sample_opens(tmp_path, cli):
    study = tmp_path / "study.yaml"
    study.write_text(f"scenario: {SCENARIOS / 'tumbling_box_capture.yaml'}\nsamples: 3\nseed: 1\n"
                     "inputs: {robot.q.joint7: {uniform: [-0.2, 0.2]}}\nmotion: {duration: 1.0, output_step: 0.05}\n")
    page = tmp_path / "nominal.html"
    done = run_cli(cli, "study", study, "-o", tmp_path / "t.csv", "--html", page, "--threads", "1", "--json")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["html"] == str(page)
    got = selftest(page, "last")
    assert got["errors"] == [] and got["frameCount"] == 21 and abs(got["time"] - 1.0) < 1e-9


# --- Python: to_html on the capture's and the operation's results -----------------------------

def frames_of(data):
    return np.frombuffer(base64.b64decode(data["frames"]), dtype=np.float32)


def test_capture_result_to_html_is_the_tools_page(tmp_path, cli):
    import kdl_space
    sc = kdl_space.load_scenario(str(SCENARIOS / "tumbling_box_capture.yaml"))
    page = tmp_path / "py.html"
    kdl_space.solve_capture(sc).to_html(str(page))
    tool = tmp_path / "tool.html"
    assert run_cli(cli, "capture", SCENARIOS / "tumbling_box_capture.yaml", "--html", tool).returncode == 0
    a, b = page_data(page), page_data(tool)
    assert a["title"] != b["title"]
    assert {k: v for k, v in a.items() if k != "title"} == {k: v for k, v in b.items() if k != "title"}


def test_operation_result_to_html_is_the_tools_page(tmp_path, cli):
    import kdl_space
    scenario = SCENARIOS / "approach_tumbling_box.yaml"
    r = kdl_space.run_operation(kdl_space.load_scenario(str(scenario)), duration=1.0)
    assert isinstance(r, dict) and isinstance(r, kdl_space.OperationResult)
    page = tmp_path / "py.html"
    r.to_html(str(page))
    tool = tmp_path / "tool.html"
    done = run_cli(cli, "simulate", scenario, "--duration", "1", "--html", tool)
    assert done.returncode == 0, done.stderr
    a, b = page_data(page), page_data(tool)
    assert a["frameCount"] == b["frameCount"] > 2 and a["phases"] == b["phases"]
    assert np.array_equal(frames_of(a), frames_of(b), equal_nan=True), "the same samples give the same frames"
    assert a["grasp"] == b["grasp"] and a["impulse"] == b["impulse"] and a["tCapture"] == b["tCapture"]
    # A copy or a pickle is the plain dict (to_html stays with the run's own result).
    assert type(pickle.loads(pickle.dumps(r))) is dict


def test_to_html_refusals_name_the_path(tmp_path):
    import kdl_space
    scenario = SCENARIOS / "tumbling_box_capture.yaml"
    sc = kdl_space.load_scenario(str(scenario))
    capture = kdl_space.solve_capture(sc)
    before = scenario.read_text()
    with pytest.raises(ValueError, match=re.escape(str(scenario))):
        capture.to_html(str(scenario))
    assert scenario.read_text() == before
    missing = tmp_path / "no" / "such" / "page.html"
    with pytest.raises(OSError, match=re.escape(str(missing))):
        capture.to_html(str(missing))
    r = kdl_space.run_operation(sc, duration=0.2)
    with pytest.raises(OSError, match=re.escape(str(missing))):
        r.to_html(str(missing))
    with pytest.raises(ValueError, match="robot's URDF"):
        r.to_html(sc.robot_urdf)
    assert list(tmp_path.iterdir()) == []


# --- Size: a 20 s run of a 44-joint humanoid ----------------------------------------------------

HUMANOID = SOURCE_DIR / "tests" / "data" / "real_patterns" / "humanoid44.urdf"


def humanoid_scenario(folder):
    """A plain motion of the humanoid: 20 s of tumbling (its joints swung by the base's rotation), a
    row every 0.01 s (2001 samples: the page keeps 30 a second). Its fingers' joints are stiff for an
    explicit integrator: rosenbrock, as the tool advises."""
    path = folder / "humanoid.yaml"
    path.write_text(f"robot:\n  urdf: {HUMANOID}\n  base: {{twist: [0.02, 0.01, 0, 0.05, -0.03, 0.04]}}\n"
                    "simulation:\n  duration: 20\n  output_step: 0.01\n  integrator: rosenbrock\n"
                    "  rtol: 1.0e-6\n  atol: 1.0e-8\n")
    return path


def test_a_humanoids_20_s_page_is_under_5_mb(tmp_path, cli):
    page = tmp_path / "humanoid.html"
    done = run_cli(cli, "simulate", humanoid_scenario(tmp_path), "--html", page, "--json")
    assert done.returncode == 0, done.stderr
    data = page_data(page)
    assert len(data["links"]) >= 45  # 44 joints' links and more: every body the model has
    times = np.frombuffer(base64.b64decode(data["times"]), dtype=np.float64)
    assert abs(times[-1] - 20.0) < 1e-9 and data["frameCount"] <= 20 * 30 + 2
    assert page.stat().st_size < 5e6, page.stat().st_size


# --- The target's URDF visuals: a rigid target read from a URDF, a free-floating target's meshes --
# A hub, a boom on a revolute joint (held at BOOM_Q: the rigid body's shape) and a gripper fixed at
# its end, each with a box visual (the gripper also with an STL mesh found through --mesh-path);
# target.link: hub makes the whole tree one rigid body whose frame is the hub's.
BOOM_Q = 0.6
TARGET_URDF = """<?xml version="1.0"?>
<robot name="boom">
  <link name="hub">
    <inertial><mass value="100"/><inertia ixx="10" ixy="0" ixz="0" iyy="12" iyz="0" izz="14"/></inertial>
    <visual><origin xyz="0.1 -0.2 0.05" rpy="0.3 0 0.2"/><geometry><box size="0.8 0.6 0.5"/></geometry></visual>
  </link>
  <link name="boom">
    <inertial><origin xyz="0.5 0 0"/><mass value="2"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.2"/></inertial>
    <visual><origin xyz="0.5 0 0" rpy="0.1 0.2 0.3"/><geometry><box size="1.0 0.1 0.08"/></geometry></visual>
  </link>
  <link name="gripper">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <visual><origin xyz="0.05 0 0" rpy="0 0.4 0"/><geometry><box size="0.1 0.2 0.3"/></geometry></visual>
    <visual><geometry><mesh filename="package://tgt/meshes/claw.stl"/></geometry></visual>
  </link>
  <joint name="boom_joint" type="revolute">
    <parent link="hub"/><child link="boom"/><origin xyz="0 0 0.5" rpy="0.2 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="1"/>
  </joint>
  <joint name="gripper_mount" type="fixed">
    <parent link="boom"/><child link="gripper"/><origin xyz="1 0 0" rpy="0 0 0.5"/>
  </joint>
</robot>
"""
# The box visuals (link, origin xyz, rpy, size), as written above.
BOXES = [("hub", [0.1, -0.2, 0.05], [0.3, 0, 0.2], [0.8, 0.6, 0.5]),
         ("boom", [0.5, 0, 0], [0.1, 0.2, 0.3], [1.0, 0.1, 0.08]),
         ("gripper", [0.05, 0, 0], [0, 0.4, 0], [0.1, 0.2, 0.3])]
CLAW_TRIANGLES = 4
HUB_POSITION, HUB_RPY = [0.4, -2.8, 1.6], [0.2, -0.1, 0.4]


def write_stl(path, triangles):
    """A binary STL of `triangles` small triangles (normals zero, as many exporters write)."""
    import struct
    body = b"".join(struct.pack("<12fH", 0, 0, 0, *[0.01 * (i + 1), 0, 0], *[0, 0.02, 0], *[0, 0, 0.03 * (i + 1)], 0)
                    for i in range(triangles))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(b"\0" * 80 + struct.pack("<I", triangles) + body)


@pytest.fixture(scope="module")
def rigid_urdf_target(tmp_path_factory, cli):
    """A 1 s run after the capture of the rigid target above (held by the hand), its page with --mesh-path."""
    d = tmp_path_factory.mktemp("rigid_urdf")
    (d / "boom.urdf").write_text(TARGET_URDF)
    write_stl(d / "meshes" / "tgt" / "meshes" / "claw.stl", CLAW_TRIANGLES)
    scenario = d / "scenario.yaml"
    scenario.write_text(f"""
robot:
  urdf: {ARM}
  contact: {{link: end_effector, offset: [0, 0, 0.05]}}
  q: {{joint2: 0.7, joint3: 0.9, joint4: 0.8, joint6: -0.6}}
target:
  urdf: {d / "boom.urdf"}
  link: hub
  q: {{boom_joint: {BOOM_Q}}}
  base: {{position: {HUB_POSITION}, rpy: {HUB_RPY}, twist: [0.01, 0.02, 0, 0.05, -0.04, 0.06]}}
law: {{type: capture}}
""")
    page = d / "run.html"
    done = run_cli(cli, "simulate", scenario, "--duration", "1", "--html", page, "--mesh-path", d / "meshes")
    assert done.returncode == 0, done.stderr
    return {"dir": d, "page": page, "stderr": done.stderr}


def pose_matrix(pose):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = quat_matrix(*pose[3:]), pose[:3]
    return T


def rpy_pose(xyz, rpy):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = rpy_matrix(*rpy), xyz
    return T


@needs_browser
@pytest.mark.parametrize("which", ["first", "last"])
def test_a_rigid_target_from_a_urdf_is_drawn_with_its_visuals(rigid_urdf_target, which):
    data = page_data(rigid_urdf_target["page"])
    k = 0 if which == "first" else data["frameCount"] - 1
    got = selftest(rigid_urdf_target["page"], k)
    assert got["errors"] == [], got["errors"]
    assert got["targetVisualCount"] == 4  # three boxes and the claw
    # The target's frame is the hub's: at the start where target.base puts it.
    target = got["targetPose"]
    if k == 0:
        assert np.allclose(pose_matrix(target), rpy_pose(HUB_POSITION, HUB_RPY), atol=2e-6)
    # Each box: target pose(k) x (hub <- link at boom_joint = BOOM_Q) x the visual's origin.
    links = urdf_fk(rigid_urdf_target["dir"] / "boom.urdf", {"boom_joint": BOOM_Q}, np.eye(4))
    box_at = [i for i, v in enumerate(data["target"]["visuals"]) if v["shape"] == "box"]
    assert len(box_at) == len(BOXES)
    for i, (link, xyz, rpy, size) in zip(box_at, BOXES):
        expected = pose_matrix(target) @ links[link] @ rpy_pose(xyz, rpy)
        pose = got["targetVisualPoses"][i]
        assert np.allclose(pose_matrix(pose), expected, atol=1e-6), (link, pose, expected)
        # ... and the box as drawn there: its corners' world bounds.
        corners = np.array([[sx * size[0] / 2, sy * size[1] / 2, sz * size[2] / 2, 1]
                            for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) @ expected.T
        drawn = got["targetVisualBoxes"][i]
        assert np.allclose(drawn, [*corners[:, :3].min(0), *corners[:, :3].max(0)], atol=2e-6), link
    # The claw: the STL's triangles, three vertices each.
    assert [m["vertices"] for m in got["targetMeshes"]] == [3 * CLAW_TRIANGLES]
    assert "claw.stl" not in rigid_urdf_target["stderr"]  # found, read, drawn: no warning


def test_a_rigid_target_without_visuals_keeps_its_box_of_inertia(tmp_path, cli):
    urdf = tmp_path / "boom.urdf"
    urdf.write_text(re.sub(r"<visual>.*?</visual>", "", TARGET_URDF))
    scenario = tmp_path / "s.yaml"
    scenario.write_text(f"""
robot: {{urdf: {ARM}, contact: {{link: end_effector}}}}
target: {{urdf: {urdf}, link: hub, q: {{boom_joint: {BOOM_Q}}}}}
law: {{type: capture}}
""")
    page = tmp_path / "p.html"
    done = run_cli(cli, "capture", scenario, "--html", page)
    assert done.returncode == 0, done.stderr
    target = page_data(page)["target"]
    assert target["visuals"] == [] and len(target["size"]) == 3


@needs_browser
def test_a_free_floating_targets_mesh_is_drawn(tmp_path, cli):
    tree = (SOURCE_DIR / "urdf" / "spacedyn_twolink.urdf").read_text()
    claw = '<visual><geometry><mesh filename="package://tgt/meshes/claw.stl"/></geometry></visual>'
    urdf = tmp_path / "twolink.urdf"
    urdf.write_text(tree.replace('<link name="hand"/>', f'<link name="hand">{claw}</link>'))
    assert claw in urdf.read_text()
    write_stl(tmp_path / "meshes" / "tgt" / "meshes" / "claw.stl", CLAW_TRIANGLES)
    scenario = tmp_path / "s.yaml"
    scenario.write_text((SCENARIOS / "robot_to_robot_capture.yaml").read_text()
                        .replace("../urdf/space_arm7.urdf", str(ARM)).replace("../urdf/spacedyn_twolink.urdf", str(urdf)))
    page = tmp_path / "p.html"
    done = run_cli(cli, "simulate", scenario, "--duration", "0.2", "--html", page, "--mesh-path", tmp_path / "meshes")
    assert done.returncode == 0, done.stderr
    got = selftest(page, 0)
    assert got["errors"] == [], got["errors"]
    assert got["targetMeshes"] == [{"link": "hand", "file": "package://tgt/meshes/claw.stl", "vertices": 3 * CLAW_TRIANGLES}]


def urdf_masses(path):
    """{link: (mass, CoM in the link's frame)} of the URDF's links with an <inertial>."""
    import xml.etree.ElementTree as ET
    out = {}
    for link in ET.parse(path).getroot().findall("link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        origin = inertial.find("origin")
        com = [float(v) for v in origin.get("xyz").split()] if origin is not None and origin.get("xyz") else [0, 0, 0]
        out[link.get("name")] = (float(inertial.find("mass").get("value")), np.array(com))
    return out


@needs_browser
def test_a_free_floating_target_drifts_as_a_rigid_body_after_a_point_impact(tmp_path, cli):
    urdf = SOURCE_DIR / "urdf" / "spacedyn_twolink.urdf"
    scenario = tmp_path / "s.yaml"
    scenario.write_text((SCENARIOS / "robot_to_robot_capture.yaml").read_text()
                        .replace("../urdf/space_arm7.urdf", str(ARM)).replace("../urdf/spacedyn_twolink.urdf", str(urdf))
                        .replace("type: capture", "type: point\n  normal: [1, 0, 0]\n  restitution: 0.5"))
    page = tmp_path / "p.html"
    done = run_cli(cli, "simulate", scenario, "--duration", "2", "--html", page)
    assert done.returncode == 0, done.stderr
    data = page_data(page)
    assert data["targetDrift"] is True
    names = [link["name"] for link in data["targetLinks"]]
    masses = urdf_masses(urdf)
    n = data["frameCount"]
    frames = [n // 3, 2 * n // 3, n - 1]
    got = [selftest(page, k) for k in frames]
    assert got[0]["errors"] == [], got[0]["errors"]
    assert "rigid body, its joints frozen" in page.read_text()
    coms, times = [], []
    for g in got:
        poses = g["targetLinkPoses"]
        assert all(p is not None for p in poses), "the separated target is drawn after the impact"
        # Its joints frozen: each link where it was relative to the base.
        relative = [np.linalg.inv(pose_matrix(poses[0])) @ pose_matrix(p) for p in poses]
        if g is got[0]:
            first = relative
        for a, b in zip(first, relative):
            assert np.allclose(a, b, atol=1e-5)
        # Its CoM, from the links' poses and the URDF's masses.
        weighted = [m * (pose_matrix(poses[names.index(link)]) @ np.append(c, 1))[:3] for link, (m, c) in masses.items()
                    if link in names]
        coms.append(sum(weighted) / sum(m for link, (m, c) in masses.items() if link in names))
        times.append(g["time"])
    # Torque-free: the CoM moves on a straight line at a constant speed.
    v1 = (coms[1] - coms[0]) / (times[1] - times[0])
    v2 = (coms[2] - coms[1]) / (times[2] - times[1])
    assert np.linalg.norm(v1) > 1e-4
    # float32 positions of a few metres (some 3e-7 m each), over the frames' time apart
    assert np.allclose(v1, v2, atol=2e-6 / min(times[1] - times[0], times[2] - times[1])), (v1, v2)


@needs_browser
def test_a_target_that_bounced_off_a_compliant_hand_drifts_from_the_contacts_end(tmp_path, cli):
    """A compliant contact that opened (issue 28): the page draws the free-floating target drifting
    from where the contact left it, its CoM at the speed of its own momentum after the contact
    (the JSON's compliant.target.momentum_after over its mass), not moving with the hand as the
    impulsive capture beside it would have it."""
    import kdl_space
    urdf = SOURCE_DIR / "urdf" / "spacedyn_twolink.urdf"
    touch = kdl_space.load_scenario(str(SCENARIOS / "robot_to_robot_capture.yaml"))
    limit = kdl_space.solve_capture(touch)
    closing = limit.floating_target.contact_twist_before[:3] - limit.robot.contact_twist_before[:3]
    normal = -closing / np.linalg.norm(closing)  # from the robot toward the target: the target closes in
    scenario = tmp_path / "s.yaml"
    scenario.write_text((SCENARIOS / "robot_to_robot_capture.yaml").read_text()
                        .replace("../urdf/space_arm7.urdf", str(ARM)).replace("../urdf/spacedyn_twolink.urdf", str(urdf))
                        .replace("type: capture", "type: compliant\n  damping_time: 1.0e-6\n  normal: [%r, %r, %r]" % tuple(normal)))
    page = tmp_path / "p.html"
    done = run_cli(cli, "simulate", scenario, "--duration", "2", "--html", page, "--json")
    assert done.returncode == 0, done.stderr
    contact = json.loads(done.stdout)["compliant"]
    assert contact["end"] == "opened" and contact["catch_rule"] is None
    data = page_data(page)
    names = [link["name"] for link in data["targetLinks"]]
    masses = urdf_masses(urdf)
    mass = sum(m for link, (m, c) in masses.items() if link in names)
    n = data["frameCount"]
    got = [selftest(page, k) for k in (n // 2, n - 1)]
    assert got[0]["errors"] == [], got[0]["errors"]
    coms = []
    for g in got:
        poses = g["targetLinkPoses"]
        assert all(p is not None for p in poses)
        coms.append(sum(m * (pose_matrix(poses[names.index(link)]) @ np.append(c, 1))[:3]
                        for link, (m, c) in masses.items() if link in names) / mass)
    v = (coms[1] - coms[0]) / (got[1]["time"] - got[0]["time"])
    expected = np.array(contact["target"]["momentum_after"][:3]) / mass
    # It bounced: the contact's impulse is not the rigid capture's (which would keep it in the hand).
    f, f_limit = np.array(contact["impulse"][:3]), np.array(limit.impulse.F[:3])
    assert np.linalg.norm(f - f_limit) > 0.1 * np.linalg.norm(f_limit), (f, f_limit)
    # float32 positions of a few metres (some 3e-7 m each), over the frames' time apart
    assert np.allclose(v, expected, atol=2e-6 / (got[1]["time"] - got[0]["time"])), (v, expected)
