"""The README's Python example runs as a newcomer would run it, from the source tree's root (with
matplotlib's non-interactive backend, so that plt.show() returns)."""

import os
import re
import subprocess
import sys

from conftest import ROOT


def test_the_readme_example_runs():
    readme = (ROOT / "README.md").read_text()
    found = re.search(r"<!-- python example[^>]*-->\s*```python\n(.*?)```", readme, re.S)
    assert found, "README.md has no Python example after its '<!-- python example' marker"
    env = dict(os.environ, MPLBACKEND="Agg")
    result = subprocess.run([sys.executable, "-c", found.group(1)], cwd=ROOT, env=env, capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 0, result.stderr
