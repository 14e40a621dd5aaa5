"""Studies as engineers state uncertainty (issue 38), from Python and the tool: the target's
principal moments by their own factors, the axes tilted, the tumble's axis in a cone give the same
rows from the tool's table and kdl_space.study (bit for bit); a sampler (a Python callable drawing
some inputs) gives the same table for the same seed, puts its values in the rows, reproduces the
study's own table when it returns the study's own draws, and its mistakes are errors that name the
column and the sample."""
import subprocess

import numpy as np
import pytest

import kdl_space
from conftest import CAPTURE_SCENARIO

SHAPE_STUDY = f"""\
scenario: {CAPTURE_SCENARIO}
samples: 48
seed: 90210
sampling: latin_hypercube
inputs:
  target.inertia.I1: {{uniform: [0.8, 1.2]}}
  target.inertia.I2: {{uniform: [0.8, 1.2]}}
  target.inertia.I3: {{uniform: [0.8, 1.2]}}
  target.inertia.tilt: {{deg: {{uniform: [0, 5]}}}}
  target.tumble: {{deg_per_s: {{uniform: [1, 3]}}}}
  target.tumble_cone: {{deg: {{uniform: [0, 10]}}}}
"""


@pytest.fixture
def shape_study(tmp_path):
    path = tmp_path / "shape.yaml"
    path.write_text(SHAPE_STUDY)
    return path


def test_the_tools_table_and_pythons_rows_are_the_same_bits(shape_study, tmp_path, cli):
    table = tmp_path / "shape.csv"
    subprocess.run([cli, "study", str(shape_study), "-o", str(table), "--threads", "2"], check=True,
                   capture_output=True, text=True)
    from_tool = np.loadtxt(table, delimiter=",", skiprows=2, comments="#")
    result = kdl_space.study(str(shape_study), threads=3)
    assert result.columns[2:2 + 16] == [
        "target.inertia.I1", "target.inertia.I2", "target.inertia.I3", "target.inertia.tilt",
        "target.inertia.tilt.axis_x", "target.inertia.tilt.axis_y", "target.inertia.tilt.axis_z", "target.tumble",
        "target.tumble.axis_x", "target.tumble.axis_y", "target.tumble.axis_z", "target.tumble_cone",
        "target.tumble_cone.axis_x", "target.tumble_cone.axis_y", "target.tumble_cone.axis_z", "impulse.fx"]
    assert np.array_equal(from_tool, result.table)
    assert (result["status"] == 0).all()
    # The draws in the units the file gives, in radians in the table.
    assert result["target.inertia.tilt"].max() <= np.radians(5) and result["target.tumble"].min() >= np.radians(1)


def test_a_sampler_draws_correlated_inputs_and_the_same_seed_gives_the_same_table(shape_study):
    def sampler(rng, i):  # one factor for I1 and I2 (a body whose two small moments move together)
        f = rng.uniform(0.9, 1.1)
        return {"target.inertia.I1": f, "target.inertia.I2": f, "target.tumble": rng.gamma(4.0, 0.01)}

    one = kdl_space.study(str(shape_study), sampler=sampler)
    two = kdl_space.study(kdl_space.load_study(str(shape_study)), sampler=sampler)
    assert np.array_equal(one.table, two.table, equal_nan=True)
    assert np.array_equal(one["target.inertia.I1"], one["target.inertia.I2"])
    for i in (0, 17, 47):  # the sampler's values, from the generator seeded by (seed, i)
        rng = np.random.default_rng([90210, i])
        f = rng.uniform(0.9, 1.1)
        assert one["target.inertia.I1"][i] == f and one["target.tumble"][i] == rng.gamma(4.0, 0.01)
    # The columns it does not give are the study's draws, and its rows differ from the study's.
    plain = kdl_space.study(str(shape_study))
    assert np.array_equal(one["target.inertia.I3"], plain["target.inertia.I3"])
    assert np.array_equal(one["target.tumble_cone.axis_x"], plain["target.tumble_cone.axis_x"])
    assert not np.array_equal(one["base_rate"], plain["base_rate"])
    assert (one["status"] == 0).all()


def test_a_sampler_returning_the_studys_own_draws_gives_the_studys_table(shape_study):
    s = kdl_space.load_study(str(shape_study))
    columns = s.input_columns
    own = kdl_space.study(s, sampler=lambda rng, i: dict(zip(columns, s.draws(i))))
    assert np.array_equal(own.table, kdl_space.study(s).table)


def test_a_sample_the_library_refuses_fails_with_its_own_reason(shape_study):
    def sampler(rng, i):
        return {"target.inertia.I3": -1.0} if i == 5 else {}

    r = kdl_space.study(str(shape_study), sampler=sampler)
    assert r["status"][5] != 0 and np.isnan(r["base_rate"][5])
    assert (np.delete(r["status"], 5) == 0).all()
    (failure,) = r.summary["failures"]
    assert failure["first_sample"] == 5 and failure["count"] == 1
    assert "inertia" in failure["message"], failure["message"]


@pytest.mark.parametrize("sampler, error, words", [
    (lambda rng, i: {"target.inertia.I4": 1.0}, ValueError, "'target.inertia.I4' (sample 0) is no input column"),
    (lambda rng, i: {"target.tumble": float("nan")}, ValueError, "target.tumble = nan (sample 0) is no finite number"),
    (lambda rng, i: {"target.tumble.axis_x": 2.0}, ValueError, "target.tumble's axis (sample 0) is no unit vector"),
    (lambda rng, i: [1.0], TypeError, "expected a dict {input column: value} for sample 0, got list"),
])
def test_a_samplers_mistakes_name_the_column_and_the_sample(shape_study, sampler, error, words):
    with pytest.raises(error, match=None) as e:
        kdl_space.study(str(shape_study), sampler=sampler)
    assert words in str(e.value), str(e.value)


def test_a_sampler_runs_in_this_process_only(shape_study):
    with pytest.raises(ValueError, match="sampler: a callable, with engine='threads'"):
        kdl_space.study(str(shape_study), engine="dask", sampler=lambda rng, i: {})
