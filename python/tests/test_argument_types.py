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
