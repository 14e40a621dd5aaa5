"""kdl_space simulate --html with a URDF's meshes: STL (binary and ASCII) and COLLADA files made
here under a package folder, named `package://pkg/meshes/...`, found through --mesh-path or
ROS_PACKAGE_PATH, embedded once each and drawn by three.js's own loaders in a real browser
(Debian's chromium, headless). What the page loaded (window.kdlSpace.meshes: vertices and the box
in the link's frame) is checked against the triangles written here; a mesh that cannot be drawn is
its link's box of inertia with a warning that names the file."""
import json
import os
import struct
import subprocess
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from conftest import ARM, CAPTURE_SCENARIO
from test_html import needs_browser, page_data, selftest

# The first line of Debian's loaders (inlined only into a page with such a mesh).
STL_LOADER = "Generated from 'examples/jsm/loaders/STLLoader.js'"
COLLADA_LOADER = "Generated from 'examples/jsm/loaders/ColladaLoader.js'"
# An axis-aligned box [lo, hi] (not centred, so that a swapped or flipped axis shows), 12 triangles.
LO, HI = np.array([-0.1, -0.05, 0.0]), np.array([0.2, 0.3, 0.4])
# A tetrahedron: 4 triangles.
TET = np.array([[0, 0, 0], [0.25, 0, 0], [0, 0.5, 0], [0, 0, 0.125]])
# The COLLADA box's corners, in its own unit (decimetres: <unit meter="0.1"/>), Z_UP.
DAE_LO, DAE_HI = np.array([-1.0, -2.0, 0.5]), np.array([3.0, 1.0, 4.0])


def box_triangles(lo, hi):
    c = [np.array([(hi if i & 1 else lo)[0], (hi if i & 2 else lo)[1], (hi if i & 4 else lo)[2]]) for i in range(8)]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    return [tri for a, b, e, d in faces for tri in [(c[a], c[b], c[e]), (c[a], c[e], c[d])]]


def binary_stl(triangles):
    out = bytearray(b"binary box".ljust(80, b" ")) + struct.pack("<I", len(triangles))
    for t in triangles:
        out += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *v) for v in t) + struct.pack("<H", 0)
    return bytes(out)


def ascii_stl(triangles):
    lines = ["solid tet"]
    for t in triangles:
        lines += ["facet normal 0 0 0", " outer loop"] + [f"  vertex {v[0]!r} {v[1]!r} {v[2]!r}" for v in t] + [" endloop", "endfacet"]
    return "\n".join(lines + ["endsolid tet", ""])


def collada_box(lo, hi):
    c = [((hi if i & 1 else lo)[0], (hi if i & 2 else lo)[1], (hi if i & 4 else lo)[2]) for i in range(8)]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    index = " ".join(f"{a} {b} {d} {a} {d} {e}" for a, b, d, e in faces)
    positions = " ".join(repr(float(x)) for corner in c for x in corner)
    return f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="decimetre" meter="0.1"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries>
    <geometry id="box-mesh" name="box"><mesh>
      <source id="box-positions">
        <float_array id="box-positions-array" count="24">{positions}</float_array>
        <technique_common><accessor source="#box-positions-array" count="8" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common>
      </source>
      <vertices id="box-vertices"><input semantic="POSITION" source="#box-positions"/></vertices>
      <triangles count="12"><input semantic="VERTEX" source="#box-vertices" offset="0"/><p>{index}</p></triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="Scene" name="Scene"><node id="box" name="box" type="NODE"><instance_geometry url="#box-mesh"/></node></visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
"""


# link: (filename, scale, origin xyz, colour); link2 and link3 share a file (stored once).
MESHES = {
    "link2": ("package://pkg/meshes/box_binary.stl", (0.5, 1.0, 2.0), (0.1, 0.0, 0.0), "0.2 0.6 0.9 1"),
    "link3": ("package://pkg/meshes/box_binary.stl", (1.0, 1.0, 1.0), (0.0, 0.0, 0.0), None),
    "link4": ("package://pkg/meshes/tet_ascii.stl", (2.0, 2.0, 2.0), (0.0, 0.0, 0.05), None),
    "link6": ("package://pkg/meshes/box.dae", (1.0, 2.0, 3.0), (0.0, 0.0, 0.0), None),
    "link5": ("package://pkg/meshes/missing.stl", (1.0, 1.0, 1.0), (0.0, 0.0, 0.0), None),
    "link7": ("meshes/hand.obj", (1.0, 1.0, 1.0), (0.0, 0.0, 0.0), None),
}
# What each drawn link's mesh is: its triangles and its box, in the file's own coordinates [m].
DRAWN = {"link2": (12, LO, HI), "link3": (12, LO, HI), "link4": (4, TET.min(0), TET.max(0)),
         "link6": (12, 0.1 * DAE_LO, 0.1 * DAE_HI)}


@pytest.fixture(scope="module")
def tree(tmp_path_factory):
    d = tmp_path_factory.mktemp("meshes")
    meshes = d / "share" / "pkg" / "meshes"
    meshes.mkdir(parents=True)
    (meshes / "box_binary.stl").write_bytes(binary_stl(box_triangles(LO, HI)))
    tet = [(TET[0], TET[2], TET[1]), (TET[0], TET[1], TET[3]), (TET[0], TET[3], TET[2]), (TET[1], TET[2], TET[3])]
    (meshes / "tet_ascii.stl").write_text(ascii_stl(tet))
    (meshes / "box.dae").write_text(collada_box(DAE_LO, DAE_HI))
    (d / "robot" / "meshes").mkdir(parents=True)
    (d / "robot" / "meshes" / "hand.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    tree = ET.parse(ARM)
    for link in tree.getroot().findall("link"):
        if link.get("name") in MESHES:
            file, scale, xyz, rgba = MESHES[link.get("name")]
            colour = f'<material name="m_{link.get("name")}"><color rgba="{rgba}"/></material>' if rgba else ""
            link.append(ET.fromstring(f'<visual><origin xyz="{" ".join(map(str, xyz))}"/><geometry><mesh filename="{file}" '
                                      f'scale="{" ".join(map(str, scale))}"/></geometry>{colour}</visual>'))
    urdf = d / "robot" / "arm.urdf"
    tree.write(urdf)
    scenario = d / "scenario.yaml"
    scenario.write_text(CAPTURE_SCENARIO.read_text().replace("../urdf/space_arm7.urdf", str(urdf)))
    return {"dir": d, "share": d / "share", "scenario": scenario}


def simulate(cli, tree, name, *extra, env=None):
    page = tree["dir"] / f"{name}.html"
    environment = {k: v for k, v in os.environ.items() if k != "ROS_PACKAGE_PATH"}
    environment.update(env or {})
    done = subprocess.run([cli, "simulate", str(tree["scenario"]), "--duration", "0.2", "--html", str(page), "--json", *extra],
                          capture_output=True, text=True, timeout=300, env=environment)
    assert done.returncode == 0, done.stderr
    return page, done


@pytest.fixture(scope="module")
def with_mesh_path(cli, tree):
    return simulate(cli, tree, "mesh_path", "--mesh-path", str(tree["dir"] / "robot"), "--mesh-path", str(tree["share"]))


@pytest.fixture(scope="module")
def with_ros_package_path(cli, tree):
    return simulate(cli, tree, "ros", env={"ROS_PACKAGE_PATH": f"/nonexistent:{tree['share']}"})


@pytest.fixture(scope="module")
def without(cli, tree):
    return simulate(cli, tree, "without")


def test_each_mesh_file_is_embedded_once(with_mesh_path):
    data = page_data(with_mesh_path[0])
    files = sorted(os.path.basename(m["file"]) for m in data["meshes"])
    assert files == ["box.dae", "box_binary.stl", "tet_ascii.stl"]
    text = with_mesh_path[0].read_text()
    assert STL_LOADER in text and COLLADA_LOADER in text


def test_a_mesh_that_cannot_be_drawn_is_named_in_a_warning(with_mesh_path):
    page, done = with_mesh_path
    for link, file in [("link5", "package://pkg/meshes/missing.stl"), ("link7", "meshes/hand.obj")]:
        line = next((l for l in done.stderr.splitlines() if l.startswith(f"kdl_space: warning: {link}: ")), "")
        assert file in line, done.stderr
    assert "--mesh-path" in next(l for l in done.stderr.splitlines() if "missing.stl" in l)
    warnings = json.loads(done.stdout)["warnings"]
    named = {w["element"]: w["message"] for w in warnings if w["kind"] == "mesh_not_drawn"}
    assert set(named) == {"link5", "link7"} and "missing.stl" in named["link5"] and "hand.obj" in named["link7"]
    links = {link["name"]: link["visuals"] for link in page_data(page)["links"]}
    assert links["link5"][0].get("inertia_box") and links["link7"][0].get("inertia_box")


def expected_box(link):
    _, lo, hi = DRAWN[link]
    _, scale, xyz, _ = MESHES[link]
    return np.concatenate([np.array(xyz) + np.array(scale) * lo, np.array(xyz) + np.array(scale) * hi])


@needs_browser
@pytest.mark.parametrize("how", ["with_mesh_path", "with_ros_package_path"])
def test_meshes_render_as_written(request, how):
    page, _ = request.getfixturevalue(how)
    got = selftest(page, 0)
    assert got["errors"] == [], got["errors"]
    meshes = {m["link"]: m for m in got["meshes"]}
    assert set(meshes) == set(DRAWN), got["meshes"]
    for link, (triangles, _, _) in DRAWN.items():
        assert meshes[link]["file"] == MESHES[link][0]
        assert meshes[link]["vertices"] == 3 * triangles, (link, meshes[link])
        # float32 vertices: 2^-24 of a few tenths of a metre; the COLLADA's up axis is ignored
        # (as RViz does), its unit kept.
        assert np.allclose(meshes[link]["box"], expected_box(link), rtol=0, atol=1e-6), (link, meshes[link]["box"], expected_box(link))


@needs_browser
def test_without_a_search_path_the_page_opens_with_boxes(without):
    page, done = without
    for file in ["box_binary.stl", "tet_ascii.stl", "box.dae", "missing.stl"]:
        assert f"package://pkg/meshes/{file}" in done.stderr, done.stderr
    data = page_data(page)
    assert data["meshes"] == []
    assert STL_LOADER not in page.read_text() and COLLADA_LOADER not in page.read_text(), "no loader without a mesh"
    got = selftest(page, 0)
    assert got["errors"] == [] and got["meshes"] == []
    assert got["objectCount"] == len(data["links"]) + 1 + 4  # the links, the target, the markers


def test_mesh_path_must_be_a_folder(cli, tree):
    done = subprocess.run([cli, "simulate", str(tree["scenario"]), "--html", str(tree["dir"] / "x.html"),
                           "--mesh-path", str(tree["dir"] / "nowhere")], capture_output=True, text=True)
    assert done.returncode == 2 and "--mesh-path" in done.stderr and "nowhere" in done.stderr, done.stderr


# --- to_html(path, mesh_path=...): Python's --mesh-path; no page replaces a mesh it embeds -------

def embedded_files(page):
    """The embedded meshes: basename -> bytes (decoded from the page's base64)."""
    import base64
    return {os.path.basename(m["file"]): base64.b64decode(m["data"]) for m in page_data(page)["meshes"]}


@pytest.fixture
def no_ros_package_path(monkeypatch):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)


@pytest.mark.parametrize("as_list", [True, False])
def test_to_html_finds_meshes_through_mesh_path(tree, tmp_path, no_ros_package_path, as_list):
    import kdl_space
    sc = kdl_space.load_scenario(str(tree["scenario"]))
    share = tree["share"] / "pkg" / "meshes"
    expected = {name: (share / name).read_bytes() for name in ["box_binary.stl", "tet_ascii.stl", "box.dae"]}
    mesh_path = [str(tree["dir"] / "robot"), tree["share"]] if as_list else str(tree["share"])
    capture = tmp_path / "capture.html"
    # A mesh the page cannot draw is a Python warning that names its link (the tool's stderr line).
    with pytest.warns(UserWarning, match=r"^link7: --html: the mesh meshes/hand.obj .* only STL and COLLADA"):
        kdl_space.solve_capture(sc).to_html(str(capture), mesh_path=mesh_path)
    assert embedded_files(capture) == expected
    run = tmp_path / "run.html"
    with pytest.warns(UserWarning, match=r"^link5: --html: the mesh package://pkg/meshes/missing.stl was not found"):
        kdl_space.run_operation(sc, duration=0.1).to_html(str(run), mesh_path=mesh_path)
    assert embedded_files(run) == expected
    # Without it (and no ROS_PACKAGE_PATH), the boxes of inertia: no mesh embedded.
    with pytest.warns(UserWarning, match=r"^link2: --html: the mesh package://pkg/meshes/box_binary.stl was not found"):
        kdl_space.solve_capture(sc).to_html(str(capture))
    assert embedded_files(capture) == {}


def test_to_html_never_replaces_a_mesh_it_embeds(tree, tmp_path, no_ros_package_path):
    import kdl_space
    sc = kdl_space.load_scenario(str(tree["scenario"]))
    mesh = tree["share"] / "pkg" / "meshes" / "box_binary.stl"
    before = mesh.read_bytes()
    (tmp_path / "alias.html").symlink_to(mesh)  # the same file by inode, under another name
    capture, run = kdl_space.solve_capture(sc), kdl_space.run_operation(sc, duration=0.1)
    for result in [capture, run]:
        for path in [str(mesh), str(tmp_path / "alias.html")]:
            with pytest.raises(ValueError) as e:
                result.to_html(path, mesh_path=[tree["share"]])
            assert path in str(e.value) and "the mesh package://pkg/meshes/box_binary.stl of link link" in str(e.value), e.value
            assert mesh.read_bytes() == before
    assert (tmp_path / "alias.html").is_symlink()
    with pytest.raises(ValueError, match="mesh_path .*nowhere is not a folder"):
        capture.to_html(str(tmp_path / "p.html"), mesh_path=[tree["dir"] / "nowhere"])
    assert not (tmp_path / "p.html").exists()
