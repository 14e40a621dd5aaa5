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
