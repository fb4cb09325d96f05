"""`cmake --install` puts a package that Debian's python3 imports from the install tree alone."""
import os
import subprocess
import sys

import pytest


def test_the_installed_package_imports_and_works(tmp_path):
    cmake, build = os.environ.get("PEGASUS_CMAKE"), os.environ.get("PEGASUS_BUILD_DIR")
    if not cmake or not build:
        pytest.skip("run by ctest, which names the build directory")
    prefix = tmp_path / "prefix"
    result = subprocess.run([cmake, "--install", build, "--prefix", str(prefix)], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    site = prefix / os.environ["PEGASUS_PYTHON_INSTALL_DIR"]
    assert (site / "pegasus" / "__init__.py").exists() and (site / "pegasus" / "_pegasus.pyi").exists()
    code = ("import pegasus, numpy as np; "
            "s = pegasus.ScenarioSet(seed=1, count=2, horizon=3, noise_dim=1); "
            "plan = pegasus.TrainingPlan(stages=[pegasus.TrainingStage('g')]); "
            "print(pegasus.__file__, s.step_noise().shape, pegasus.training.__file__)")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(site)
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(str(site)) and "(2, 3, 1)" in result.stdout
    assert result.stdout.strip().endswith(str(site / "pegasus" / "training.py"))
