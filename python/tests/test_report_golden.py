"""The reports after they moved into the report layer (issue 36) against what the tool printed
before (tests/data/golden/reports, README there): capture, ik, plan and inspect --json of the
shipped scenarios, the same keys, strings and nulls and the numbers within 1e-9; and Python's
dicts (run_operation, ik, plan_capture) from the same report JSON the tool prints."""
import json
import subprocess

import pytest

from conftest import SOURCE_DIR
from test_operation import assert_same

GOLDEN = SOURCE_DIR / "tests" / "data" / "golden" / "reports"
SCENARIOS = SOURCE_DIR / "scenarios"


def tool_json(cli, *args):
    out = subprocess.run([cli, *args], capture_output=True, text=True, timeout=600, cwd=SCENARIOS)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


@pytest.mark.parametrize("name", sorted(p.name.split(".")[0] for p in GOLDEN.glob("*.capture.json")))
def test_capture_json_is_what_the_tool_printed_before(cli, name):
    before = json.loads((GOLDEN / f"{name}.capture.json").read_text())
    assert_same(before, tool_json(cli, "capture", f"{name}.yaml", "--json"), 1e-9, 1e-12)


@pytest.mark.parametrize("what,args", [
    ("ik", ["ik", "tumbling_box_capture.yaml", "--position", "0.6,0.2,0.3", "--json"]),
    ("plan", ["plan", "tumbling_box_capture.yaml", "--json"]),
    ("inspect", ["inspect", "--urdf", "../urdf/spacedyn_twolink.urdf", "--tip", "hand", "--json"]),
])
def test_ik_plan_and_inspect_json_are_what_the_tool_printed_before(cli, what, args):
    before = json.loads((GOLDEN / f"{what}.json").read_text())
    now = tool_json(cli, *args)
    if what == "plan":
        # The optimiser's path (BOBYQA's evaluations) follows the last bits of the objective, which
        # move with the build (a unity batch's inlining into the x86-64-v3 clones, where GCC fuses
        # multiply-adds): the count within 5 %, the optimum it finds at 1e-9.
        a, b = before.pop("evaluations"), now.pop("evaluations")
        assert abs(a - b) <= 0.05 * a, (a, b)
        # Its joints are an inverse kinematics' (pose tolerance 1e-10; the self-motion's origin,
        # the posture nearest the scenario's, to round-off since issue 38: plan.json was printed
        # again then, README there): fixed to 1e-9 rad, not to 1e-9 of each angle.
        assert_same(before, now, 1e-9, 1e-9)
        return
    assert_same(before, now, 1e-9, 1e-12)


def test_python_dicts_are_the_tools_json(cli):
    """Without text in between (json_objects.cpp): the same keys and values, exactly."""
    import kdl_space
    scenario = SCENARIOS / "tumbling_box_capture.yaml"
    ik = kdl_space.ik(str(scenario), ([0.6, 0.2, 0.3], [0, 0, 0]))  # position, rpy
    tool = tool_json(cli, "ik", "tumbling_box_capture.yaml", "--position", "0.6,0.2,0.3", "--json")
    assert {"q_by_name", "position_residual", "moved_joints"} <= ik.keys() & tool.keys()
    for key, value in ik.items():
        if key in tool:
            assert json.loads(json.dumps(value if not hasattr(value, "tolist") else value.tolist())) == tool[key], key
    plan = kdl_space.plan_capture(scenario)
    tool_plan = tool_json(cli, "plan", "tumbling_box_capture.yaml", "--json")
    assert plan.optimum == tool_plan["optimum"] and plan.nominal == tool_plan["nominal"]


def test_the_study_table_is_what_the_tool_wrote_before(cli, tmp_path):
    """The first of 8 shards of the shipped study (its table's format moved into the library's
    study/ layer): the same head line (fingerprint, rows), columns and statuses, the numbers within
    1e-9; and Python's study_to_table writes the tool's bytes."""
    import math
    import kdl_space
    before = (GOLDEN / "study_grasp_configuration.part-1-of-8.csv").read_text().splitlines()
    out = subprocess.run([cli, "study", "study_grasp_configuration.yaml", "--shard", "1/8", "-o", tmp_path / "now.csv"],
                         capture_output=True, text=True, timeout=600, cwd=SCENARIOS)
    assert out.returncode == 0, out.stderr
    now = (tmp_path / "now.csv").read_text().splitlines()
    assert now[:2] == before[:2] and len(now) == len(before) == 53
    assert now[-1].startswith("# end; rows 0-50; crc32 ")
    for a, b in zip(before[2:-1], now[2:-1]):
        x, y = [float(v) for v in a.split(",")], [float(v) for v in b.split(",")]
        assert x[:2] == y[:2]  # sample, status
        for u, v in zip(x, y):
            assert (math.isnan(u) and math.isnan(v)) or abs(u - v) <= 1e-9 * max(1.0, abs(u)), (a, b)
    done = kdl_space.study_to_table(SCENARIOS / "study_grasp_configuration.yaml", tmp_path / "py.csv", shard=(1, 8))
    assert done["summary"] is None
    # the fingerprint folds the study's path as given: the same path, the same bytes
    py = (tmp_path / "py.csv").read_text().splitlines()
    assert py[1:] == now[1:]
