"""Shared fixtures: the repository (KDL_SPACE_SOURCE_DIR, set by ctest), the command-line tool
(KDL_SPACE_CLI), the default arm."""
import os
import pathlib

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
