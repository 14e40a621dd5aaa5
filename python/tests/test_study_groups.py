"""A study's answers per grid point (issue 26, item 4): the per-grid-point aggregates in the tool's
JSON, its --groups CSV, Python's summary and StudyResult.grid_points equal a NumPy group-by of the
raw table; the heat map's data has one value a cell; the objective with a statistic ranks grid
points; the q.JOINT columns are kdl_space.self_motion's angles; the qdot.JOINT columns are the
rates after the capture and exceeds.joint_rate tests them."""
import json
import subprocess

import numpy as np
import pytest

import kdl_space
from conftest import CAPTURE_SCENARIO

GRID_STUDY = f"""\
scenario: {CAPTURE_SCENARIO}
samples: 48
seed: 77
inputs:
  robot.self_motion: {{grid: [-0.5, 0.5, 3]}}
  robot.q.joint7: {{grid: [-0.3, 0.3, 2]}}
  target.tumble: {{uniform: [0.02, 0.22]}}
limits:
  joint_rate: 0.06
  base_rate: 0.0015
objective: {{outcome: base_rate, statistic: q95}}
heat_map: {{x: robot.self_motion, y: robot.q.joint7, outcome: base_rate}}
"""


def read_csv(path):
    """A CSV with a header line (comment lines skipped): (names, float64 rows)."""
    with open(path) as f:
        lines = [line.rstrip("\n") for line in f if not line.startswith("#")]
    names = lines[0].split(",")
    return names, np.array([[float(x) for x in line.split(",")] for line in lines[1:]], dtype=np.float64)


def ulps(v):
    """Two ulps of the largest magnitude in v: how far two roundings of a lerp between its values differ."""
    return 2 * np.spacing(np.abs(v).max()) + 1e-300


def group_by(names, table):
    """The aggregates by hand: {(self_motion, joint7): {"count", column: values}} of the computed rows."""
    sm, q7 = names.index("robot.self_motion"), names.index("robot.q.joint7")
    groups = {}
    for row in table:
        groups.setdefault((row[sm], row[q7]), []).append(row)
    return {k: np.array(v) for k, v in groups.items()}


@pytest.fixture(scope="module")
def grid_tool(cli, tmp_path_factory):
    d = tmp_path_factory.mktemp("groups")
    path = d / "grid.yaml"
    path.write_text(GRID_STUDY)
    out = subprocess.run([cli, "study", str(path), "-o", str(d / "grid.csv"), "--groups", str(d / "groups.csv"),
                          "--heat-map", str(d / "map.csv"), "--json"], check=True, capture_output=True, text=True, cwd=d)
    return path, d, json.loads(out.stdout)


def outcome_names(names):
    first = names.index("impulse.fx")
    return [n for n in names[first:] if not n.startswith("exceeds.")], [n for n in names if n.startswith("exceeds.")]


def test_grid_point_aggregates_equal_a_numpy_group_by(grid_tool):
    path, d, summary = grid_tool
    names, table = read_csv(d / "grid.csv")
    assert (table[:, 1] == 0).all()
    groups = group_by(names, table)
    assert len(groups) == 6 and summary["grid_inputs"] == ["robot.self_motion", "robot.q.joint7"]
    outcomes, limits = outcome_names(names)
    assert "q.joint1" in outcomes and "qdot.joint7" in outcomes
    result = kdl_space.StudyResult(kdl_space.load_study(str(path)), table)
    for points in (summary["grid_points"], result.grid_points, result.summary["grid_points"]):
        assert len(points) == 6
        for p in points:
            rows = groups[(p["inputs"]["robot.self_motion"], p["inputs"]["robot.q.joint7"])]
            assert p["count"] == len(rows) == 8 and p["failed"] == 0
            for name in outcomes:
                v = rows[:, names.index(name)]
                got = p["outcomes"][name]
                assert got["mean"] == pytest.approx(v.mean(), rel=1e-14, abs=1e-300), name
                # Linear between order statistics, as the summary (exact here); NumPy's lerp rounds
                # otherwise: to an ulp of the two values it interpolates.
                assert got["q95"] == pytest.approx(np.quantile(v, 0.95), rel=0, abs=ulps(v)), name
                assert got["max"] == v.max(), name
            for name in limits:
                assert p["probabilities"][name] == rows[:, names.index(name)].mean(), name
    assert any(p["probabilities"]["exceeds.any"] > 0 for p in summary["grid_points"])
    # The groups' CSV: one row a point, the same numbers.
    gnames, g = read_csv(d / "groups.csv")
    assert gnames[:4] == ["robot.self_motion", "robot.q.joint7", "count", "failed"]
    assert gnames[-1] == "P(exceeds.any)" and "base_rate.q95" in gnames
    assert g.shape == (6, len(gnames))
    for row in g:
        rows = groups[(row[0], row[1])]
        assert row[2] == 8
        for name in outcomes:
            v = rows[:, names.index(name)]
            assert row[gnames.index(name + ".max")] == v.max()
            assert row[gnames.index(name + ".q95")] == pytest.approx(np.quantile(v, 0.95), rel=0, abs=ulps(v))


def test_heat_map_has_one_value_a_cell(grid_tool):
    _, d, summary = grid_tool
    names, table = read_csv(d / "grid.csv")
    mnames, cells = read_csv(d / "map.csv")
    assert mnames == ["robot.self_motion", "robot.q.joint7", "base_rate.mean"]
    assert cells.shape == (6, 3) and len({(x, y) for x, y, _ in cells}) == 6  # 48 samples, 6 cells
    groups = group_by(names, table)
    for x, y, v in cells:
        assert v == pytest.approx(groups[(x, y)][:, names.index("base_rate")].mean(), rel=1e-14)


def test_objective_statistic_ranks_grid_points(grid_tool):
    path, d, summary = grid_tool
    names, table = read_csv(d / "grid.csv")
    groups = group_by(names, table)
    by_q95 = sorted(groups, key=lambda k: np.quantile(groups[k][:, names.index("base_rate")], 0.95))
    q95s = sorted(np.quantile(v[:, names.index("base_rate")], 0.95) for v in groups.values())
    assert all(b - a > 1e-12 * b for a, b in zip(q95s, q95s[1:])), "no near ties: the order is NumPy's too"
    assert summary["objective"] == "base_rate" and summary["objective_statistic"] == "q95"
    best = [(p["inputs"]["robot.self_motion"], p["inputs"]["robot.q.joint7"]) for p in summary["best_grid_points"]]
    assert best == by_q95[:5]
    assert summary["worst_grid_points"][0]["objective"] == pytest.approx(q95s[-1], rel=1e-15)
    s = kdl_space.load_study(str(path))
    assert s.objective_statistic == "q95" and s.heat_map_statistic == "mean"
    assert kdl_space.StudyResult(s, table).summary["best_grid_points"] == summary["best_grid_points"]


def test_self_motion_columns_are_the_self_motion_call(grid_tool):
    _, d, _ = grid_tool
    scenario = kdl_space.load_scenario(str(CAPTURE_SCENARIO))
    # Without the wrist input, the columns are the call's angles exactly.
    plain = d / "plain.yaml"
    plain.write_text(f"scenario: {CAPTURE_SCENARIO}\nseed: 1\ninputs:\n  robot.self_motion: {{grid: [-0.6, 0.6, 4]}}\n")
    r = kdl_space.study(str(plain))
    moved = False
    for k in range(len(r)):
        q = kdl_space.self_motion(scenario, float(r["robot.self_motion"][k]))
        for j, angle in q.items():
            assert r["q." + j][k] == angle, j
        moved |= abs(q["joint1"] - kdl_space.self_motion(scenario, 0.0)["joint1"]) > 0.01
    assert moved
    # An arm with no one-parameter self-motion (6 joints to the hand): refused, saying why.
    with pytest.raises(kdl_space.InputError, match="robot.self_motion: the arm has 6 joints"):
        kdl_space.self_motion(kdl_space.load_scenario(str(CAPTURE_SCENARIO).replace(
            "tumbling_box_capture", "dual_arm_captures_robot")), 0.1)


def test_exceeds_joint_rate_tests_the_rate_columns(grid_tool):
    _, d, _ = grid_tool
    names, table = read_csv(d / "grid.csv")
    rates = np.stack([table[:, i] for i, n in enumerate(names) if n.startswith("qdot.")], axis=1)
    assert rates.shape[1] == 7
    exceeded = (np.abs(rates) > 0.06).any(axis=1)
    assert (table[:, names.index("exceeds.joint_rate")] == exceeded).all()
    assert 0 < exceeded.sum() < len(table)
