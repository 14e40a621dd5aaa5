"""solve_capture against the command-line tool's JSON for the same scenario (the same library
through another front end: equal to 1e-12)."""
import json
import subprocess

import numpy as np

import kdl_space
from conftest import CAPTURE_SCENARIO


def same(actual, expected, what):
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, what
    scale = max(1.0, float(np.max(np.abs(expected))))
    assert np.max(np.abs(actual - expected), initial=0.0) <= 1e-12 * scale, f"{what}: {actual} vs {expected}"


def test_capture_matches_the_tool(cli, source_dir):
    out = subprocess.run([cli, "capture", str(CAPTURE_SCENARIO), "--json"], check=True, capture_output=True,
                         text=True, cwd=source_dir)
    j = json.loads(out.stdout)
    r = kdl_space.solve_capture(kdl_space.load_scenario(str(CAPTURE_SCENARIO)))
    same(r.impulse.F, j["impulse"], "impulse")
    assert r.robot.joint_names == j["robot"]["joint_names"]
    for key in ("base_twist_before", "base_twist_after", "qdot_before", "qdot_after", "contact_twist_before",
                "contact_twist_after"):
        same(getattr(r.robot, key), j["robot"][key], key)
    same(r.target_twist_before, j["target"]["twist_before"], "target twist before")
    same(r.target_twist_after, j["target"]["twist_after"], "target twist after")
    same(r.momentum_before, j["momentum_before"], "momentum_before")
    same(r.momentum_after, j["momentum_after"], "momentum_after")
    same(r.energy_before, j["energy_before"], "energy_before")
    same(r.energy_after, j["energy_after"], "energy_after")
    same(r.energy_lost, j["energy_lost"], "energy_lost")
    same(r.G_robot, j["G_star"], "G_robot")
    same(r.G_target, j["G_B"], "G_target")
    assert (r.virtual_mass is None) == (j["virtual_mass"] is None)
    if r.virtual_mass is not None:
        same(r.virtual_mass, j["virtual_mass"], "virtual_mass")
    assert r.floating_target is None


def test_scenario_problem_is_the_scenario(source_dir):
    scenario = kdl_space.load_scenario(str(CAPTURE_SCENARIO))
    assert scenario.impact and scenario.robot_urdf.endswith("space_arm7.urdf") and scenario.target_urdf == ""
    assert scenario.problem.law.kind == "capture"
    a = kdl_space.solve_capture(scenario)
    b = kdl_space.solve_capture(scenario.problem)
    assert np.array_equal(a.impulse.F, b.impulse.F)
