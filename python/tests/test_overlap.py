"""The overlap warning in Python's results: a robot link inside the target's box of inertia at the
capture, in solve_capture(scenario).warnings (with the robot's URDF visuals) and in
run_operation's 'warnings' (kind 'overlap', link, target, depth [m], moment), as the tool's."""
import kdl_space

STICK_ARM = """<robot name="stick">
  <link name="base"><inertial><mass value="100"/><inertia ixx="10" iyy="10" izz="10" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="1 1 1"/></geometry></visual></link>
  <link name="link1">{inertial}<visual><origin xyz="0 0 0.5"/><geometry><box size="0.1 0.1 1"/></geometry></visual></link>
  <link name="link2">{inertial}<visual><origin xyz="0 0 0.25"/><geometry><sphere radius="0.05"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="link1"/><origin xyz="0 0 0.5"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="link1"/><child link="link2"/><origin xyz="0 0 1"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
</robot>""".format(inertial='<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>')


def swallowed(tmp_path, z):
    """The stick arm (link1's visual: 0.1 x 0.1 x 1, z 0.5..1.5) holding a 12 kg target whose box of
    inertia is a 2 m cube (I = 12 (4 + 4) / 12 = 8) centred at height z."""
    (tmp_path / "stick.urdf").write_text(STICK_ARM)
    path = tmp_path / "swallowed.yaml"
    path.write_text("robot:\n  urdf: stick.urdf\n  contact: {link: link2, offset: [0, 0, 0.5]}\n"
                    "target:\n  mass: 12\n  inertia: [[8, 0, 0], [0, 8, 0], [0, 0, 8]]\n"
                    f"  pose: {{position: [0, 0, {z}]}}\n  twist: [0.01, 0, 0, 0, 0, 0]\n"
                    "law: {type: capture}\nsimulation: {duration: 0.1, output_step: 0.05}\n")
    return kdl_space.load_scenario(str(path))


def test_solve_capture_warns_of_a_link_inside_the_target(tmp_path):
    # The cube spans z 0.6..2.6: link1 is 1.5 - 0.6 = 0.9 deep (sideways 1.05, upwards 2.1).
    warnings = kdl_space.solve_capture(swallowed(tmp_path, 1.6)).warnings
    overlaps = [w for w in warnings if w["kind"] == "overlap"]
    assert len(overlaps) == 1, warnings
    w = overlaps[0]
    assert (w["element"], w["link"], w["target"], w["moment"], w["geometry"]) == ("link1", "link1", "target", "capture", "visuals")
    assert abs(w["depth"] - 0.9) < 1e-9
    assert "link 'link1'" in w["message"] and "0.9 m" in w["message"]


def test_solve_capture_of_a_problem_checks_the_boxes_of_inertia(tmp_path):
    # Without the URDF's visuals, the boxes of inertia: the base's a cube of edge sqrt(6 * 10 / 100)
    # at z = 0, link1's (the wrist: it carries the hand) of edge sqrt(6 * 0.01 / 1) at z = 0.5. The
    # target's cube at z = 1.3 spans 0.3..2.3: the base is (edge_b / 2 - 0.3) in, link1 (0.5 +
    # edge_1 / 2 - 0.3), beyond its allowance, 1 cm plus the grasp point's depth (2.3 - 2.0).
    problem = swallowed(tmp_path, 1.3).problem
    overlaps = [w for w in kdl_space.solve_capture(problem).warnings if w["kind"] == "overlap"]
    assert [(w["link"], w["geometry"]) for w in overlaps] == [("link1", "inertia_box"), ("base", "inertia_box")]
    edge_b, edge_1 = (6 * 10 / 100) ** 0.5, (6 * 0.01 / 1) ** 0.5
    assert abs(overlaps[0]["depth"] - (0.5 + edge_1 / 2 - 0.3)) < 1e-9
    assert abs(overlaps[1]["depth"] - (edge_b / 2 - 0.3)) < 1e-9
    assert "the grasp point, 0.3 m inside the box" in overlaps[0]["message"]


def test_no_overlap_no_warning(tmp_path):
    assert [w for w in kdl_space.solve_capture(swallowed(tmp_path, 2.55)).warnings if w["kind"] == "overlap"] == []


def test_run_operation_carries_the_warning(tmp_path):
    d = kdl_space.run_operation(swallowed(tmp_path, 1.6), duration=0.05)
    overlaps = [w for w in d["warnings"] if w["kind"] == "overlap"]
    assert [(w["link"], w["moment"]) for w in overlaps] == [("link1", "capture")]
    assert abs(overlaps[0]["depth"] - 0.9) < 1e-9
