"""pytest setup for the Python package's tests: run by ctest (test `python`) with PYTHONPATH=build/python,
PEGASUS_CLI the built command line and PEGASUS_SOURCE_DIR the repository."""
import os
import pathlib
import sys

import pytest

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))  # numpy_bicycle


@pytest.fixture(scope="session")
def source_dir():
    return pathlib.Path(os.environ.get("PEGASUS_SOURCE_DIR", HERE.parent.parent))


@pytest.fixture(scope="session")
def cli(source_dir):
    path = os.environ.get("PEGASUS_CLI", str(source_dir / "build" / "pegasus"))
    if not os.path.exists(path):
        pytest.fail(f"PEGASUS_CLI: no pegasus binary at {path}")
    return path
