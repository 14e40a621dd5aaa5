"""Capture studies from Python: Study.rows equals the command-line tool's table bit for bit (the
same rows whatever computes them: threads, a Dask LocalCluster of 2 workers, 3 shards merged);
the result's CSV is the tool's file byte for byte, its .npz round-trips, its summary is the tool's
--json; study_to_table is the tool's run to a table (shards, merge, lock, Ctrl-C and resume); a missing or wrong study file and bad arguments are errors that
name what is wrong (an unusable scheduler: test_study_dask.py)."""
import json
import math
import os
import pathlib
import signal
import subprocess
import threading
import time
import zlib

import numpy as np
import pytest

import kdl_space
from conftest import CAPTURE_SCENARIO, SOURCE_DIR
from kdl_space.study import study_chunk_rows

GRASP_STUDY = SOURCE_DIR / "scenarios" / "study_grasp_configuration.yaml"

SMALL_STUDY = f"""\
scenario: {CAPTURE_SCENARIO}
samples: 60
seed: 4242
inputs:
  target.tumble: {{uniform: [0.02, 0.2]}}
  robot.q.joint2: {{normal: {{mean: 0.7, std: 0.05}}}}
limits:
  joint_rate: 0.05
  base_rate: 0.004
objective: base_rate
"""


def run_cli(cli, *args, cwd):
    return subprocess.run([cli, "study", *map(str, args)], check=True, capture_output=True, text=True, cwd=cwd)


def read_table(path):
    """A table the tool wrote: (first line, columns, rows as float64)."""
    with open(path) as f:
        head, header = f.readline().rstrip("\n"), f.readline().rstrip("\n").split(",")
        rows = [[float(x) for x in line.rstrip("\n").split(",")] for line in f if not line.startswith("# end;")]
    return head, header, np.array(rows, dtype=np.float64).reshape(len(rows), len(header))


def bit_identical(a, b):
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    path = tmp_path_factory.mktemp("study") / "small_study.yaml"
    path.write_text(SMALL_STUDY)
    return path


@pytest.fixture(scope="module")
def small_tool(cli, small):
    """The tool's whole table and --json summary of the small study."""
    out = run_cli(cli, small, "-o", small.parent / "all.csv", "--threads", "2", "--json", cwd=small.parent)
    return small.parent / "all.csv", json.loads(out.stdout)


@pytest.fixture(scope="module")
def grasp_tool(cli, tmp_path_factory):
    d = tmp_path_factory.mktemp("grasp")
    out = run_cli(cli, GRASP_STUDY, "-o", d / "grasp.csv", "--json", cwd=d)
    return d / "grasp.csv", json.loads(out.stdout)


def test_load_study_properties(small):
    s = kdl_space.load_study(str(small))
    assert s.file == str(small) and s.samples == 60 and s.seed == 4242 and not s.latin_hypercube
    assert s.inputs == ["target.tumble", "robot.q.joint2"]
    assert s.columns[:6] == ["sample", "status", "target.tumble", "target.tumble.axis_x", "target.tumble.axis_y",
                             "target.tumble.axis_z"]
    # The rates after the capture added after the columns there were (none renamed or moved).
    limits = s.columns.index("exceeds.joint_rate")
    assert s.columns[limits:limits + 3] == ["exceeds.joint_rate", "exceeds.base_rate", "exceeds.any"]
    assert s.columns[limits + 3:] == [f"qdot.joint{j}" for j in range(1, 8)]
    assert s.distributions["robot.q.joint2"] == {"kind": "normal", "a": 0.7, "b": 0.05}
    assert s.objective == "base_rate" and s.heat_map is None and s.motion_duration == 0.0
    assert isinstance(s.scenario, kdl_space.Scenario) and s.scenario.file == str(CAPTURE_SCENARIO)
    assert 0 <= s.fingerprint < 2**64 and s.default_chunk_size == 16
    assert s.chunks() == [(0, 16), (16, 32), (32, 48), (48, 60)]
    assert s.chunks(25, 10, 55) == [(10, 25), (25, 50), (50, 55)]
    assert repr(s).startswith(f"<kdl_space.Study '{small}' 60 samples, inputs [target.tumble, robot.q.joint2], columns (")
    g = kdl_space.load_study(str(GRASP_STUDY))
    assert not g.latin_hypercube and g.samples == 31 * 13 and g.heat_map == ("robot.self_motion", "robot.q.joint7", "base_rate")
    assert g.distributions["robot.self_motion"] == {"kind": "grid", "a": -1.5, "b": 1.5, "count": 31}


def test_rows_equal_the_tool_table(grasp_tool):
    table, _ = grasp_tool
    head, header, expected = read_table(table)
    s = kdl_space.load_study(str(GRASP_STUDY))
    assert header == s.columns
    assert head == f"# kdl_space study; fingerprint {s.fingerprint:016x}; samples {s.samples}; rows 0-{s.samples}"
    rows = s.rows(0, s.samples, threads=2)
    assert rows.shape == (403, len(s.columns)) and rows.dtype == np.float64
    assert np.all(rows[:, 1] == 0.0) and np.all(rows[:, 0] == np.arange(403))
    assert bit_identical(rows, expected)
    assert bit_identical(s.rows(0, s.samples), rows)                       # 1 thread
    assert bit_identical(s.rows(0, s.samples, threads=0), rows)            # all cores
    assert bit_identical(s.rows(123, 301, threads=2), rows[123:301])      # any range
    assert s.rows(7, 7).shape == (0, len(s.columns))


def test_rows_release_the_gil():
    s = kdl_space.load_study(str(GRASP_STUDY))
    done = threading.Event()
    worker = threading.Thread(target=lambda: (s.rows(0, s.samples, threads=1), done.set()))
    ticks = 0
    worker.start()
    while not done.is_set():
        ticks += 1
        time.sleep(0)
    worker.join()
    assert ticks > 100  # this thread ran while rows() computed


@pytest.mark.filterwarnings("ignore:make_current is deprecated:DeprecationWarning")  # tornado, in distributed
def test_dask_and_shards_give_the_same_rows(cli, small, small_tool):
    from dask.distributed import Client, LocalCluster

    s = kdl_space.load_study(str(small))
    embedded = s.rows(0, s.samples, threads=2)
    _, _, whole = read_table(small_tool[0])
    assert bit_identical(embedded, whole)

    parts = [small.parent / f"part{i}.csv" for i in (1, 2, 3)]
    for i, part in enumerate(parts, 1):
        run_cli(cli, small, "--shard", f"{i}/3", "-o", part, "--threads", "1", cwd=small.parent)
    run_cli(cli, small, "--merge", *parts, "-o", small.parent / "merged.csv", cwd=small.parent)
    _, _, merged = read_table(small.parent / "merged.csv")
    assert bit_identical(merged, embedded)

    # 2 worker processes on loopback: the task loads the study on the worker (PYTHONPATH inherited)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster, Client(cluster) as client:
        r = kdl_space.study(str(small), engine="dask", client=client)
        assert bit_identical(r.table, embedded)
        r7 = kdl_space.study(s, engine="dask", client=client, chunk_size=7)  # 9 tasks
        assert bit_identical(r7.table, embedded)
        assert client.status == "running"  # the user's client is left open
        # a worker whose files differ refuses the task
        with pytest.raises(kdl_space.InputError, match="fingerprint"):
            client.submit(study_chunk_rows, str(small), s.fingerprint ^ 1, 0, 5).result()

    # neither client nor scheduler: a LocalCluster of the call's own
    r = kdl_space.study(small, engine="dask", threads=2)
    assert bit_identical(r.table, embedded)
    assert bit_identical(kdl_space.study(small, threads=2).table, embedded)


def test_to_csv_is_the_tool_table(small, small_tool, grasp_tool, tmp_path):
    for study_file, (table, _) in ((small, small_tool), (GRASP_STUDY, grasp_tool)):
        r = kdl_space.study(str(study_file), threads=2)
        r.to_csv(tmp_path / "mine.csv")
        assert (tmp_path / "mine.csv").read_bytes() == table.read_bytes()
    assert sorted(os.listdir(tmp_path)) == ["mine.csv"]


def test_to_csv_ends_with_the_crc32_the_tool_checks(cli, small, small_tool, tmp_path):
    # The last line: the rows again and the CRC-32 of the row lines' bytes; a table from to_csv
    # merges as a part (the tool reads and checks it), and one with a digit changed is refused.
    r = kdl_space.study(str(small), threads=2)
    r.to_csv(tmp_path / "mine.csv")
    data = (tmp_path / "mine.csv").read_bytes()
    lines = data.split(b"\n")
    assert lines[-1] == b"" and lines[-2] == b"# end; rows 0-60; crc32 %08x" % zlib.crc32(b"".join(l + b"\n" for l in lines[2:-2]))
    run_cli(cli, small, "--merge", tmp_path / "mine.csv", "-o", tmp_path / "merged.csv", cwd=tmp_path)
    assert (tmp_path / "merged.csv").read_bytes() == small_tool[0].read_bytes()
    at = data.index(b",", data.index(b"\n3,") + 4) + 3  # a digit of sample 3's first input
    changed = data[:at] + (b"1" if data[at:at + 1] != b"1" else b"2") + data[at + 1:]
    (tmp_path / "changed.csv").write_bytes(changed)
    with pytest.raises(subprocess.CalledProcessError) as e:
        run_cli(cli, small, "--merge", tmp_path / "changed.csv", "-o", tmp_path / "never.csv", cwd=tmp_path)
    assert e.value.returncode == 3
    assert f"{tmp_path / 'changed.csv'}:63: the rows' checksum is " in e.value.stderr
    assert not (tmp_path / "never.csv").exists()


def test_to_npz_round_trips(small, tmp_path):
    r = kdl_space.study(str(small), threads=2)
    r.to_npz(tmp_path / "t.npz")
    with np.load(tmp_path / "t.npz") as z:
        assert list(z["columns"]) == r.columns
        assert int(z["fingerprint"]) == r.study.fingerprint and int(z["seed"]) == 4242 and int(z["samples"]) == 60
        assert str(z["study"]) == str(small)
        table = np.column_stack([z[name] for name in z["columns"]])
        assert bit_identical(table, r.table)
        for name in r.columns:
            assert bit_identical(z[name], r[name])


def same(actual, expected, where):
    """Equal keys, equal strings and integers, numbers to 1e-12 (relative)."""
    if isinstance(expected, dict):
        assert isinstance(actual, dict) and sorted(actual) == sorted(expected), where
        for k in expected:
            same(actual[k], expected[k], f"{where}.{k}")
    elif isinstance(expected, list):
        assert isinstance(actual, list) and len(actual) == len(expected), where
        for i, (a, e) in enumerate(zip(actual, expected)):
            same(a, e, f"{where}[{i}]")
    elif isinstance(expected, (str, bool)) or expected is None:
        assert actual == expected, where
    elif isinstance(expected, int):
        assert actual == expected and isinstance(actual, int), where
    else:
        assert abs(actual - expected) <= 1e-12 * max(1.0, abs(expected)), f"{where}: {actual} vs {expected}"


def test_summary_is_the_tool_json(small, small_tool, grasp_tool):
    for study_file, (_, expected) in ((small, small_tool), (GRASP_STUDY, grasp_tool)):
        r = kdl_space.study(str(study_file), threads=2)
        expected = dict(expected)
        del expected["table"]  # the tool's file; a result in memory has none
        assert expected.pop("html") is None  # the tool's page of the nominal sample (--html): none asked
        assert r.summary == expected  # the same writer (report::studySummaryJson): equal, not close
        same(r.summary, expected, "summary")
        assert r.summary["samples"] == r.study.samples and r.summary["failed"] == r.failed == 0
        assert r.summary["fingerprint"] == f"{r.study.fingerprint:016x}"
        # the summary of the rows in any order is the same
        shuffled = r.table[np.random.default_rng(1).permutation(len(r))]
        same(r.study.summary(shuffled), r.summary, "shuffled")
    grasp = kdl_space.study(str(GRASP_STUDY), threads=2)
    assert set(grasp.summary["probabilities"]) == {"exceeds.joint_rate", "exceeds.base_rate", "exceeds.any"}
    best = grasp.summary["best"][0]
    assert best["objective"] == grasp["base_rate"].min()
    assert grasp["base_rate"][best["sample"]] == best["objective"]
    assert set(best["inputs"]) == {"robot.self_motion", "robot.q.joint7"}
    assert repr(grasp) == f"<kdl_space.StudyResult '{GRASP_STUDY}' 403 samples (0 failed), table (403, {len(grasp.columns)})>"


def test_a_failure_keeps_its_message(tmp_path):
    # joint3 drawn beyond its hard stop (2.96706 rad): the motion's set-up refuses to start it, so
    # the status column says E_BAD_ARGUMENT, the summary why. (A normal target mass, which could
    # draw <= 0, is refused when the study loads.)
    scenario = tmp_path / "stops.yaml"
    text = pathlib.Path(CAPTURE_SCENARIO).read_text().replace("../urdf/", f"{SOURCE_DIR}/urdf/")
    scenario.write_text(text.replace("  atol:", "  limits: stop\n  atol:"))
    path = tmp_path / "failing.yaml"
    path.write_text(f"scenario: {scenario}\nsamples: 30\nseed: 5\n"
                    "inputs: {robot.q.joint3: {normal: {mean: 2.9, std: 0.1}}}\nmotion: {duration: 0.05}\n")
    with pytest.raises(kdl_space.InputError, match="target.mass: takes values > 0"):
        bad = tmp_path / "mass.yaml"
        bad.write_text(f"scenario: {CAPTURE_SCENARIO}\nsamples: 30\nseed: 5\n"
                       "inputs: {target.mass: {normal: {mean: 10, std: 20}}}\n")
        kdl_space.load_study(str(bad))
    r = kdl_space.study(str(path), threads=2)
    status = r["status"]
    failed = np.flatnonzero(status != 0)
    assert len(failed) > 0 and np.all(status[failed] == kdl_space.E_BAD_ARGUMENT)
    q = r["robot.q.joint3"]
    assert np.array_equal(failed, np.flatnonzero(np.abs(q) > 2.96706))
    first = f"{q[failed[0]]:.6g}"
    assert r.summary["failures"] == [{"status": kdl_space.E_BAD_ARGUMENT, "count": len(failed),
                                      "first_sample": int(failed[0]),
                                      "message": f"{scenario}: simulation.limits: joint 'joint3' starts at {first}, "
                                                 "outside its limits [-2.96706, 2.96706] (a hard stop keeps it inside "
                                                 "them): start it inside, or let its limits warn"}]
    # rows in any order: the same first sample and message
    assert r.study.summary(r.table[::-1])["failures"] == r.summary["failures"]


def test_bad_inputs(small, tmp_path):
    missing = tmp_path / "nope.yaml"
    with pytest.raises(kdl_space.InputError, match="nope.yaml"):
        kdl_space.load_study(str(missing))
    with pytest.raises(kdl_space.InputError, match="nope.yaml"):
        kdl_space.study(missing)
    bad = tmp_path / "bad.yaml"
    bad.write_text(SMALL_STUDY + "colour: blue\n")
    with pytest.raises(kdl_space.InputError, match="colour"):
        kdl_space.load_study(str(bad))
    bad.write_text(SMALL_STUDY.replace("target.tumble:", "target.spin:"))
    with pytest.raises(kdl_space.InputError, match="target.spin"):
        kdl_space.load_study(str(bad))

    s = kdl_space.load_study(str(small))
    with pytest.raises(ValueError, match="begin"):
        s.rows(10, 5)
    with pytest.raises(ValueError, match="end"):
        s.rows(0, 61)
    with pytest.raises(ValueError, match="begin"):
        s.rows(-1, 5)
    with pytest.raises(ValueError, match="threads"):
        s.rows(0, 5, threads=-2)
    with pytest.raises(ValueError, match=r"rows: expected shape \(n, %d\)" % len(s.columns)):
        s.summary(np.zeros((3, 4)))
    with pytest.raises(ValueError, match="engine"):
        kdl_space.study(s, engine="mpi")
    with pytest.raises(ValueError, match="threads"):
        kdl_space.study(s, threads=-1)
    with pytest.raises(ValueError, match="chunk_size"):
        kdl_space.study(s, engine="dask", chunk_size=0)
    with pytest.raises(ValueError, match="only for engine='dask'"):
        kdl_space.study(s, scheduler="tcp://127.0.0.1:8786")
    with pytest.raises(TypeError, match="study"):
        kdl_space.study(42)
    r = kdl_space.StudyResult(s, s.rows(0, 3))
    with pytest.raises(KeyError, match="no column"):
        r["impulse"]
    assert len(r) == 3 and bit_identical(r["sample"], np.arange(3.0))


def test_rows_answer_ctrl_c_within_half_a_second(tmp_path):
    # Each sample a capture and half a second of motion (about 6 ms); 512,000 samples: chunks of
    # 2,000 (about 13 s each on one thread); rows 0..4,000 would take about half a minute. SIGINT
    # to this process after 0.3 s: KeyboardInterrupt within 0.5 s.
    path = tmp_path / "long_study.yaml"
    path.write_text(SMALL_STUDY.replace("samples: 60", "samples: 512000") + "motion: {duration: 0.5}\n")
    s = kdl_space.load_study(str(path))
    assert s.default_chunk_size == 2000
    sent = []

    def interrupt():
        sent.append(time.monotonic())
        signal.pthread_kill(threading.main_thread().ident, signal.SIGINT)

    timer = threading.Timer(0.3, interrupt)
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            s.rows(0, 4000, threads=1)
        answered = time.monotonic()
    finally:
        timer.cancel()
        timer.join()
    assert sent and sent[0] - start >= 0.29, "the signal came while rows() ran"
    latency = answered - sent[0]
    print(f"rows() answered SIGINT in {latency * 1e3:.0f} ms")
    assert latency < 0.5
    # the study runs again afterwards (no thread or state left behind)
    assert s.rows(0, 3).shape == (3, len(s.columns))


def test_summary_states_its_quantile_rank_error(small):
    s = kdl_space.load_study(str(small))
    rows = s.rows(0, 60, threads=2)
    assert s.summary(rows)["quantile_rank_error"] == 0.0  # 60 samples: exact
    # 70,000 rows made up from these (the summary takes any rows of the study): past the sketch's
    # first buffer of 65,536, the error of the quantiles' ranks is bounded and stated.
    big = np.tile(rows, (1167, 1))[:70000].copy()
    big[:, 0] = np.arange(70000)
    rng = np.random.default_rng(3)
    rate = s.columns.index("base_rate")
    big[:, rate] = rng.exponential(1.0, 70000)
    summary = s.summary(big)
    e = summary["quantile_rank_error"]
    assert 0.0 < e <= 1 / 65536 + math.floor(math.log2(70000 / 16384)) / 16384
    ordered = np.sort(big[:, rate])
    n = len(ordered)
    for key, p in (("q05", 0.05), ("median", 0.5), ("q95", 0.95)):
        r, slack = math.floor(p * (n - 1)), math.ceil(e * n)
        assert ordered[r - slack] <= summary["outcomes"]["base_rate"][key] <= ordered[min(n - 1, r + 1 + slack)], key
    assert summary["outcomes"]["base_rate"]["min"] == ordered[0] and summary["outcomes"]["base_rate"]["max"] == ordered[-1]
    # the mean: the exact sum rounded once (math.fsum is correctly rounded too), over n
    assert summary["outcomes"]["base_rate"]["mean"] == math.fsum(ordered) / n


def test_study_to_table_is_the_tool_run(small, small_tool, tmp_path):
    # The library's runStudyToTable, as `kdl_space study -o` runs it: the same bytes, the same summary
    table, expected = small_tool
    for given in (small, str(small), kdl_space.load_study(str(small))):  # a path or a loaded Study
        out = tmp_path / "mine.csv"
        done = kdl_space.study_to_table(given, out, threads=2)
        assert out.read_bytes() == table.read_bytes()
        summary = dict(expected)
        assert summary.pop("html") is None
        summary["table"] = str(out)
        assert done["summary"] == summary
        assert (done["table"], done["begin"], done["end"], done["computed"], done["resumed"]) == (str(out), 0, 60, 60, 0)
        assert done["threads"] == 2 and done["how"].startswith("60 computed on 2 threads in ")
        out.unlink()
    assert sorted(os.listdir(tmp_path)) == []  # no chunks, lock or temporary left


def test_study_to_table_shards_merge_into_the_whole_table(small, small_tool, tmp_path):
    parts = []
    for i in (1, 2, 3):
        part = tmp_path / f"part{i}.csv"
        done = kdl_space.study_to_table(small, part, shard=(i, 3), chunk_size=7)
        assert done["summary"] is None and (done["begin"], done["end"]) == ((i - 1) * 20, i * 20)
        parts.append(part)
    merged = kdl_space.study_to_table(small, tmp_path / "merged.csv", merge=parts[::-1])
    assert (tmp_path / "merged.csv").read_bytes() == small_tool[0].read_bytes()
    assert merged["how"] == "3 parts merged" and merged["computed"] == 0
    assert merged["summary"]["samples"] == 60
    # a missing shard, a shard out of range, shard and merge together, an output on an input
    with pytest.raises(kdl_space.InputError, match="rows 40-60 are in no part"):
        kdl_space.study_to_table(small, tmp_path / "never.csv", merge=parts[:2])
    with pytest.raises(ValueError, match="shard 4/3"):
        kdl_space.study_to_table(small, tmp_path / "never.csv", shard=(4, 3))
    with pytest.raises(ValueError, match="61 shards of 60 samples"):
        kdl_space.study_to_table(small, tmp_path / "never.csv", shard=(1, 61))
    with pytest.raises(ValueError, match="shard and merge"):
        kdl_space.study_to_table(small, tmp_path / "never.csv", shard=(1, 3), merge=parts)
    with pytest.raises(TypeError, match="merge"):
        kdl_space.study_to_table(small, tmp_path / "never.csv", merge=parts[0])
    before = small.read_bytes()
    with pytest.raises(ValueError, match="the study file"):
        kdl_space.study_to_table(small, small)
    with pytest.raises(ValueError, match="the study file"):
        kdl_space.study(small).to_csv(small)
    assert small.read_bytes() == before
    assert not (tmp_path / "never.csv").exists()


def test_study_to_table_takes_a_stale_lock_with_a_warning_and_refuses_a_live_one(small, small_tool, tmp_path):
    table = tmp_path / "t.csv"
    lock = tmp_path / "t.csv.lock"
    dead = subprocess.Popen(["true"])
    dead.wait()
    lock.write_text(f"pid {dead.pid}\nhost {os.uname().nodename}\nsince 2026-11-26T10:00:00Z\n")
    with pytest.warns(UserWarning, match="removed a stale lock"):
        kdl_space.study_to_table(small, table)
    assert table.read_bytes() == small_tool[0].read_bytes() and not lock.exists()
    lock.write_text(f"pid {os.getpid()}\nhost {os.uname().nodename}\nsince 2026-11-26T10:00:00Z\n")
    with pytest.raises(kdl_space.InputError, match="is being written by kdl_space"):
        kdl_space.study_to_table(small, tmp_path / "t.csv")
    assert lock.exists()


def test_study_to_table_answers_ctrl_c_and_the_same_call_resumes(tmp_path):
    # 600 samples of a capture and 0.5 s of motion (about 6 ms each) in chunks of 20 on two
    # threads: about 2 s. SIGINT after 0.5 s: KeyboardInterrupt saying what is kept; the chunks
    # stay; the same call computes only the rest, and the table is the uninterrupted run's.
    path = tmp_path / "long_study.yaml"
    path.write_text(SMALL_STUDY.replace("samples: 60", "samples: 600") + "motion: {duration: 0.5}\n")
    table = tmp_path / "t.csv"
    timer = threading.Timer(0.5, lambda: signal.pthread_kill(threading.main_thread().ident, signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt, match="chunks kept in"):
            kdl_space.study_to_table(path, table, threads=2, chunk_size=20)
    finally:
        timer.cancel()
        timer.join()
    kept = sorted(os.listdir(str(table) + ".parts"))
    assert kept and not table.exists() and not (tmp_path / "t.csv.lock").exists()
    done = kdl_space.study_to_table(path, table, threads=2, chunk_size=20)
    assert done["resumed"] == 20 * len(kept) and done["computed"] == 600 - done["resumed"]
    whole = kdl_space.study(path, threads=2)
    whole.to_csv(tmp_path / "whole.csv")
    assert table.read_bytes() == (tmp_path / "whole.csv").read_bytes()
    assert not os.path.exists(str(table) + ".parts")
