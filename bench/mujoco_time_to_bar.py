#!/usr/bin/env python3
"""Wall time and environment steps to each shipped MuJoCo task's bar (issue 18), per optimizer.

For every shipped training config (experiments/mujoco/*-train.toml) and every optimizer named on the command
line (default: the config's own), runs `pegasus mujoco train` and reads back
  summary.json     first_success: the first evaluated policy whose rollouts all met the task's success
                   criterion on the training scenarios (evaluation number, control and physics steps), and the
                   final policy's held-out success rate over 100 other scenarios;
  run.json         timings: seconds_to_first_success and training_seconds (wall clock: depends on the machine's load).
Prints one Markdown row per (task, optimizer) and writes BUILD/bench-results/mujoco_time_to_bar.json.

Usage (from the repository root): bench/mujoco_time_to_bar.py [--build build] [--threads 2]
                                  [--tasks cartpole,acrobot,hopper] [--methods cmaes,ars]
Other methods use the config's budget for their own iteration limit (max_iterations of the method).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

TASKS = ["cartpole", "acrobot", "hopper"]


def run(build, task, method, threads, out):
    config = f"experiments/mujoco/{task}-train.toml"
    args = [f"{build}/pegasus", "mujoco", "train", "--config", config, "--threads", str(threads), "--quiet",
            "--force", "--out", out]
    if method:
        args += ["--optimizer.method", method]
    start = time.monotonic()
    subprocess.run(args, check=True)
    wall = time.monotonic() - start
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(out, "run.json")) as f:
        clock = json.load(f)["timings"]
    first = summary.get("first_success")
    return {
        "task": task,
        "method": summary["method"],
        "policy": f'{summary["policy_class"]}{" phased by " + summary["phase"]["observation"] if summary.get("phase") else ""}'
                  f' ({summary["parameters"]} parameters)',
        "threads": threads,
        "first_success_evaluation": first and first["evaluation"],
        "first_success_control_steps": first and first["control_steps"],
        "first_success_physics_steps": first and first["physics_steps"],
        "seconds_to_first_success": clock.get("seconds_to_first_success"),
        "training_control_steps": summary["training_control_steps"],
        "training_seconds": clock["training_seconds"],
        "command_seconds": wall,
        "held_out_success_rate": summary["evaluation"]["success_rate"],
        "held_out_mean_return": summary["evaluation"]["mean_return"],
        "load_average": os.getloadavg()[0],
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", default="build")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--tasks", default=",".join(TASKS))
    parser.add_argument("--methods", default="", help="comma-separated; empty: the config's method")
    a = parser.parse_args()
    methods = a.methods.split(",") if a.methods else [""]
    rows = []
    print("| task | method, policy | first success: evaluation, control steps, wall s | training: control steps,"
          " wall s | held-out success rate, mean return | load average |")
    print("| --- | --- | --- | --- | --- | --- |")
    with tempfile.TemporaryDirectory() as tmp:
        for task in a.tasks.split(","):
            for method in methods:
                r = run(a.build, task, method, a.threads, os.path.join(tmp, f"{task}-{method or 'config'}"))
                rows.append(r)
                first = ("never" if r["first_success_evaluation"] is None else
                         f'{r["first_success_evaluation"]}, {r["first_success_control_steps"]:,},'
                         f' {r["seconds_to_first_success"]:.1f}')
                print(f'| {task} | {r["method"]}, {r["policy"]} | {first} | {r["training_control_steps"]:,},'
                      f' {r["training_seconds"]:.1f} | {r["held_out_success_rate"]:.2f},'
                      f' {r["held_out_mean_return"]:.1f} | {r["load_average"]:.1f} |', flush=True)
    os.makedirs(f"{a.build}/bench-results", exist_ok=True)
    with open(f"{a.build}/bench-results/mujoco_time_to_bar.json", "w") as f:
        json.dump({"cpu": cpu_model(), "rows": rows}, f, indent=2)


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return ""


if __name__ == "__main__":
    sys.exit(main())
