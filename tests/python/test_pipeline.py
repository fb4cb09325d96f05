"""pegasus.pipeline: `pegasus heli pipeline` run in this process by the command table's own code. The same
settings give the CLI's summary.json byte for byte; the working directory is neither used nor changed; bad
settings raise ValueError naming the setting and leave no directory behind."""
import json
import os
import subprocess

import pytest

import pegasus

# The smallest pipeline that still trains and flies (a few seconds), as keywords and as the CLI's options.
SMALL = dict(train_seconds=60, test_seconds=25, cv_points=40, scale_grid=[2, 4], coordinate_passes=0, scenarios=2,
             scenario_seconds=2, gradient_iterations=0, hill_climbing_iterations=1, flights=2, flight_seconds=3)


def cli_options(settings):
    options = []
    for name, value in settings.items():
        text = ",".join(map(str, value)) if isinstance(value, list) else str(value)
        options += ["--" + name.replace("_", "-"), text]
    return options


def test_the_pipeline_gives_the_clis_summary_and_leaves_the_working_directory(cli, tmp_path, monkeypatch):
    result = subprocess.run([cli, "heli", "pipeline", *cli_options(SMALL), "--seed", "5", "--threads", "2",
                             "--quiet", "--out", str(tmp_path / "cli")], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr

    # From a working directory where the stages' relative names (pilot-train/log.csv, ...) name nothing.
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    summary = pegasus.pipeline(tmp_path / "lib", seed=5, threads=2, **SMALL)
    assert os.getcwd() == str(elsewhere)
    assert list(elsewhere.iterdir()) == []
    cli_summary = (tmp_path / "cli" / "summary.json").read_bytes()
    assert (tmp_path / "lib" / "summary.json").read_bytes() == cli_summary
    assert summary == json.loads(cli_summary)
    for stage in ["identify", "hover", "fly"]:
        assert ((tmp_path / "lib" / stage / "summary.json").read_bytes()
                == (tmp_path / "cli" / stage / "summary.json").read_bytes()), stage
    assert summary["flights"] == 2
    # The report's bundle is found from the module as from the CLI (next to it in the build tree).
    for stage in ["", "identify", "fly"]:
        assert (tmp_path / "lib" / stage / "report.html").exists() == (tmp_path / "cli" / stage / "report.html").exists()

    # A second call into the committed directory is refused as the CLI refuses it, unless forced.
    with pytest.raises(ValueError):
        pegasus.pipeline(tmp_path / "lib", seed=5, threads=2, **SMALL)
    assert pegasus.pipeline(str(tmp_path / "lib"), seed=5, threads=2, force=True, **SMALL) == summary


@pytest.mark.parametrize("setting, named", [({"flights": -1}, "'flights'"), ({"flight_secs": 3}, "'flight_secs'"),
                                            ({"flights": "two"}, "'flights'"), ({"seed": -1}, "'seed'"),
                                            ({"scale_grid": {"a": 1}}, "scale_grid")])
def test_a_bad_setting_raises_value_error_naming_it_and_writes_nothing(tmp_path, setting, named):
    settings = dict(setting)
    seed = settings.pop("seed", 1)
    with pytest.raises(ValueError, match=named) as raised:
        pegasus.pipeline(tmp_path / "bad", seed=seed, **settings)
    assert "\n" not in str(raised.value)
    assert list(tmp_path.iterdir()) == []
