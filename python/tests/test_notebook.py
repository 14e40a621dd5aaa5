"""examples/notebook.py runs headless (MPLBACKEND=Agg) and writes its figures, so it cannot rot."""
import os
import subprocess
import sys

from conftest import SOURCE_DIR


def test_notebook_runs_headless(tmp_path):
    figures = tmp_path / "figures"
    env = dict(os.environ, MPLBACKEND="Agg", KDL_SPACE_FIGURES=str(figures), KDL_SPACE_DURATION="2")
    env.pop("DISPLAY", None)
    # the package as the tests import it, from another working directory
    env["PYTHONPATH"] = os.pathsep.join(os.path.abspath(p) for p in env.get("PYTHONPATH", "").split(os.pathsep) if p)
    out = subprocess.run([sys.executable, str(SOURCE_DIR / "examples" / "notebook.py")], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert "impulse (f; n):" in out.stdout and "SimulationResult" in out.stdout
    for name in ("capture_motion.png", "capture_motion_digital_pd.png", "digital_pd_torques.png"):
        f = figures / name
        assert f.is_file() and f.stat().st_size > 10_000, name
