"""A wrong type for an argument is a TypeError that names the argument and what it takes (issue 35,
item 10): pybind11's own cast failure would be a RuntimeError "Unable to cast ..." naming neither."""
import pytest

import kdl_space
from conftest import ARM, CAPTURE_SCENARIO


@pytest.fixture(scope="module")
def scenario():
    return kdl_space.load_scenario(str(CAPTURE_SCENARIO))


@pytest.fixture(scope="module")
def model():
    return kdl_space.load_urdf(str(ARM))


CALLS = [
    ("duration", lambda s, m: kdl_space.run_operation(s, duration="long")),
    ("output_step", lambda s, m: kdl_space.run_operation(s, output_step=[1])),
    ("control_rate", lambda s, m: kdl_space.run_operation(s, controller=lambda *a: None, control_rate="fast")),
    ("damping_time", lambda s, m: kdl_space.solve_compliant_capture(s, stiffness=[1e6] * 6, damping_time="x")),
    ("catch_tolerance", lambda s, m: kdl_space.solve_compliant_capture(s, stiffness=[1e6] * 6, catch_tolerance={})),
    ("max_duration", lambda s, m: kdl_space.solve_compliant_capture(s, stiffness=[1e6] * 6, max_duration=object())),
    ("preferred['joint1']", lambda s, m: kdl_space.ik(s, ([0.5, 0, 0.5], [0, 0, 0]), preferred={"joint1": "up"})),
    ("preferred", lambda s, m: kdl_space.ik(s, ([0.5, 0, 0.5], [0, 0, 0]), preferred="up")),
    ("weights['impulse']", lambda s, m: kdl_space.plan_capture(s, weights={"impulse": "much"})),
    ("weights", lambda s, m: kdl_space.plan_capture(s, weights=2.0)),
    ("timing", lambda s, m: kdl_space.plan_capture(s, timing="soon")),
    ("q['joint1']", lambda s, m: m.state(q={"joint1": "x"})),
    ("locked", lambda s, m: kdl_space.ForwardDynamicsSolver(m, locked=[1.5, "joint1"])),
]


@pytest.mark.parametrize("argument,call", CALLS, ids=[c[0] for c in CALLS])
def test_a_wrong_type_is_a_type_error_naming_the_argument(scenario, model, argument, call):
    with pytest.raises(TypeError) as e:
        call(scenario, model)
    assert argument in str(e.value), str(e.value)
    assert "expected" in str(e.value), str(e.value)


# One rule (issue 36): every call that takes a scenario takes a loaded Scenario or the path of its
# file, as str or os.PathLike; the same answer either way; a path it cannot read is the loader's
# InputError naming the file, anything else a TypeError.
def test_every_scenario_call_takes_a_scenario_or_its_path(tmp_path):
    import pathlib
    import numpy as np
    import kdl_space
    from conftest import SOURCE_DIR
    path = SOURCE_DIR / "scenarios" / "tumbling_box_capture.yaml"
    loaded = kdl_space.load_scenario(str(path))
    for given in (loaded, str(path), pathlib.Path(path)):
        r = kdl_space.solve_capture(given)
        assert np.array_equal(r.impulse.F, kdl_space.solve_capture(loaded).impulse.F)
        assert kdl_space.attach_target(given, r).nj == loaded.robot.nj
        assert kdl_space.run_operation(given, duration=0.05, approach=False)["capture"]["impulse"] == \
            kdl_space.run_operation(loaded, duration=0.05, approach=False)["capture"]["impulse"]
        assert kdl_space.self_motion(given, 0.1) == kdl_space.self_motion(loaded, 0.1)
        assert kdl_space.Simulator.from_scenario(given).joint_names == loaded.robot.joint_names
        plan = kdl_space.plan_capture(given, scan=3, polish_starts=1)
        assert np.array_equal(plan.q, kdl_space.plan_capture(loaded, scan=3, polish_starts=1).q)
    with pytest.raises(kdl_space.InputError, match="missing.yaml"):
        kdl_space.run_operation(str(tmp_path / "missing.yaml"))
    with pytest.raises(TypeError):
        kdl_space.run_operation(42)
