"""examples/python runs, so it never rots (each example asserts its own result)."""
import os
import subprocess
import sys

import pytest


@pytest.mark.parametrize("script", ["own_simulator.py", "finite_mdp_shaping.py", "gymnasium_env.py", "helicopter.py"])
def test_example_runs(source_dir, script):
    result = subprocess.run([sys.executable, str(source_dir / "examples" / "python" / script)], capture_output=True,
                            text=True, timeout=300, env=dict(os.environ))
    assert result.returncode == 0, result.stdout + result.stderr
