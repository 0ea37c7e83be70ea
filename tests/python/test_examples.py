"""Every script in examples/ runs to its end (each asserts what it shows)."""
import os
import subprocess
import sys

import pytest

EXAMPLES = os.environ["RDYN_EXAMPLES"]


@pytest.mark.parametrize("script", sorted(f for f in os.listdir(EXAMPLES) if f.endswith(".py")))
def test_example_runs(script, tmp_path):
    p = subprocess.run([sys.executable, os.path.join(EXAMPLES, script)], cwd=tmp_path, capture_output=True,
                       text=True, timeout=600)
    assert p.returncode == 0, p.stdout + p.stderr
