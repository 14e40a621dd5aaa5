"""Capture-study throughput, side by side in one run: the embedded engine (Study.rows, C++ threads)
on 1 and 2 threads, and Dask with a 2-worker LocalCluster (worker processes on loopback, one
thread each), for one study; and the Dask overhead per chunk.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/study_throughput.py
    PYTHONPATH=build/python /usr/bin/python3 benchmarks/study_throughput.py --samples 20000 --chunk-size 250

--samples N runs the study with N samples instead of its own count (a copy of the study file in a
temporary folder, its scenario by absolute path: the same inputs, seed and outcomes; sample i is
the same row as in the original). Each rate is the best of --repeat runs (the machine is shared).

Dask overhead per chunk, two ways:
  * derived from the full run: the worker-seconds the Dask run took beyond the computing itself,
    per chunk: (workers x T_dask - T_embedded_1_thread) / chunks. The embedded 1-thread time is
    the compute a chunk's share needs (T_1 x chunk / samples), so this is what each chunk costs
    on top of it (scheduling, pickling the rows, the transfer, gathering), assuming the workers
    are as busy as they can be. It is noisy when the chunks are large (a small difference of
    large times).
  * measured with empty-ish chunks: --overhead-tasks tasks of one sample each, through the same
    client: (workers x T - tasks x t_sample) / tasks, with t_sample from the embedded 1-thread
    run. This is the floor of a chunk's cost whatever its size.
The Dask runs are warm: a first run (not timed) loads the study on each worker (each worker keeps
the studies it has loaded by path and fingerprint), as on a cluster that runs a study repeatedly.
The first, cold run's time is printed too.
"""

import argparse
import os
import pathlib
import sys
import tempfile
import time

import numpy as np
import yaml

import kdl_space
from kdl_space.study import study_chunk_rows

ROOT = pathlib.Path(__file__).resolve().parents[1]


def study_with_samples(path, samples, folder):
    """A copy of the study with `samples` samples, its scenario by absolute path."""
    with open(path) as f:
        doc = yaml.safe_load(f)
    scenario = pathlib.Path(doc["scenario"])
    if not scenario.is_absolute():
        doc["scenario"] = str((pathlib.Path(path).resolve().parent / scenario).resolve())
    doc["samples"] = samples
    out = pathlib.Path(folder) / (pathlib.Path(path).stem + f"_{samples}.yaml")
    with open(out, "w") as f:
        yaml.safe_dump(doc, f, sort_keys=False)
    return str(out)


def best_of(repeat, f):
    times, result = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = f()
        times.append(time.perf_counter() - t0)
    return min(times), result


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--study", default=str(ROOT / "scenarios" / "study_grasp_configuration.yaml"))
    p.add_argument("--samples", type=int, default=4000, help="samples (default 4000; 0: the study's own)")
    p.add_argument("--chunk-size", type=int, default=0, help="samples per Dask task (0: the study's default)")
    p.add_argument("--repeat", type=int, default=3, help="runs of each, the best kept")
    p.add_argument("--overhead-tasks", type=int, default=200, help="one-sample tasks for the overhead floor")
    p.add_argument("--inproc", action="store_true", help="Dask workers as threads of this process, not processes")
    a = p.parse_args()

    from dask.distributed import Client, LocalCluster

    with tempfile.TemporaryDirectory() as folder:
        path = study_with_samples(a.study, a.samples, folder) if a.samples else os.path.abspath(a.study)
        s = kdl_space.load_study(path)
        n = s.samples
        chunk = a.chunk_size or s.default_chunk_size
        chunks = len(s.chunks(chunk))
        print(f"study {a.study}: {n} samples, {len(s.columns)} columns, inputs {', '.join(s.inputs)}")
        print(f"machine: {os.cpu_count()} cores; python {sys.version.split()[0]}; best of {a.repeat}\n")

        t1, rows1 = best_of(a.repeat, lambda: s.rows(0, n, threads=1))
        t2, rows2 = best_of(a.repeat, lambda: s.rows(0, n, threads=2))
        assert rows1.tobytes() == rows2.tobytes()
        t_sample = t1 / n

        workers = 2
        t0 = time.perf_counter()
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=not a.inproc, host="127.0.0.1",
                          dashboard_address=None) as cluster, Client(cluster) as client:
            t_start = time.perf_counter() - t0
            t0 = time.perf_counter()
            cold = kdl_space.study(s, engine="dask", client=client, chunk_size=chunk)
            t_cold = time.perf_counter() - t0
            td, warm = best_of(a.repeat, lambda: kdl_space.study(s, engine="dask", client=client, chunk_size=chunk))
            assert cold.table.tobytes() == rows1.tobytes() and warm.table.tobytes() == rows1.tobytes()

            m = min(a.overhead_tasks, n)
            path_abs = os.path.abspath(s.file)

            def one_sample_tasks():
                futures = client.map(study_chunk_rows, [path_abs] * m, [s.fingerprint] * m, list(range(m)),
                                     list(range(1, m + 1)), pure=False)
                return np.concatenate(client.gather(futures))

            to, rows_o = best_of(a.repeat, one_sample_tasks)
            assert rows_o.tobytes() == rows1[:m].tobytes()

        derived = (workers * td - t1) / chunks
        floor = (workers * to - m * t_sample) / m
        mode = "threads of this process" if a.inproc else "processes, tcp on 127.0.0.1"
        print(f"{'engine':44s}{'time [s]':>10s}{'captures/s':>14s}{'per core':>12s}")
        for name, t, cores in ((f"embedded, 1 thread", t1, 1), (f"embedded, 2 threads", t2, 2),
                               (f"dask, 2 workers ({chunks} chunks of {chunk})", td, 2)):
            print(f"{name:44s}{t:10.3f}{n / t:14.0f}{n / t / cores:12.0f}")
        print(f"\nper capture (embedded, 1 thread): {t_sample * 1e6:.1f} us; scaling on 2 threads: {t1 / t2:.2f}x; "
              f"dask vs embedded 2 threads: {td / t2:.2f}x the time")
        print(f"dask workers: {mode}; cluster start {t_start:.2f} s; first (cold) run {t_cold:.3f} s "
              f"(loads the study on each worker)")
        print(f"dask overhead per chunk, derived from the run: (2 x {td:.3f} - {t1:.3f}) / {chunks} = "
              f"{derived * 1e3:.2f} ms")
        print(f"dask overhead per chunk, measured with {m} one-sample tasks: {to:.3f} s, "
              f"(2 x {to:.3f} - {m} x {t_sample * 1e6:.1f} us) / {m} = {floor * 1e3:.2f} ms")


if __name__ == "__main__":
    main()
