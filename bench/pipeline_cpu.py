#!/usr/bin/python3
"""CPU time of `pegasus identify` + `pegasus hover` at the defaults on a 10-minute log (issues 48 and 53).

For each aircraft and rate: the aircraft's built-in ground truth flown by `pegasus pilot` for 600 s (training,
seed 1) and 300 s (hold-out, seed 2), logged at RATE Hz in the vehicle file's layout; then `pegasus identify`
and `pegasus hover` with every other setting at its default (the vehicle file sets the model rate and the
controller's rate to RATE, as a user whose logs and flight computer run at RATE would). Each command's CPU
seconds (user + system of the process and its threads, getrusage of the children) and wall seconds.

Aircraft:
  outside-heli   the X-Cell 60 in tests/logs/outside_aircraft.hpp's layout (quaternion attitude, body
                 velocities, its own channel order, ranges and signs), simulator "xcell"
  ros-quadrotor  experiments/vehicles/ros-quadrotor.toml (ENU/FLU, degrees), simulator "crazyflie2"

The CPU seconds are the figure to compare: on a machine shared with other work the wall seconds stretch and
the CPU seconds do not (much). Extra hover options (for example a smaller budget to measure the cost per
evaluation, or --refit-every 1 for the slow setting) go after --hover.

Usage: /usr/bin/python3 bench/pipeline_cpu.py [--cli build/pegasus] [--rates 10,25]
           [--aircraft outside-heli,ros-quadrotor] [--threads 2] [--work DIR] [--out F.json] [--hover OPT ...]
"""
import argparse
import json
import os
import pathlib
import re
import resource
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent

def outside_heli(rate):
    """experiments/vehicles/outside-heli.toml (tests/logs/outside_aircraft.hpp's aircraft, flown on the X-Cell's
    ground truth, with its judged cost) at `rate`."""
    text = (ROOT / "experiments/vehicles/outside-heli.toml").read_text()
    text = re.sub(r"(?m)^(rate_hz|model_rate_hz) = 10\b", lambda m: f"{m.group(1)} = {rate}", text)
    return text


def ros_quadrotor(rate):
    text = (ROOT / "experiments/vehicles/ros-quadrotor.toml").read_text()
    text = text.replace('name = "ros-quadrotor"', 'name = "ros-quadrotor"\nsimulator = "crazyflie2"', 1)
    text = re.sub(r"(?m)^rate_hz = 50\b", f"rate_hz = {rate}", text)
    text = re.sub(r"(?m)^model_rate_hz = 10\b", f"model_rate_hz = {rate}", text)
    return text


VEHICLES = {"outside-heli": outside_heli, "ros-quadrotor": ros_quadrotor}


def timed(cmd):
    """Runs cmd; returns (cpu seconds, wall seconds, stdout)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: exit {r.returncode}\n{r.stdout}\n{r.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, wall, r.stdout


def run_case(cli, aircraft, rate, threads, work, hover_extra):
    d = work / f"{aircraft}-{rate}hz"
    d.mkdir(parents=True, exist_ok=True)
    vehicle = d / "vehicle.toml"
    vehicle.write_text(VEHICLES[aircraft](rate))
    common = ["--vehicle", str(vehicle), "--threads", str(threads), "--quiet", "--force"]
    for name, seconds, seed in (("train", 600, 1), ("test", 300, 2)):
        if not (d / name / "log.csv").exists():
            timed([cli, "pilot", *common, "--seconds", str(seconds), "--seed", str(seed), "--out", str(d / name)])
    id_cpu, id_wall, _ = timed([cli, "identify", *common, "--train", str(d / "train/log.csv"), "--test",
                                str(d / "test/log.csv"), "--out", str(d / "identify")])
    hv_cpu, hv_wall, _ = timed([cli, "hover", *common, "--model", str(d / "identify/model.json"), *hover_extra,
                                "--out", str(d / "hover")])
    ident = json.loads((d / "identify/summary.json").read_text())
    hover = json.loads((d / "hover/summary.json").read_text())
    # The class hover trained on: identify's, or the global fit beside a local model that cannot fly the default
    # training wind (hover's choices.training_model).
    model_class = (hover.get("choices", {}).get("model_class") or
                   ident.get("choices", {}).get("model_class", {}).get("class"))
    return {
        "aircraft": aircraft, "rate_hz": rate, "threads": threads,
        "identify_cpu_s": round(id_cpu, 1), "identify_wall_s": round(id_wall, 1),
        "hover_cpu_s": round(hv_cpu, 1), "hover_wall_s": round(hv_wall, 1),
        "total_cpu_min": round((id_cpu + hv_cpu) / 60, 2),
        "model_class": model_class,
        "noise": ident.get("choices", {}).get("noise", {}).get("model"),
        # A global linear model is never refitted: its summary's refit_every means nothing there.
        "refit_every": hover.get("refit_every") if model_class == "locally weighted" else None,
        "evaluations": hover.get("evaluations"),
        "hover_cpu_s_per_evaluation": round(hv_cpu / max(1, hover.get("evaluations") or 1), 3),
        "initial_uhat": hover.get("initial_uhat"), "final_uhat": hover.get("final_uhat"),
        "hover_extra": " ".join(hover_extra),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=str(ROOT / "build/pegasus"))
    ap.add_argument("--rates", default="10,25")
    ap.add_argument("--aircraft", default="outside-heli,ros-quadrotor")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--work", help="directory for the logs and runs (kept; logs are reused)")
    ap.add_argument("--out", help="write the rows as JSON here")
    ap.add_argument("--hover", nargs=argparse.REMAINDER, default=[], help="extra hover options")
    a = ap.parse_args()
    work = pathlib.Path(a.work) if a.work else pathlib.Path(tempfile.mkdtemp(prefix="pegasus-pipeline-cpu-"))
    rows = []
    print("| aircraft | rate | identify CPU s | hover CPU s | total CPU min | model | refit every | "
          "evaluations | hover CPU s / evaluation | U-hat start -> trained |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for aircraft in a.aircraft.split(","):
        for rate in (int(r) for r in a.rates.split(",")):
            r = run_case(a.cli, aircraft, rate, a.threads, work, a.hover)
            rows.append(r)
            print(f"| {aircraft} | {rate} Hz | {r['identify_cpu_s']} | {r['hover_cpu_s']} | {r['total_cpu_min']} | "
                  f"{r['model_class']} | {'-' if r['refit_every'] is None else r['refit_every']} | {r['evaluations']} | "
                  f"{r['hover_cpu_s_per_evaluation']} | {r['initial_uhat']:.6g} -> {r['final_uhat']:.6g} |",
                  flush=True)
    print(f"(CPU seconds of {a.threads} threads; load average {os.getloadavg()[0]:.1f}: other work on the "
          f"machine stretches the wall seconds, not the CPU seconds)")
    if a.out:
        pathlib.Path(a.out).write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()
