"""kdl_space.plan_capture: the same plan as `kdl_space plan --json` (one library, deterministic),
inside the URDF's limits (read here with ElementTree), better than the scenario as written, a
weighted sum that is the sum of its terms; the refusals."""
import json
import subprocess

import pytest

import kdl_space
from conftest import CAPTURE_SCENARIO, SOURCE_DIR, ARM
from urdf_numpy import urdf_limits

ARM6 = SOURCE_DIR / "tests" / "data" / "scenarios" / "arm6_reach_capture.json"


def test_the_same_plan_as_the_command(cli):
    plan = kdl_space.plan_capture(str(CAPTURE_SCENARIO), scan=11)
    tool = json.loads(subprocess.run([cli, "plan", str(CAPTURE_SCENARIO), "--scan", "11", "--json"], check=True,
                                     capture_output=True, text=True).stdout)
    assert plan.q_by_name == tool["q_by_name"]
    assert plan.objective == tool["objective"]
    assert plan.nominal_objective == tool["nominal_objective"]
    assert plan.parameters == tool["parameters"]
    assert plan.searched == tool["searched"] == ["self_motion", "wrist_roll"]


def test_the_plan_is_inside_the_limits_and_better_than_the_nominal():
    plan = kdl_space.plan_capture(kdl_space.load_scenario(str(CAPTURE_SCENARIO)), scan=11)
    assert plan.optimum["feasible"]
    assert plan.objective < plan.nominal_objective
    for name, (lower, upper, velocity) in urdf_limits(ARM).items():
        assert lower <= plan.q_by_name[name] <= upper, name
        assert abs(plan.qdot_after[plan.joint_names.index(name)]) <= velocity, name
    assert list(plan.q) == [plan.q_by_name[n] for n in plan.joint_names]


def test_a_weighted_sum_is_the_sum_of_its_terms():
    plan = kdl_space.plan_capture(str(ARM6), weights={"base_rate": 1.0, "impulse": 0.01}, scan=9)
    t = plan.optimum
    assert t["objective"] == pytest.approx(t["base_rate"] + 0.01 * t["impulse"], rel=1e-15)
    assert plan.objective <= plan.nominal_objective
    assert "self_motion" not in plan.parameters  # a six-joint arm has none


def test_refusals():
    with pytest.raises(kdl_space.InputError, match="objective: unknown term 'spin'"):
        kdl_space.plan_capture(str(ARM6), objective="spin")
    with pytest.raises(kdl_space.InputError, match="weight of impulse"):
        kdl_space.plan_capture(str(ARM6), weights={"impulse": 0.0})
    with pytest.raises(kdl_space.InputError, match="nothing to plan"):
        kdl_space.plan_capture(str(ARM6), wrist_roll=(0.0, 0.0))
    with pytest.raises(ValueError, match="wrist_roll"):
        kdl_space.plan_capture(str(ARM6), wrist_roll=(1.0, -1.0))


def test_a_planned_closing_speed_is_the_commands_and_within_the_rate_limits(cli):
    plan = kdl_space.plan_capture(str(CAPTURE_SCENARIO), closing_speed=(0.01, 0.05), scan=5)
    tool = json.loads(subprocess.run([cli, "plan", str(CAPTURE_SCENARIO), "--scan", "5", "--closing-speed", "0.01,0.05",
                                      "--json"], check=True, capture_output=True, text=True).stdout)
    assert plan.searched == tool["searched"] == ["self_motion", "wrist_roll", "closing_speed"]
    assert plan.parameters == tool["parameters"]
    assert list(plan.qdot_before) == tool["qdot_before"]
    assert list(plan.base_twist_before) == tool["base_twist_before"]
    assert 0.01 <= plan.parameters["closing_speed"] <= 0.05
    for name, (_, _, velocity) in urdf_limits(ARM).items():
        assert abs(plan.qdot_before[plan.joint_names.index(name)]) <= velocity, name
    with pytest.raises(kdl_space.InputError, match="closing_speed: must be >= 0"):
        kdl_space.plan_capture(str(ARM6), closing_speed=(-1.0, 0.0))


def test_ctrl_c_ends_plan_capture_within_a_second():
    """A scan of 10^6 points (long): SIGINT stops the search and raises KeyboardInterrupt (issue 35,
    item 6), not when the search ends."""
    import os
    import signal
    import threading
    import time

    sent = []
    timer = threading.Timer(1.0, lambda: (sent.append(time.monotonic()), os.kill(os.getpid(), signal.SIGINT)))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            kdl_space.plan_capture(str(CAPTURE_SCENARIO), scan=1000000)
    finally:
        timer.cancel()
        timer.join()
    assert sent and time.monotonic() - sent[0] < 1.0
