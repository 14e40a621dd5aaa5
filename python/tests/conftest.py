"""Shared fixtures: the repository (KDL_SPACE_SOURCE_DIR, set by ctest), the command-line tool
(KDL_SPACE_CLI), the default arm."""
import os
import pathlib
import threading

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("KDL_SPACE_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
REFERENCE_DIR = SOURCE_DIR / "tests" / "data" / "reference"
ARM = SOURCE_DIR / "urdf" / "space_arm7.urdf"
CAPTURE_SCENARIO = SOURCE_DIR / "scenarios" / "tumbling_box_capture.yaml"


@pytest.fixture(scope="session")
def source_dir():
    return SOURCE_DIR


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("KDL_SPACE_CLI", str(SOURCE_DIR / "build" / "kdl_space"))
    if not os.path.exists(path):
        pytest.skip("the command-line tool is not built (KDL_SPACE_CLI)")
    return path


@pytest.fixture(scope="session")
def arm():
    import kdl_space
    return kdl_space.load_urdf(str(ARM))


def on_two_threads(work):
    """work(k) for k = 0, 1 on two threads side by side: their results, in order. Fails if either
    raises or is still running after 120 s."""
    out, errors = {}, []

    def run(k):
        try:
            out[k] = work(k)
        except Exception as e:  # noqa: BLE001
            errors.append(e)

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert not errors and not any(t.is_alive() for t in threads), errors
    return out[0], out[1]
