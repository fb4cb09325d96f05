#!/usr/bin/python3
"""Runs the shipped small configs and compares each run's summary.json with a recorded digest.

A refactoring must not change a result: every summary.json depends only on its inputs, so its SHA-256 (after
dropping keys that hold wall-clock time) is a fingerprint of the code's behaviour. Usage:
  summary_digests.py --cli build/pegasus [--record] [--only NAME ...] [--work DIR]
--record rewrites tests/digests/summary-digests.json from this build (do it only when a change of result is
intended, and say why in the commit). Every summary's keys must also be described in the key table
(`pegasus --undescribed-summary-keys`). Exit 0 when every digest matches and every key is described, 1 when not
(the differing summary or the undescribed keys are printed), 2 on bad usage.
"""
import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DIGESTS = os.path.join(ROOT, "tests", "digests", "summary-digests.json")

# name -> (arguments after `pegasus`, with {out} for the run directory and {work} for the work folder). Runs
# that read another run's output come after it.
RUNS = [
    ("pomdp-gridworld-demo", ["pomdp-gridworld", "--config", "experiments/pomdp-gridworld-demo.toml"]),
    ("bicycle-demo", ["bicycle", "experiment", "--config", "experiments/bicycle-demo.toml"]),
    ("flags-5", ["shaping", "flags", "--config", "experiments/flags-5.toml", "--runs", "4", "--trials", "200"]),
    ("shaping-gridworld-10", ["shaping", "gridworld", "--config", "experiments/shaping-gridworld-10.toml",
                              "--runs", "4", "--trials", "300"]),
    ("shaping-progress-bonus", ["shaping", "progress-bonus"]),
    ("pendulum", ["pendulum", "train", "--config", "experiments/pendulum.toml"]),
    ("heli-demo", ["heli", "pipeline", "--config", "experiments/heli-demo.toml"]),
    ("heli-maneuver-demo", ["heli", "maneuver", "--config", "experiments/heli-maneuver-demo.toml",
                            "--model", "{work}/heli-demo/identify/model.json"]),
]

# Values that are wall-clock measurements, not results, as "summary path: key/key": they are left out of the
# digest. Only these: a key such as `seconds` or `train_seconds` is an input elsewhere (a log's length).
WALL_CLOCK = {
    "pendulum": {"summary.json": ["cpu_seconds_to_bar", "seconds_to_bar", "refine_seconds", "training_seconds"]},
    "heli-demo": {"hover/summary.json": ["train_seconds", "gradient/seconds", "hill_climb/seconds"]},
}


def without(value, key_path):
    head, _, rest = key_path.partition("/")
    if isinstance(value, dict) and head in value:
        if rest:
            without(value[head], rest)
        else:
            del value[head]


def with_work_dir_named(value, work):
    """Paths under the work folder written as <work>/...: a summary that names a file stays the same wherever
    the runs were made."""
    if isinstance(value, dict):
        return {k: with_work_dir_named(v, work) for k, v in value.items()}
    if isinstance(value, list):
        return [with_work_dir_named(v, work) for v in value]
    if isinstance(value, str):
        return value.replace(work, "<work>")
    return value


def summary_digests(name, run_dir, work):
    """{relative path of every summary.json under run_dir: sha256 of its canonical JSON, wall clock left out}."""
    digests = {}
    for folder, _, files in sorted(os.walk(run_dir)):
        if "summary.json" in files:
            path = os.path.relpath(os.path.join(folder, "summary.json"), run_dir)
            with open(os.path.join(folder, "summary.json"), encoding="utf-8") as f:
                summary = with_work_dir_named(json.load(f), work)
            for key_path in WALL_CLOCK.get(name, {}).get(path, []):
                without(summary, key_path)
            text = json.dumps(summary, sort_keys=True, separators=(",", ":"))
            digests[path] = hashlib.sha256(text.encode()).hexdigest()
    return digests


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", required=True)
    parser.add_argument("--record", action="store_true")
    parser.add_argument("--only", nargs="*")
    parser.add_argument("--threads", default="2")
    parser.add_argument("--work")
    parser.add_argument("--root", default=ROOT, help="the checkout whose experiments/ the runs read")
    args = parser.parse_args()
    names = [name for name, _ in RUNS]
    for name in args.only or []:
        if name not in names:
            print(f"summary_digests: --only: unknown run {name!r}; expected one of {', '.join(names)}",
                  file=sys.stderr)
            return 2
    recorded = {}
    if os.path.exists(DIGESTS):
        with open(DIGESTS, encoding="utf-8") as f:
            recorded = json.load(f)
    work = os.path.abspath(args.work) if args.work else tempfile.mkdtemp(prefix="pegasus-digests-")
    failures = 0
    measured = dict(recorded)
    for name, argv in RUNS:
        if args.only and name not in args.only:
            continue
        out = os.path.join(work, name)
        shutil.rmtree(out, ignore_errors=True)
        command = [args.cli] + [a.format(work=work) for a in argv] + [
            "--out", out, "--quiet", "--force", "--threads", args.threads]
        result = subprocess.run(command, cwd=args.root, capture_output=True, text=True)
        if result.returncode != 0:
            print(f"{name}: exit {result.returncode}: {' '.join(command)}\n{result.stderr}", file=sys.stderr)
            failures += 1
            continue
        digests = summary_digests(name, out, work)
        measured[name] = digests
        # Every key these summaries hold has its unit and meaning in the key table (report/summary_keys.hpp),
        # which the report and the manual's summary.json page show.
        keys = subprocess.run([args.cli, "--undescribed-summary-keys", out], capture_output=True, text=True)
        if keys.returncode != 0:
            failures += 1
            print(f"{name}: summary keys without a description in src/report/summary_keys_table.cpp:\n"
                  f"{keys.stdout}{keys.stderr}", file=sys.stderr)
        if args.record:
            print(f"{name}: recorded {len(digests)} summaries")
        elif recorded.get(name) != digests:
            failures += 1
            print(f"{name}: summary.json differs from the recorded digest", file=sys.stderr)
            for path, digest in sorted(digests.items()):
                if recorded.get(name, {}).get(path) != digest:
                    print(f"  {path}: {digest} (recorded {recorded.get(name, {}).get(path)})", file=sys.stderr)
        else:
            print(f"{name}: {len(digests)} summaries match")
    if args.record:
        with open(DIGESTS, "w", encoding="utf-8") as f:
            json.dump(measured, f, indent=2, sort_keys=True)
            f.write("\n")
    if not args.work:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
