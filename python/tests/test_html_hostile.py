"""A page built from a hostile robot folder (issue 35, item 2): meshes that are links to files
outside it, `package://` paths that climb out, a COLLADA texture that is a URL (a beacon). The
page holds none of the outside bytes, names each refused mesh in a warning, and, opened offline in
Chromium with its network log on and a local HTTP server listening at the beacon's address, makes
no request: the server sees none, the log names no request of the page's beyond its file."""
import base64
import http.server
import json
import os
import subprocess
import threading
import xml.etree.ElementTree as ET

import pytest

from conftest import ARM, CAPTURE_SCENARIO
from test_html import CHROMIUM, needs_browser, page_data
from test_html_meshes import DAE_HI, DAE_LO, HI, LO, binary_stl, box_triangles, collada_box

SECRET = b"kdl_space-secret-" + os.urandom(12).hex().encode() + b"\n"


class Beacon(http.server.BaseHTTPRequestHandler):
    hits = []

    def do_GET(self):  # noqa: N802 (the handler's name)
        Beacon.hits.append(self.path)
        self.send_response(404)
        self.end_headers()

    def log_message(self, *args):
        pass


@pytest.fixture(scope="module")
def beacon():
    server = http.server.HTTPServer(("127.0.0.1", 0), Beacon)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}"
    server.shutdown()


def textured_collada(url):
    """test_html_meshes' box, its triangles bound to a material whose diffuse is a texture at `url`."""
    texture = f"""</asset>
  <library_images><image id="tex"><init_from>{url}/beacon.png</init_from></image></library_images>
  <library_effects><effect id="eff"><profile_COMMON>
    <newparam sid="surf"><surface type="2D"><init_from>tex</init_from></surface></newparam>
    <newparam sid="samp"><sampler2D><source>surf</source></sampler2D></newparam>
    <technique sid="common"><lambert><diffuse><texture texture="samp" texcoord="UV"/></diffuse></lambert></technique>
  </profile_COMMON></effect></library_effects>
  <library_materials><material id="mat"><instance_effect url="#eff"/></material></library_materials>"""
    bound = ('<instance_geometry url="#box-mesh"><bind_material><technique_common>'
             '<instance_material symbol="skin" target="#mat"/></technique_common></bind_material></instance_geometry>')
    text = collada_box(DAE_LO, DAE_HI).replace("</asset>", texture).replace('<triangles count="12">', '<triangles count="12" material="skin">')
    return text.replace('<instance_geometry url="#box-mesh"/>', bound)


# link: the mesh's filename; each but link6 points outside the robot's folder and the search path.
HOSTILE = {
    "link2": "meshes/secret.stl",                          # a link to the outside file
    "link3": "package://pkg/meshes/secret.stl",            # a link in the package
    "link4": "package://pkg/../../outside/secret.stl",     # climbs out of the package
    "link5": "package://../outside/secret.stl",            # the package is ".."
    "link7": "package://pkg//OUTSIDE/secret.stl",          # absolute after the package
    "link6": "package://pkg/meshes/textured.dae",          # inside, with a texture URL
}


@pytest.fixture(scope="module")
def hostile(tmp_path_factory, cli, beacon):
    d = tmp_path_factory.mktemp("hostile")
    outside = d / "outside"
    outside.mkdir()
    secret = outside / "secret.stl"
    stl = bytearray(binary_stl(box_triangles(LO, HI)))
    stl[:80] = SECRET.ljust(80)  # a drawable mesh whose first bytes are the secret
    secret.write_bytes(bytes(stl))
    (d / "robot" / "meshes").mkdir(parents=True)
    (d / "robot" / "meshes" / "secret.stl").symlink_to(secret)
    package = d / "share" / "pkg" / "meshes"
    package.mkdir(parents=True)
    (package / "secret.stl").symlink_to(secret)
    (package / "textured.dae").write_text(textured_collada(beacon))
    tree = ET.parse(ARM)
    for link in tree.getroot().findall("link"):
        if link.get("name") in HOSTILE:
            file = HOSTILE[link.get("name")].replace("OUTSIDE", str(outside).lstrip("/"))
            link.append(ET.fromstring(f'<visual><geometry><mesh filename="{file}"/></geometry></visual>'))
    urdf = d / "robot" / "arm.urdf"
    tree.write(urdf)
    scenario = d / "scenario.yaml"
    scenario.write_text(CAPTURE_SCENARIO.read_text().replace("../urdf/space_arm7.urdf", str(urdf)))
    page = d / "page.html"
    environment = {k: v for k, v in os.environ.items() if k != "ROS_PACKAGE_PATH"}
    done = subprocess.run([cli, "simulate", str(scenario), "--duration", "0.2", "--html", str(page), "--json",
                           "--mesh-path", str(d / "share")], capture_output=True, text=True, timeout=300, env=environment)
    assert done.returncode == 0, done.stderr
    return {"dir": d, "page": page, "done": done, "secret": secret}


def test_the_page_holds_no_byte_from_outside(hostile):
    text = hostile["page"].read_bytes()
    for needle in [SECRET.strip(), base64.b64encode(hostile["secret"].read_bytes())[:40], b"beacon.png",
                   b"127.0.0.1:"]:
        assert needle not in text, needle
    data = page_data(hostile["page"])
    assert [os.path.basename(m["file"]) for m in data["meshes"]] == ["textured.dae"]
    for m in data["meshes"]:
        assert b"library_images" not in base64.b64decode(m["data"])


def test_each_refused_mesh_is_named_with_its_reason(hostile):
    warnings = json.loads(hostile["done"].stdout)["warnings"]
    refused = {w["element"]: w["message"] for w in warnings if w["kind"] == "mesh_not_drawn"}
    assert set(refused) == {"link2", "link3", "link4", "link5", "link7"}, refused
    assert "is outside" in refused["link2"] and "give --mesh-path" in refused["link2"], refused["link2"]
    assert "is outside" in refused["link3"], refused["link3"]
    for link in ["link4", "link5", "link7"]:
        assert "leaves its package" in refused[link], refused[link]
    dropped = [w for w in warnings if w["kind"] == "mesh_reference_dropped"]
    assert [w["element"] for w in dropped] == ["link6"] and "library_images" in dropped[0]["message"], dropped
    for link in refused:
        assert f"kdl_space: warning: {link}: --html: the mesh" in hostile["done"].stderr


@needs_browser
def test_the_page_opened_offline_fetches_nothing(hostile, tmp_path):
    Beacon.hits.clear()
    log = tmp_path / "netlog.json"
    done = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
                           "--virtual-time-budget=5000", f"--log-net-log={log}", "--dump-dom",
                           f"file://{hostile['page']}#selftest=0"], capture_output=True, text=True, timeout=120)
    assert '<pre id="selftest">' in done.stdout, done.stderr[-2000:]
    assert Beacon.hits == [], Beacon.hits
    # Every request the page started (its initiator is the page's origin, "null" for a file:// page;
    # Chromium's own, to its update and time services, say "not an origin"): none leaves the file.
    netlog = json.loads(log.read_text())
    start_job = netlog["constants"]["logEventTypes"]["URL_REQUEST_START_JOB"]
    by_page = sorted(e["params"]["url"] for e in netlog["events"] if e["type"] == start_job and
                     "url" in e.get("params", {}) and e["params"].get("initiator") != "not an origin")
    assert [u for u in by_page if not u.startswith(("file:", "data:", "blob:"))] == [], by_page


# --- names that would end or swallow the page's script (issue 35, item 7) --------------------------

NASTY = "<!--<script>"


@pytest.fixture(scope="module")
def nasty_page(tmp_path_factory, cli):
    """The arm with link3 named `<!--<script>` and joint5 `</script><b>`: the page of a short run."""
    d = tmp_path_factory.mktemp("nasty")
    text = ARM.read_text().replace('"link3"', '"&lt;!--&lt;script&gt;"').replace('"joint5"', '"&lt;/script&gt;&lt;b&gt;"')
    urdf = d / "arm.urdf"
    urdf.write_text(text)
    scenario = d / "scenario.yaml"
    scenario.write_text(CAPTURE_SCENARIO.read_text().replace("../urdf/space_arm7.urdf", str(urdf))
                        .replace("joint5:", '"</script><b>":'))
    page = d / "page.html"
    done = subprocess.run([cli, "simulate", str(scenario), "--duration", "0.2", "--html", str(page)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return page


def test_no_name_ends_or_swallows_the_pages_script(nasty_page):
    text = nasty_page.read_text()
    data = text[text.index("window.KDL_DATA = "):]
    data = data[:data.index(";\n</script>")]
    assert "<" not in data and ">" not in data, "every < and > in the data is a JSON escape"
    names = {link["name"] for link in page_data(nasty_page)["links"]}
    assert NASTY in names, names


@needs_browser
def test_a_page_with_such_names_still_draws(nasty_page):
    from test_html import selftest
    got = selftest(nasty_page, 0)
    assert got["errors"] == [], got["errors"]
    assert got["objectCount"] > 5
