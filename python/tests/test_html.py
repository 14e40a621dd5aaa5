"""kdl_space simulate --html: the page opened in a real browser (Debian's chromium, headless).
The page's hook (window.kdlSpace) is read through `#selftest=K`, which writes its state at frame K
into <pre id="selftest"> for `--dump-dom`; the contact point is checked against the CSV of the
same run through an independent forward kinematics (urdf_numpy), the URDF's visuals against what
the test wrote into the URDF."""
import base64
import json
import math
import re
import shutil
import functools
import subprocess
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from conftest import ARM, SOURCE_DIR
from urdf_numpy import urdf_fk

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
needs_browser = pytest.mark.skipif(CHROMIUM is None, reason="no chromium binary (Debian package chromium; tools/deps.sh installs it)")
SCENARIO = SOURCE_DIR / "scenarios" / "approach_tumbling_box.yaml"
# Markers besides the links and the target: the base frame's axes, the contact point, the hand's
# path, the impulse's arrow, the grasp frame's axes (approach.grasp, riding on the target).
MARKERS = 5

# What the test puts into the arm's URDF: one visual of each kind (the mesh's file does not exist:
# its link's box of inertia; test_html_meshes.py draws meshes).
VISUALS = {
    "satellite": '<visual><origin xyz="0 0 0.1"/><geometry><box size="0.8 0.6 0.4"/></geometry>'
                 '<material name="gold"><color rgba="0.9 0.7 0.1 1"/></material></visual>',
    "link2": '<visual><origin xyz="0 0 0.2" rpy="0 1.5707963 0"/><geometry><cylinder radius="0.05" length="0.4"/></geometry>'
             '<material name="gold"/></visual>',
    "link4": '<visual><geometry><sphere radius="0.07"/></geometry></visual>',
    "link6": '<visual><geometry><mesh filename="package://arm/meshes/wrist.stl" scale="0.001 0.001 0.001"/></geometry></visual>',
}


@pytest.fixture(scope="module")
def run(tmp_path_factory, cli):
    """One approach and 2 s after the capture with the visuals above: the page, the CSV, stderr."""
    d = tmp_path_factory.mktemp("html")
    tree = ET.parse(ARM)
    for link in tree.getroot().findall("link"):
        if link.get("name") in VISUALS:
            link.append(ET.fromstring(VISUALS[link.get("name")]))
    urdf = d / "arm.urdf"
    tree.write(urdf)
    scenario = d / "scenario.yaml"
    scenario.write_text(SCENARIO.read_text().replace("../urdf/space_arm7.urdf", str(urdf)))
    page, csv = d / "run.html", d / "run.csv"
    done = subprocess.run([cli, "simulate", str(scenario), "--duration", "2", "--html", str(page), "--csv", str(csv)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return {"dir": d, "urdf": urdf, "page": page, "csv": csv, "stderr": done.stderr, "scenario": scenario}


def page_data(page):
    text = page.read_text()
    m = re.search(r"window\.KDL_DATA = (.*);\n</script>", text)
    assert m, "the page holds no window.KDL_DATA"
    assert "<" not in m.group(1), "every < in the data is written \\u003c"
    return json.loads(m.group(1))


def browser(page, fragment, *extra):
    return subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
                           "--virtual-time-budget=5000", *extra, f"file://{page}#{fragment}"],
                          capture_output=True, text=True, timeout=120)


@functools.lru_cache(maxsize=None)
def selftest(page, k):
    """The page's self-test at frame k (one Chromium run; the same page and frame asked again, the
    same answer: a page is a file the module's run wrote once)."""
    done = browser(page, f"selftest={k}", "--dump-dom")
    m = re.search(r'<pre id="selftest">(.*?)</pre>', done.stdout, re.S)
    assert m and m.group(1), f"no selftest output; chromium said: {done.stderr[-2000:]}"
    return json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&"))


def csv_rows(path):
    lines = path.read_text().splitlines()
    head = lines[0].split(",")
    return head, [line.split(",") for line in lines[1:]]


def contact_from_csv(urdf, head, row):
    """The hand's contact point (end_effector, offset [0, 0, 0.05]) from the row's base pose and q."""
    value = {name: row[i] for i, name in enumerate(head)}
    x, y, z, w = (float(value[f"base_q{c}"]) for c in "xyzw")
    R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = [float(value[f"base_{c}"]) for c in "xyz"]
    q = {name[2:]: float(v) for name, v in value.items() if name.startswith("q_")}
    pose = urdf_fk(str(urdf), q, T)["end_effector"]
    return pose[:3, :3] @ np.array([0, 0, 0.05]) + pose[:3, 3]


def test_page_is_self_contained(run):
    text = run["page"].read_text()
    assert "http://" not in re.sub(r"(xmlns|www\.w3\.org|//[^\n]*)", "", text.split("window.KDL_DATA")[1])
    assert "<script src" not in text and "three" in text.lower()


def test_visuals_reach_the_page(run):
    data = page_data(run["page"])
    links = {link["name"]: link["visuals"] for link in data["links"]}
    assert links["satellite"][0]["shape"] == "box" and links["satellite"][0]["size"] == [0.8, 0.6, 0.4]
    # urdfdom keeps colours as float: 2^-24 of 1
    assert links["satellite"][0]["origin"][:3] == [0, 0, 0.1] and np.allclose(links["satellite"][0]["rgba"], [0.9, 0.7, 0.1, 1], atol=1e-7)
    cyl = links["link2"][0]
    assert cyl["shape"] == "cylinder" and cyl["size"][:2] == [0.05, 0.4]
    assert np.allclose(cyl.get("rgba", [0, 0, 0, 0]), [0.9, 0.7, 0.1, 1], atol=1e-7), "a material named on the visual takes the robot's colour of that name"
    # rpy (0, pi/2, 0) as a quaternion: (0, sin(pi/4), 0, cos(pi/4))
    assert np.allclose(cyl["origin"][3:], [0, math.sin(math.pi / 4), 0, math.cos(math.pi / 4)], atol=1e-7)
    assert links["link4"][0]["shape"] == "sphere" and links["link4"][0]["size"][0] == 0.07
    assert links["link6"][0].get("inertia_box") and links["link6"][0]["shape"] == "box"
    assert "package://arm/meshes/wrist.stl" in run["stderr"] and "link6" in run["stderr"]
    assert links["link1"][0].get("inertia_box"), "a link without a visual: its box of inertia"


@needs_browser
@pytest.mark.parametrize("which", ["first", "impact", "middle", "last"])
def test_contact_point_matches_the_csv(run, which):
    data = page_data(run["page"])
    n = data["frameCount"]
    first = selftest(run["page"], 0)
    k = {"first": 0, "impact": first["impactFrame"], "middle": n // 2, "last": n - 1}[which]
    got = selftest(run["page"], k)
    assert got["errors"] == [], got["errors"]
    assert got["frameCount"] == n and got["frame"] == k
    assert got["objectCount"] == len(data["links"]) + 1 + MARKERS
    head, rows = csv_rows(run["csv"])
    row = min(rows, key=lambda r: abs(float(r[0]) - got["time"]))
    assert abs(float(row[0]) - got["time"]) < 1e-9, "a frame is a sample of the run"
    expected = contact_from_csv(run["urdf"], head, row)
    # float32 in the page: 2^-24 of a few metres
    assert np.allclose(got["contactPoint"], expected, rtol=0, atol=1e-6), (got["contactPoint"], expected)


@needs_browser
def test_impact_frame_is_the_contact_instant(run):
    got = selftest(run["page"], 0)
    k = got["impactFrame"]
    assert k > 0
    at = selftest(run["page"], k)
    head, rows = csv_rows(run["csv"])
    t_capture = next(float(r[0]) for r in rows if r[head.index("phase")] == "capture")
    assert abs(at["time"] - t_capture) < 1e-9


@needs_browser
def test_screenshots_are_drawn_and_move(run):
    from matplotlib.image import imread
    images = []
    for frame in ["0", "last"]:
        png = run["dir"] / f"frame_{frame}.png"
        done = browser(run["page"], f"frame={frame}", f"--screenshot={png}", "--window-size=800,600")
        assert png.exists(), done.stderr[-2000:]
        images.append(imread(png)[..., :3])
    for image in images:
        colours = np.unique((image * 255).astype(np.uint8).reshape(-1, 3), axis=0)
        assert len(colours) > 20, f"{len(colours)} colours: a blank page"
    assert images[0].shape == images[1].shape
    assert np.abs(images[0] - images[1]).max() > 0.2, "the start and the end look the same"


@needs_browser
def test_a_failed_approach_still_writes_its_page(run, cli):
    scenario = run["dir"] / "short.yaml"
    scenario.write_text(run["scenario"].read_text().replace("max_duration: 30", "max_duration: 1"))
    page = run["dir"] / "failed.html"
    done = subprocess.run([cli, "simulate", str(scenario), "--html", str(page)], capture_output=True, text=True, timeout=300)
    assert done.returncode != 0 and page.exists(), done.stderr
    data = page_data(page)
    assert data["note"].startswith("The approach failed")
    got = selftest(page, data["frameCount"] - 1)
    assert got["errors"] == [] and got["objectCount"] == len(data["links"]) + 1 + MARKERS - 1  # no impulse


def test_html_may_not_overwrite_an_input(run, cli):
    done = subprocess.run([cli, "simulate", str(run["scenario"]), "--html", str(run["urdf"])], capture_output=True, text=True)
    assert done.returncode == 2 and "--html" in done.stderr and run["urdf"].exists()
    assert "<robot" in run["urdf"].read_text()


def test_a_long_run_is_decimated(run, cli):
    """250 s after the capture at 0.05 s (5000 samples): at most 3000 frames, in time order, the
    run's end the last."""
    page = run["dir"] / "long.html"
    done = subprocess.run([cli, "simulate", str(run["scenario"]), "--duration", "250", "--html", str(page), "--json"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    data = page_data(page)
    times = np.frombuffer(base64.b64decode(data["times"]), dtype=np.float64)
    frames = np.frombuffer(base64.b64decode(data["frames"]), dtype=np.float32)
    assert len(times) == data["frameCount"] <= 3000 and frames.size == data["frameCount"] * data["stride"]
    assert np.all(np.diff(times) >= 0)
    end = json.loads(done.stdout)
    assert end["simulation"]["html"] == str(page)
    t_end = end["approach"]["t_contact"] + 250
    assert abs(times[-1] - t_end) < 1e-6, (times[-1], t_end)
    assert page.stat().st_size < 5e6
