"""kdl_space simulate --html: the linked plots under the view, in a real browser (Debian's chromium,
headless). A test script is added at the end of a copy of the page (after the page's own): it
reads the page's hooks (window.kdlSpace.plots, plotValue, plotPoint, plotCursor), dispatches real
mouse events on the plots' canvases, and writes what it saw as JSON into <pre id="plottest">,
which `--dump-dom` prints. The plotted values are checked against the CSV of the same run: the
page stores them as float32 (2^-24 relative; tested at 1e-6 relative)."""
import json
import math
import re
import subprocess

import numpy as np
import pytest

from conftest import ARM, SOURCE_DIR
from test_html import browser, csv_rows, needs_browser, page_data, run  # noqa: F401  (run: the fixture)

# What the page stores: float32, 2^-24 relative (tested at 1e-6 relative, with an absolute floor
# far below any value the run gives except an exact zero).
RTOL, FLOOR = 1e-6, 1e-30


def in_browser(page, script, *extra):
    """Runs `script` (JavaScript; `K` is window.kdlSpace, `out` an object to fill) in a copy of the
    page, after the page's own script; returns `out` with K.errors as out.errors."""
    text = page.read_text()
    probe = ("<pre id=\"plottest\"></pre><script>\n(function () {\n var K = window.kdlSpace, out = {};\n"
             " try {\n" + script + "\n } catch (e) { K.errors.push('test script: ' + e.message); }\n"
             " out.errors = K.errors;\n document.getElementById('plottest').textContent = JSON.stringify(out);\n})();\n"
             "</script>\n</body></html>")
    assert text.rstrip().endswith("</body></html>")
    copy = page.with_name(page.stem + "_probe.html")
    copy.write_text(text.rstrip()[: -len("</body></html>")] + probe)
    done = browser(copy, "frame=0", "--dump-dom", *extra)
    m = re.search(r'<pre id="plottest">(.*?)</pre>', done.stdout, re.S)
    assert m and m.group(1), f"no output of the test script; chromium said: {done.stderr[-2000:]}"
    return json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&").replace("&lt;", "<").replace("&gt;", ">"))


def columns(csv):
    head, rows = csv_rows(csv)
    return {name: np.array([float(r[i]) if r[i] not in ("", "capture", "post", "approach", "motion") else math.nan
                            for r in rows]) for i, name in enumerate(head)}, [r[head.index("phase")] for r in rows]


def rpy_deg(qx, qy, qz, qw):
    """Roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll)) of a unit quaternion, in degrees."""
    R = np.array([[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
                  [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
                  [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]])
    return np.degrees([math.atan2(R[2, 1], R[2, 2]), math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0])),
                       math.atan2(R[1, 0], R[0, 0])])


def expected_series(col, phases, i, joints):
    """What each plot's series should be at CSV row i, from the CSV alone."""
    e = {("attitude", name): v for name, v in zip(["roll", "pitch", "yaw"],
                                                   rpy_deg(*(col[f"base_q{c}"][i] for c in "xyzw")))}
    for c in "xyz":
        e[("angular rate", f"w_{c}")] = math.degrees(col[f"base_w{c}"][i])
    for j in joints:
        e[("joint rates", j)] = col[f"qdot_{j}"][i]
        e[("joint torques", j)] = col[f"tau_{j}"][i]
    e[("momentum", "|P|")] = math.sqrt(sum(col[f"P_{c}"][i] ** 2 for c in "xyz"))
    e[("momentum", "|L|")] = math.sqrt(sum(col[f"L_{c}"][i] ** 2 for c in "xyz"))
    T = col["kinetic_energy"]
    e[("energy", "T")] = T[i]
    # The balance from the phase's first row: the approach's (and the contact instant's) from the
    # run's first, after the capture from the first post row.
    start = phases.index("post") if phases[i] == "post" else 0
    work = sum(col[name][i] for name in col if name.startswith("work_"))
    e[("energy balance", "T - T0 - work")] = T[i] - T[start] - work
    if "base_control_nx" in col:
        for c in "xyz":
            e[("base control", f"n_{c}")] = col[f"base_control_n{c}"][i]
    for name in col:
        if name.startswith("wheel_h_"):
            e[("wheel momentum", "h_" + name[len("wheel_h_"):])] = col[name][i]
    if "grasp_fx" in col:  # NaN (empty cells) where nothing is held
        e[("grasp load", "|f|")] = math.sqrt(sum(col[f"grasp_f{c}"][i] ** 2 for c in "xyz"))
        e[("grasp load", "|n|")] = math.sqrt(sum(col[f"grasp_n{c}"][i] ** 2 for c in "xyz"))
    return e


def check_values(page, csv, joints):
    data = page_data(page)
    n = data["frameCount"]
    frames = sorted({0, 1, n // 3, n // 2, n - 2, n - 1})
    got = in_browser(page, f"""
 out.plots = K.plots; out.values = {{}}; out.times = {{}};
 {json.dumps(frames)}.forEach(function (k) {{
   out.times[k] = K.time(k); out.values[k] = {{}};
   K.plots.forEach(function (p) {{
     out.values[k][p.name] = p.series.map(function (s) {{ return K.plotValue(p.name, s, k); }});
   }});
 }});""")
    assert got["errors"] == [], got["errors"]
    col, phases = columns(csv)
    checked = 0
    for k in frames:
        t = got["times"][str(k)]
        # The row of that time and phase (the contact instant and the first post row share a time).
        phase = ["approach", "capture", "post", "motion"][data["phases"][k]]
        i = min((r for r in range(len(phases)) if phases[r] == phase), key=lambda r: abs(col["t"][r] - t))
        assert abs(col["t"][i] - t) < 1e-9, "a frame is a sample of the run"
        want = expected_series(col, phases, i, joints)
        for p in got["plots"]:
            assert p["samples"] == n
            for s, value in zip(p["series"], got["values"][str(k)][p["name"]]):
                e = want[(p["name"], s)]
                if math.isnan(e):  # nothing to plot there (the grasp's load before the capture)
                    assert value is None or math.isnan(value), (k, p["name"], s, value)
                    checked += 1
                    continue
                # The balance: a difference of energies, each written with 17 digits.
                floor = 1e-12 * abs(col["kinetic_energy"][i]) if s == "T - T0 - work" else FLOOR
                assert value is not None and abs(value - e) <= RTOL * abs(e) + floor, (k, p["name"], s, value, e)
                checked += 1
    return got["plots"], checked


@needs_browser
def test_plotted_values_are_the_csvs(run):
    joints = [f"joint{j}" for j in range(1, 8)]
    plots, checked = check_values(run["page"], run["csv"], joints)
    names = [p["name"] for p in plots]
    assert names == ["attitude", "angular rate", "joint rates", "joint torques", "momentum", "energy", "energy balance",
                     "grasp load"], names  # the grasp's load: the hand holds the box after the capture
    assert next(p for p in plots if p["name"] == "joint rates")["series"] == joints
    assert checked == 6 * (3 + 3 + 7 + 7 + 2 + 1 + 1 + 2)


def geometry_script(name, targets):
    """Clicks (a mousedown and a mouseup) on plot `name` at each time of `targets`; per click: the
    time asked, the clientX asked and delivered, the frame then, and two points of the time axis."""
    return f"""
 var canvas = K.plotCanvas({json.dumps(name)}), slider = document.getElementById('slider');
 out.clicks = [];
 {json.dumps(targets)}.forEach(function (t) {{
   var at = K.plotPoint({json.dumps(name)}, t), seen = null;
   var listen = function (e) {{ seen = e.clientX; }};
   canvas.addEventListener('mousedown', listen);
   canvas.dispatchEvent(new MouseEvent('mousedown', {{ clientX: at.x, clientY: at.y, bubbles: true, button: 0 }}));
   window.dispatchEvent(new MouseEvent('mouseup', {{ clientX: at.x, clientY: at.y, bubbles: true }}));
   canvas.removeEventListener('mousedown', listen);
   out.clicks.push({{ t: t, x: at.x, delivered: seen, slider: parseInt(slider.value, 10), current: K.current() }});
 }});
 out.axis = [K.plotPoint({json.dumps(name)}, 0).x, K.plotPoint({json.dumps(name)}, 1).x];"""


def nearest_frame(times, t):
    return int(np.argmin(np.abs(times - t)))


@needs_browser
def test_clicking_a_plot_moves_the_slider(run):
    data = page_data(run["page"])
    times = np.frombuffer(__import__("base64").b64decode(data["times"]), dtype=np.float64)
    n = len(times)
    # Times between frames, away from the midpoints (a pixel either way does not change the nearest).
    targets = [float(times[k] + 0.2 * (times[k + 1] - times[k])) for k in (0, n // 4, n // 2, n - 2)] + [float(times[-1])]
    got = in_browser(run["page"], geometry_script("joint rates", targets), "--window-size=1600,900")
    assert got["errors"] == [], got["errors"]
    px_per_s = got["axis"][1] - got["axis"][0]
    assert px_per_s > 0
    for c in got["clicks"]:
        assert c["delivered"] is not None, "the canvas saw the mousedown"
        t_clicked = c["t"] + (c["delivered"] - c["x"]) / px_per_s  # the time under the pointer
        expected = nearest_frame(times, t_clicked)
        assert c["slider"] == expected and c["current"] == expected, (c, expected)
    assert got["clicks"][-1]["slider"] == n - 1
    assert len({c["slider"] for c in got["clicks"]}) == len(targets), "each click moved the slider"


@needs_browser
def test_dragging_on_a_plot_moves_the_slider(run):
    data = page_data(run["page"])
    times = np.frombuffer(__import__("base64").b64decode(data["times"]), dtype=np.float64)
    n = len(times)
    t1, t2 = float(times[n // 5]), float(times[3 * n // 4])
    got = in_browser(run["page"], f"""
 var canvas = K.plotCanvas('energy'), slider = document.getElementById('slider');
 var a = K.plotPoint('energy', {t1}), b = K.plotPoint('energy', {t2});
 canvas.dispatchEvent(new MouseEvent('mousedown', {{ clientX: a.x, clientY: a.y, bubbles: true }}));
 out.pressed = K.current();
 canvas.dispatchEvent(new MouseEvent('mousemove', {{ clientX: b.x, clientY: b.y, bubbles: true, buttons: 1 }}));
 out.dragged = K.current();
 window.dispatchEvent(new MouseEvent('mouseup', {{ bubbles: true }}));
 var c = K.plotPoint('energy', {float(times[0])});
 canvas.dispatchEvent(new MouseEvent('mousemove', {{ clientX: c.x, clientY: c.y, bubbles: true }}));
 out.released = K.current();
 out.slider = parseInt(slider.value, 10);""", "--window-size=1600,900")
    assert got["errors"] == [], got["errors"]
    # To within a pixel of the times asked (the frames are more than a pixel apart at this width).
    assert abs(got["pressed"] - n // 5) <= 1 and abs(got["dragged"] - 3 * n // 4) <= 1, got
    assert got["released"] == got["dragged"] == got["slider"], "a move without the button pressed does not drag"


@needs_browser
def test_the_cursor_follows_the_frame(run):
    data = page_data(run["page"])
    n = data["frameCount"]
    frames = [0, n // 3, n - 1]
    got = in_browser(run["page"], f"""
 out.cursors = [];
 {json.dumps(frames)}.forEach(function (k) {{
   K.setFrame(k);
   var row = [];
   K.plots.forEach(function (p) {{
     var c = K.plotCursor(p.name), canvas = K.plotCanvas(p.name);
     var at = K.plotPoint(p.name, K.time(k)), r = canvas.getBoundingClientRect();
     var pixel = canvas.getContext('2d').getImageData(c.x, Math.floor(canvas.height / 2), 1, 1).data;
     row.push({{ name: p.name, frame: c.frame, x: c.x, expectedX: (at.x - r.left) * canvas.width / r.width,
                 pixel: Array.prototype.slice.call(pixel) }});
   }});
   out.cursors.push(row);
 }});
 out.slider = parseInt(document.getElementById('slider').value, 10);""")
    assert got["errors"] == [], got["errors"]
    assert got["slider"] == n - 1
    xs = []
    for k, row in zip(frames, got["cursors"]):
        assert len(row) == len(got["cursors"][0]) >= 5
        for c in row:
            assert c["frame"] == k, c
            assert c["x"] == round(c["expectedX"]), c
            assert c["pixel"][:3] == [255, 0, 255], f"the cursor (magenta) is drawn at x = {c['x']} on {c['name']}: {c['pixel']}"
        xs.append(row[0]["x"])
    assert xs[0] < xs[1] < xs[2], "the cursor moves right as the frame goes on"


@pytest.fixture(scope="module")
def free_run(tmp_path_factory, cli):
    """A plain motion of the arm with its joints free (no servo, no friction): no torque acts."""
    d = tmp_path_factory.mktemp("free")
    scenario = d / "free.yaml"
    scenario.write_text(f"robot:\n  urdf: {ARM}\n  q: {{joint2: 0.7, joint4: 0.8}}\n  qdot: {{joint1: 0.2, joint4: -0.3}}\n"
                        "simulation:\n  duration: 1\n  output_step: 0.05\n")
    page, csv = d / "free.html", d / "free.csv"
    done = subprocess.run([cli, "simulate", str(scenario), "--html", str(page), "--csv", str(csv), "--json"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return {"page": page, "csv": csv}


@needs_browser
def test_a_run_without_torques_has_no_torque_plot(free_run):
    """Decided: no joint torque acted (the run's record) -> no torque plot (rather than a flat zero one)."""
    joints = [f"joint{j}" for j in range(1, 8)]
    col, _ = columns(free_run["csv"])
    assert all(np.all(col[f"tau_{j}"] == 0) for j in joints), "the scenario applies no torque"
    plots, _ = check_values(free_run["page"], free_run["csv"], joints)
    assert [p["name"] for p in plots] == ["attitude", "angular rate", "joint rates", "momentum", "energy", "energy balance"]


@needs_browser
def test_base_control_has_its_plot(tmp_path, cli):
    """scenarios/base_attitude_control.yaml (servos and an attitude control): its torque's plot too."""
    page, csv = tmp_path / "bc.html", tmp_path / "bc.csv"
    done = subprocess.run([cli, "simulate", str(SOURCE_DIR / "scenarios" / "base_attitude_control.yaml"), "--duration", "3",
                           "--html", str(page), "--csv", str(csv)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    plots, _ = check_values(page, csv, [f"joint{j}" for j in range(1, 8)])
    assert [p["name"] for p in plots][-1] in ("base control", "grasp load")
    assert "base control" in [p["name"] for p in plots]
    col, _ = columns(csv)
    assert np.abs(col["base_control_nz"]).max() > 1e-6, "the control acts"


@needs_browser
def test_reaction_wheels_have_their_plot(tmp_path, cli):
    """scenarios/detumble_with_wheels.yaml: the wheels' momenta have a plot, the CSV's at every frame."""
    page, csv = tmp_path / "wheels.html", tmp_path / "wheels.csv"
    done = subprocess.run([cli, "simulate", str(SOURCE_DIR / "scenarios" / "detumble_with_wheels.yaml"), "--duration", "10",
                           "--html", str(page), "--csv", str(csv)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    plots, checked = check_values(page, csv, [f"joint{j}" for j in range(1, 8)])
    assert [p["name"] for p in plots][-3:] == ["base control", "wheel momentum", "grasp load"]
    assert plots[-2]["series"] == ["h_1", "h_2", "h_3"] and plots[-1]["series"] == ["|f|", "|n|"]
    col, _ = columns(csv)
    assert np.abs(col["wheel_h_3"]).max() > 1.0, "the wheels take momentum"


def test_a_humanoids_page_stays_small(tmp_path, cli):
    """A 20 s run of the 46-joint humanoid (tests/data/real_patterns/humanoid44.urdf, free joints
    with their URDF friction) at 100 rows a second: the page, its plots' series included, under
    5 MB (about 2.6 MB: 501 frames, 102 float32 a frame for the plots, 272 kB in base64)."""
    scenario = tmp_path / "humanoid.yaml"
    scenario.write_text(f"robot:\n  urdf: {SOURCE_DIR / 'tests' / 'data' / 'real_patterns' / 'humanoid44.urdf'}\n"
                        "  base: {position: [0, 0, 0], rpy: [0, 0, 0], twist: [0.01, 0, 0, 0.02, -0.01, 0.03]}\n"
                        "simulation:\n  duration: 20\n  output_step: 0.01\n  integrator: rosenbrock\n"
                        "  rtol: 1.0e-6\n  atol: 1.0e-8\n")
    page = tmp_path / "humanoid.html"
    done = subprocess.run([cli, "simulate", str(scenario), "--html", str(page)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    data = page_data(page)
    rates = next(p for p in data["plots"] if p["name"] == "joint rates")
    assert len(rates["series"]) == 46
    series = __import__("base64").b64decode(data["series"])
    assert len(series) == 4 * data["frameCount"] * data["seriesStride"]
    assert data["seriesStride"] >= 6 + 46 + 2 + 2
    assert page.stat().st_size < 5e6, page.stat().st_size
