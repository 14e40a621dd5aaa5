"""Capture studies from Python: ``kdl_space.study(...)`` runs a study file's samples on this
machine's threads (the C++ engine, as ``kdl_space study``) or as Dask tasks on a cluster, and
returns a :class:`StudyResult` (the table as a NumPy array, its summary, CSV and ``.npz`` output).

Sample i depends only on (seed, i): the rows are bit-identical whatever engine, threads, workers or
chunks computed them, and equal to the command-line tool's table (its ``--shard`` parts merged too).

Dask: each task is one chunk of samples (the study's grid of chunks, as the command-line tool cuts
them). A task loads the study **from its path on the worker** and computes its rows there, so the
workers must see the same files at the same absolute path (the study, its scenario, the URDFs: a
cluster's shared file system, or the same checkout on every machine); a worker whose files differ
(another fingerprint) fails the task with InputError rather than compute another study's rows.
"""

import math
import os
import threading

import numpy as np

from ._kdl_space import InputError, Study, load_study

__all__ = ["study", "study_to_table", "StudyResult"]

_ENGINES = ("threads", "dask")


def _resolve(study_or_path):
    if isinstance(study_or_path, Study):
        return study_or_path
    if isinstance(study_or_path, (str, os.PathLike)):
        return load_study(os.fspath(study_or_path))
    raise TypeError(f"study: expected a path or a kdl_space.Study, got {type(study_or_path).__name__}")


# A worker's studies, by (path, fingerprint): loaded once per worker process, not once per task.
_worker_studies = {}
_worker_lock = threading.Lock()


def _worker_study(path, fingerprint):
    key = (path, fingerprint)
    with _worker_lock:
        found = _worker_studies.get(key)
    if found is not None:
        return found
    loaded = load_study(path)
    if loaded.fingerprint != fingerprint:
        raise InputError(f"{path}: the worker's study files differ from the client's (fingerprint "
                         f"{loaded.fingerprint:016x}, the client's {fingerprint:016x}): the workers need the same "
                         "files at the same path")
    with _worker_lock:
        if len(_worker_studies) >= 8:
            _worker_studies.clear()
        _worker_studies[key] = loaded
    return loaded


def study_chunk_rows(path, fingerprint, begin, end):
    """A Dask task: rows [begin, end) of the study at `path` (on the worker), which must have
    `fingerprint`; (end - begin, columns) float64. Module-level so that it pickles by name."""
    return _worker_study(path, fingerprint).rows(begin, end, threads=1)


def _count(value, name, low):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
        raise ValueError(f"{name}: expected a whole number >= {low}, got {value!r}")
    return int(value)


def _probe(scheduler, timeout):
    """What answers at `scheduler` (a tcp:// or tls:// address), found within `timeout` seconds
    without creating a Client (a Client that fails to start hangs the interpreter's exit for
    seconds): None if a Dask scheduler, else why not, as a sentence."""
    import asyncio
    import socket
    import time
    from distributed.comm import connect
    from distributed.comm.addressing import parse_address, parse_host_port
    try:
        scheme, location = parse_address(scheduler, strict=True)
        host, port = parse_host_port(location)
    except (ValueError, TypeError) as e:
        return f"is no scheduler address ({e}): expected tcp://HOST:PORT, e.g. tcp://10.0.0.5:8786"
    if scheme not in ("tcp", "tls"):
        return None  # inproc://, ucx://...: the Client tells
    start = time.monotonic()
    try:
        socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except socket.gaierror as e:
        return f"cannot resolve the host {host!r} ({e.strerror}): check the name"
    try:
        socket.create_connection((host, port), timeout=timeout).close()
    except ConnectionRefusedError:
        return (f"the connection was refused: nothing listens at {host}:{port} (start the scheduler, "
                "`dask scheduler`, or check the port: 8786 by default)")
    except socket.timeout:
        return f"no answer within {timeout:g} s (a firewall, or the wrong host?)"
    except OSError as e:
        return f"cannot connect ({e.strerror or e})"
    left = max(timeout - (time.monotonic() - start), 0.1)

    async def handshake():
        comm = await connect(scheduler, timeout=left)
        try:
            await comm.write({"op": "identity"})
            return await asyncio.wait_for(comm.read(), left)
        finally:
            comm.abort()

    t0 = time.monotonic()
    try:
        reply = asyncio.run(handshake())
    except (OSError, asyncio.TimeoutError, EOFError, ValueError, TypeError) as e:
        took = time.monotonic() - t0
        if took < 0.9 * left:  # it answered, and not as Dask does
            return (f"something answers at {host}:{port}, but not a Dask scheduler (the handshake failed "
                    f"after {took:.1f} s: {type(e).__name__}): check the address and port")
        return f"the connection opened, but no Dask handshake within {timeout:g} s (a busy or hung scheduler?)"
    except Exception as e:  # a reply that does not even decode: garbage
        return (f"something answers at {host}:{port}, but not a Dask scheduler ({type(e).__name__}: {e}): "
                "check the address and port")
    if not (isinstance(reply, dict) and reply.get("type") == "Scheduler"):
        what = reply.get("type") if isinstance(reply, dict) else type(reply).__name__
        return f"a Dask {what}, not a scheduler, answers there: give the scheduler's address"
    return None


def _connect(scheduler, timeout):
    from dask.distributed import Client
    why = _probe(scheduler, timeout)
    if why is not None:
        raise InputError(f"scheduler {scheduler}: {why}")
    try:
        return Client(scheduler, timeout=timeout, set_as_default=False)
    except (OSError, TimeoutError) as e:  # asyncio/ distributed timeouts are OSError or TimeoutError
        raise InputError(f"scheduler {scheduler}: cannot connect within {timeout:g} s ({type(e).__name__}: {e})") from None


def _run_dask(s, client, scheduler, threads, chunk_size, timeout):
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError as e:  # pragma: no cover - the Debian package python3-distributed
        raise ImportError("engine='dask' needs dask.distributed (Debian: python3-distributed)") from e
    path = os.path.abspath(s.file)
    chunks = s.chunks(chunk_size)
    owned = []  # what this call started, closed at its end
    try:
        if client is None and scheduler is not None:
            client = _connect(scheduler, timeout)
            owned.append(client)
        elif client is None:
            workers = threads or os.cpu_count() or 1
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=False,
                                   dashboard_address=None)
            owned.append(cluster)
            client = Client(cluster, set_as_default=False)
            owned.insert(0, client)
        futures = client.map(study_chunk_rows, [path] * len(chunks), [s.fingerprint] * len(chunks),
                             [b for b, _ in chunks], [e for _, e in chunks], pure=False)
        try:
            parts = client.gather(futures)
        finally:
            for f in futures:
                f.release()
    finally:
        for x in owned:
            x.close()
    if not parts:
        return np.empty((0, len(s.columns)))
    return np.concatenate(parts, axis=0)


def _sampled(s, sampler):
    """The study's rows with sample i's inputs from ``sampler(rng, i)`` (a dict {input column: value}
    replacing the study's draws of those columns; the rest drawn as the file says), ``rng`` numpy's
    Generator seeded by (the study's seed, i): the same seed, the same table, in any order."""
    columns = s.input_columns
    where = {c: k for k, c in enumerate(columns)}
    draws = np.empty((s.samples, len(columns)))
    for i in range(s.samples):
        draws[i] = s.draws(i)
        given = sampler(np.random.default_rng([s.seed, i]), i)
        if not isinstance(given, dict):
            raise TypeError(f"sampler: expected a dict {{input column: value}} for sample {i}, got {type(given).__name__}")
        for name, value in given.items():
            if name not in where:
                raise ValueError(f"sampler: {name!r} (sample {i}) is no input column of this study "
                                 f"(its input columns: {', '.join(columns)})")
            if not (isinstance(value, (int, float, np.floating, np.integer)) and math.isfinite(value)):
                raise ValueError(f"sampler: {name} = {value!r} (sample {i}) is no finite number")
            draws[i, where[name]] = float(value)
        for k, c in enumerate(columns):  # an axis (target.tumble, .tilt, .tumble_cone) must stay a unit vector
            if c.endswith(".axis_x") and abs(np.linalg.norm(draws[i, k:k + 3]) - 1.0) > 1e-9:
                raise ValueError(f"sampler: {c[:-7]}'s axis (sample {i}) is no unit vector: |axis| = "
                                 f"{np.linalg.norm(draws[i, k:k + 3])!r}; give all three components")
    return s.rows_drawn(draws)


def study(study, *, engine="threads", threads=0, client=None, scheduler=None, chunk_size=None, timeout=10.0,
          sampler=None):
    """Runs a capture study and returns its :class:`StudyResult` (all samples, in order).

    study: a study file's path, or a :class:`Study` (``load_study``).
    engine: ``"threads"``: the C++ engine on this process's threads (``threads``; 0: all cores).
      ``"dask"``: chunks of samples as tasks on a ``dask.distributed`` cluster, gathered in order:
      ``client`` (a ``dask.distributed.Client``, left open), or ``scheduler`` (its address, e.g.
      ``"tcp://10.0.0.5:8786"``: connected within ``timeout`` seconds, else InputError naming it and
      what happened: refused, a host with no address, something that is no Dask scheduler, no
      handshake in time, a malformed address),
      or neither: a ``LocalCluster`` of ``threads`` (0: all cores) single-threaded workers in this
      process, started and closed by the call. The workers load the study from its absolute path:
      they need the same files at the same path (a shared file system).
    chunk_size: samples per Dask task (default: the study's ``default_chunk_size``, the command-line
      tool's chunks); the rows do not depend on it.
    sampler: a callable ``sampler(rng, i)`` that draws sample i's inputs as you state them (correlated
      inputs, a distribution the file cannot write): it returns a dict {input column: value} (the
      study's ``input_columns``, e.g. ``"target.inertia.I1"``, ``"target.tumble.axis_x"``), which
      replaces those columns' draws; ``rng`` is ``numpy.random.default_rng([seed, i])``, so the same
      study and sampler give the same table. Evaluated in this process (engine threads).
    """
    if engine not in _ENGINES:
        raise ValueError(f"engine: expected 'threads' or 'dask', got {engine!r}")
    threads = _count(threads, "threads", 0)
    if chunk_size is not None:
        chunk_size = _count(chunk_size, "chunk_size", 1)
    if not (isinstance(timeout, (int, float)) and timeout > 0 and math.isfinite(timeout)):
        raise ValueError(f"timeout: expected a number of seconds > 0, got {timeout!r}")
    if engine == "threads" and (client is not None or scheduler is not None):
        raise ValueError("client, scheduler: only for engine='dask'")
    if client is not None and scheduler is not None:
        raise ValueError("client, scheduler: give one (a Client, or the address of a scheduler to connect to)")
    s = _resolve(study)
    if sampler is not None:
        if engine != "threads" or not callable(sampler):
            raise ValueError("sampler: a callable, with engine='threads'")
        table, failures = _sampled(s, sampler)
        return StudyResult(s, table, failures)
    if engine == "threads":
        table = s.rows(0, s.samples, threads=threads)
    else:
        table = _run_dask(s, client, scheduler, threads, chunk_size or 0, float(timeout))
    return StudyResult(s, table)


def study_to_table(study, table, *, threads=0, shard=None, merge=(), chunk_size=None):
    """Runs a study to its table file, as ``kdl_space study STUDY -o TABLE`` does (the library's
    runStudyToTable): the rows in chunks kept in ``TABLE.parts/`` until the table is whole (a call
    stopped by Ctrl-C keeps them, and the same call resumes), one run at a time on a table (its
    lock), the summary from the rows as they are written (never the whole table in memory).

    study: a study file's path, or a :class:`Study`. threads: 0 for all cores. shard: ``(i, n)``,
    rows of shard i of n only (1 <= i <= n <= samples), for a batch scheduler's job array.
    merge: the paths of parts (shards) to join into the whole table instead of computing.
    chunk_size: samples per chunk kept on disk (default: the study's ``default_chunk_size``).

    Returns a dict: ``table``, ``begin`` and ``end`` (its rows), ``computed``, ``resumed`` (rows
    taken from a stopped run's chunks), ``threads``, ``seconds``, ``how`` (a sentence) and
    ``summary`` (``kdl_space study --json``'s dict; None for a shard). A stale lock removed is a
    UserWarning."""
    s = _resolve(study)
    threads = _count(threads, "threads", 0)
    chunk_size = 0 if chunk_size is None else _count(chunk_size, "chunk_size", 1)
    if isinstance(merge, (str, os.PathLike)):
        raise TypeError("merge: expected a list of paths, got one path")
    if shard is not None:
        if not (isinstance(shard, (tuple, list)) and len(shard) == 2):
            raise TypeError(f"shard: expected a pair (i, n), got {shard!r}")
        shard = (_count(shard[0], "shard[0]", 1), _count(shard[1], "shard[1]", 1))
    return s.to_table(os.fspath(table), threads=threads, shard=shard, merge=[os.fspath(p) for p in merge],
                      chunk_size=chunk_size)


class StudyResult:
    """The rows of a study: ``table`` (samples, len(columns)) float64, one row per sample in order,
    column 0 ``sample``, column 1 ``status`` (0: computed; else an error code, outcomes NaN)."""

    def __init__(self, study, table, failures=None):
        table = np.asarray(table, dtype=np.float64)
        if table.ndim != 2 or table.shape[1] != len(study.columns):
            raise ValueError(f"table: expected shape (n, {len(study.columns)}), got {table.shape}")
        self.study = study
        self.columns = list(study.columns)
        self.table = table
        self._summary = None
        self._failures = failures  # {sample: why}: a sampler's rows (the study's draws would say otherwise)

    def __len__(self):
        return self.table.shape[0]

    def __getitem__(self, name):
        """The column `name` as an array (a view of the table)."""
        try:
            return self.table[:, self.columns.index(name)]
        except ValueError:
            raise KeyError(f"{name!r} is no column of this study (its columns: {', '.join(self.columns)})") from None

    @property
    def summary(self):
        """The summary as ``kdl_space study --json`` prints it (without its "table" file name)."""
        if self._summary is None:
            self._summary = self.study.summary(self.table)
            for f in self._summary.get("failures", []) if self._failures is not None else []:
                f["message"] = self._failures.get(f["first_sample"], f["message"])
        return self._summary

    @property
    def grid_points(self):
        """The per-grid-point aggregates (the summary's ``grid_points``): one dict per point of the
        study's grid that has samples, in the grid's order: ``grid_point``, ``inputs`` {grid input:
        value}, ``count`` (computed), ``failed``, ``outcomes`` {name: {mean, q95, max}},
        ``probabilities`` {exceeds.*: p}. Empty without grid inputs."""
        return self.summary["grid_points"]

    @property
    def failed(self):
        """How many samples could not be computed (status != 0)."""
        return int(np.count_nonzero(self.table[:, 1] != 0.0))

    def to_csv(self, path):
        """Writes the table as ``kdl_space study -o`` does, byte for byte (the library's writer, the
        tool's): so the command-line tool can merge it (``--merge``), resume from it, plot it. Whole
        or not at all; a path that is one of the study's inputs is refused (ValueError)."""
        self.study.write_table(self.table, os.fspath(path))

    def to_npz(self, path):
        """Writes the table with np.savez: one array per column (by its name), plus ``columns``
        (their names, in order), ``fingerprint``, ``seed`` and ``samples`` (uint64) and ``study`` (its file)."""
        arrays = {name: self.table[:, k] for k, name in enumerate(self.columns)}
        meta = {"columns": np.array(self.columns), "fingerprint": np.uint64(self.study.fingerprint),
                "seed": np.uint64(self.study.seed), "samples": np.uint64(self.study.samples),
                "study": np.array(self.study.file)}
        clash = set(arrays) & set(meta)
        if clash:  # pragma: no cover - no study column has these names
            raise ValueError(f"to_npz: columns named {sorted(clash)} clash with the file's metadata")
        np.savez(path, **arrays, **meta)

    def __repr__(self):
        return (f"<kdl_space.StudyResult '{self.study.file}' {self.table.shape[0]} samples "
                f"({self.failed} failed), table {self.table.shape}>")
