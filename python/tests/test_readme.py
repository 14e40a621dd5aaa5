"""The README's Python example, run exactly as written (between its markers) from the repository."""
import os
import re
import subprocess
import sys

from conftest import SOURCE_DIR


def test_readme_example():
    readme = (SOURCE_DIR / "README.md").read_text()
    block = re.search(r"<!-- python-example -->\s*```python\n(.*?)```\s*<!-- /python-example -->", readme, re.S)
    assert block, "README.md: the Python example between <!-- python-example --> markers is missing"
    code = block.group(1)
    assert len(code.strip().splitlines()) <= 12
    out = subprocess.run([sys.executable, "-c", code], cwd=SOURCE_DIR, capture_output=True, text=True,
                         env=dict(os.environ), timeout=120)
    assert out.returncode == 0, out.stderr
    assert "G* =" in out.stdout and "impulse" in out.stdout
