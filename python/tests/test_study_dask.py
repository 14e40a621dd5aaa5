"""A Dask scheduler that cannot be used is an InputError that says what happened, promptly, and
leaves no hang at the interpreter's exit: nothing listens (refused), the host has no address,
something that is no Dask scheduler answers (garbage), the connection opens but nothing answers
(silent), the address is malformed. A real scheduler over TCP computes the threads' rows."""
import socket
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import kdl_space
from conftest import CAPTURE_SCENARIO

STUDY = f"""\
scenario: {CAPTURE_SCENARIO}
samples: 12
seed: 7
inputs:
  target.tumble: {{uniform: [0.02, 0.2]}}
"""


@pytest.fixture()
def small(tmp_path):
    path = tmp_path / "small_study.yaml"
    path.write_text(STUDY)
    return path


class Server:
    """A TCP server on loopback that answers every connection with `reply` (bytes, then closes)
    or, when reply is None, keeps it open and says nothing."""

    def __init__(self, reply):
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.reply, self.held = reply, []
        threading.Thread(target=self._serve, daemon=True).start()

    @property
    def address(self):
        return f"tcp://127.0.0.1:{self.sock.getsockname()[1]}"

    def _serve(self):
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            if self.reply is None:
                self.held.append(conn)
            else:
                conn.sendall(self.reply)
                conn.close()

    def close(self):
        self.sock.close()
        for c in self.held:
            c.close()


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]  # closed again: nothing listens there


CASES = {
    "refused": lambda: (f"tcp://127.0.0.1:{free_port()}", "the connection was refused: nothing listens at", 2.0),
    "no such host": lambda: ("tcp://no-such-host.invalid:8786", "cannot resolve the host 'no-such-host.invalid'", 2.0),
    "malformed": lambda: ("nonsense:://x", "is no scheduler address", 2.0),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_scheduler_that_cannot_be_reached(small, case):
    address, message, within = CASES[case]()
    t0 = time.monotonic()
    with pytest.raises(kdl_space.InputError, match=f"scheduler {address}: {message}"):
        kdl_space.study(str(small), engine="dask", scheduler=address, timeout=8)
    assert time.monotonic() - t0 < within + 1.0  # well before the 8 s timeout: it knows at once


def test_garbage_is_no_scheduler_and_silence_is_a_timeout(small):
    garbage = Server(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n" * 4)
    silent = Server(None)
    try:
        t0 = time.monotonic()
        with pytest.raises(kdl_space.InputError,
                           match=f"scheduler {garbage.address}: something answers at 127.0.0.1:[0-9]+, but not a "
                                 "Dask scheduler"):
            kdl_space.study(str(small), engine="dask", scheduler=garbage.address, timeout=8)
        assert time.monotonic() - t0 < 4.0  # not "timed out after 8 s"
        t0 = time.monotonic()
        with pytest.raises(kdl_space.InputError,
                           match=f"scheduler {silent.address}: the connection opened, but no Dask handshake "
                                 "within 2 s"):
            kdl_space.study(str(small), engine="dask", scheduler=silent.address, timeout=2)
        assert 1.5 < time.monotonic() - t0 < 6.0
    finally:
        garbage.close()
        silent.close()


def test_no_hang_at_exit_after_a_failed_connection(small):
    """The failed call leaves no Client behind whose clean-up holds the interpreter's exit."""
    script = textwrap.dedent(f"""
        import time, kdl_space
        for address in ("tcp://127.0.0.1:{free_port()}", "nonsense:://x"):
            try:
                kdl_space.study({str(small)!r}, engine="dask", scheduler=address, timeout=10)
            except kdl_space.InputError as e:
                print("failed:", e, flush=True)
        print("end", time.monotonic(), flush=True)
    """)
    t0 = time.monotonic()
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    ended = time.monotonic()
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("failed:") == 2
    assert "Exception ignored" not in done.stderr, done.stderr
    # the process is gone within 3 s of its last line (before: a 10 s hang in Client.__del__)
    last = float(done.stdout.split("end ")[1])
    assert ended - last < 3.0, f"exit took {ended - last:.1f} s"
    assert ended - t0 < 20.0


@pytest.mark.filterwarnings("ignore:make_current is deprecated:DeprecationWarning")  # tornado, in distributed
def test_a_scheduler_over_tcp_gives_the_threads_rows(small):
    from dask.distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp", host="127.0.0.1",
                      dashboard_address=None) as cluster:
        assert cluster.scheduler_address.startswith("tcp://")
        r = kdl_space.study(str(small), engine="dask", scheduler=cluster.scheduler_address, timeout=10)
    expected = kdl_space.study(str(small), threads=1).table
    assert r.table.shape == expected.shape
    assert np.array_equal(r.table.view(np.uint64), expected.view(np.uint64))
