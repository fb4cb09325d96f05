#!/usr/bin/env python3
"""Writes BENCHMARKS.md from the JSON of `make bench` (Google Benchmark's --benchmark_out format).

    python3 scripts/benchmarks_md.py [BENCH_JSON] [--mpi MPI_JSON] [--race RACE_JSON] [--out BENCHMARKS.md]

Defaults: build/bench-results/bench.json, mpi_scaling.json beside it, bench/pendulum_race.json,
BENCHMARKS.md. Python 3 standard library only.

The optional MPI file is the mpi_scaling.json of bench/mpi_scaling_model.py (1 process vs 2 ranks x 1
thread), or Google Benchmark JSON whose benchmark names carry "ranks:N", or {"rows": [{"workload": str,
"ranks": int, "threads": int, "seconds": float}, ...]}. Missing files and benchmarks read "not measured".

The race file holds the Pendulum-v1 race against RLtools, both sides measured in one window (RLtools is
built and run outside the repository): {"machine": str, "load": [str], "rltools": str, "pegasus": str,
"runs": [{"side": "Pegasus" | "RLtools TD3" | ..., "seed": int, "seconds_to_bar": float (<= 0: never),
"cpu_seconds_to_bar": float, "total_seconds": float, "final_mean_return_100": float}, ...]}.
"""
import argparse
import json
import os
import re
import statistics
import sys

NOT_MEASURED = "not measured"


def load(path):
    if not path or not os.path.exists(path):
        return None
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def seconds(b, which="real_time"):
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b.get("time_unit", "ns")]
    return b[which] * scale


class Results:
    """The benchmarks of one run, by name; aggregates (mean/median/stddev) are skipped."""

    def __init__(self, data):
        self.context = data.get("context", {}) if data else {}
        self.by_name = {}
        for b in (data or {}).get("benchmarks", []):
            if b.get("run_type") == "aggregate":
                continue
            self.by_name.setdefault(b["name"], b)

    def find(self, pattern):
        """The first benchmark whose name matches the regular expression, or None."""
        rx = re.compile(pattern)
        for name, b in self.by_name.items():
            if rx.search(name):
                return b
        return None

    def find_all(self, pattern):
        rx = re.compile(pattern)
        return [b for name, b in self.by_name.items() if rx.search(name)]


def fmt_rate(x):
    if x is None:
        return NOT_MEASURED
    for unit, scale in (("G", 1e9), ("M", 1e6), ("k", 1e3)):
        if x >= scale:
            return f"{x / scale:.3g} {unit}"
    return f"{x:.3g}"


def fmt_time(s):
    if s is None:
        return NOT_MEASURED
    if s >= 1.0:
        return f"{s:.3g} s"
    if s >= 1e-3:
        return f"{s * 1e3:.3g} ms"
    if s >= 1e-6:
        return f"{s * 1e6:.3g} us"
    return f"{s * 1e9:.3g} ns"


def counter(b, name):
    return None if b is None or name not in b else float(b[name])


def cpu_rate(b, name):
    """A rate counter per CPU second. Google Benchmark divides rates by wall time in `real_time` benchmarks;
    for a single-threaded benchmark on a loaded machine, dividing by CPU time instead measures the code, not
    the load."""
    value = counter(b, name)
    if value is None or not b["name"].endswith("real_time") or not b.get("cpu_time"):
        return value
    return value * b["real_time"] / b["cpu_time"]


def steps_table(r):
    # (environment, benchmark, what one step is). Rates are single-threaded, so per core; Google Benchmark
    # divides by CPU time unless the benchmark uses real time.
    rows = [
        ("Gridworld 50x50 (Sarsa: step + TD update)", r"^BM_Sarsa_Gridworld50x50/", "steps_per_s"),
        ("Gridworld, POMDP exhaustive search (naive-equivalent steps)", r"^BM_ExhaustiveNaiveLoop/", "naive_steps_per_s"),
        ("Bicycle (Randlov & Alstrom)", r"^BM_BicycleStep_Fast_1M$", "steps_per_s"),
        ("Bicycle rollout with the 15-feature policy", r"^BM_BicycleRollout_Policy15_H500$", "steps_per_s"),
        ("Helicopter, ground-truth aircraft", r"^BM_HeliAircraftStep$", "steps_per_s"),
        ("Helicopter, learned model (LWR, refits included)", r"^BM_LearnedModelStep$", "steps_per_s"),
        ("Pendulum-v1 rollout (observe, act, step, reward)", r"^BM_PendulumRollout_SwingUp_H200$", "steps_per_s"),
    ]
    out = ["| Environment | Steps per second per core | Benchmark |", "|---|---:|---|"]
    for label, pattern, key in rows:
        b = r.find(pattern)
        # A benchmark that measures its own thread's CPU time says so in a *_per_cpu_s counter.
        own = counter(b, key.replace("_per_s", "_per_cpu_s"))
        out.append(f"| {label} | {fmt_rate(own if own else cpu_rate(b, key))} | `{b['name'] if b else pattern}` |")
    return out


def one_thread(r, family):
    """The single-thread instance of a family: '/threads:1', or '/1' as first argument."""
    for b in r.find_all("^" + re.escape(family) + "/"):
        rest = b["name"][len(family) + 1:]
        if rest.startswith("threads:1/") or rest == "threads:1" or rest.startswith("1/") or rest == "1":
            return b
    return None


def two_threads(r, family):
    for b in r.find_all("^" + re.escape(family) + "/"):
        rest = b["name"][len(family) + 1:]
        if rest.startswith("threads:2/") or rest == "threads:2" or rest.startswith("2/") or rest == "2":
            return b
    return None


def uhat_table(r):
    rows = [
        ("POMDP gridworld (one policy of a batch)", "BM_UhatBatchGridworld", "policies_per_s"),
        ("Bicycle, m = 30, H = 500", "BM_BicycleUhat_m30_H500", None),
        ("Helicopter hover", "BM_HeliHoverUhat", None),
        ("Pendulum-v1, m = 32, H = 200", "BM_PendulumUhat_m32_H200", None),
    ]
    out = ["| Training problem | U-hat evaluation, CPU time (1 thread) | Wall time | Benchmark |", "|---|---:|---:|---|"]
    for label, family, per_s in rows:
        b = one_thread(r, family)
        cpu = wall = None
        if b is not None and per_s:
            if counter(b, per_s):
                per_iteration = counter(b, per_s) * seconds(b)  # policies evaluated per benchmark iteration
                cpu, wall = seconds(b, "cpu_time") / per_iteration, seconds(b) / per_iteration
        elif b is not None:
            cpu, wall = seconds(b, "cpu_time"), seconds(b)
        out.append(f"| {label} | {fmt_time(cpu)} | {fmt_time(wall)} | `{b['name'] if b else family}` |")
    return out


def refit_table(r):
    out = ["| Local regression refit | CPU time | Points used | Benchmark |", "|---|---:|---:|---|"]
    labels = {
        "BM_LwrRefit_Fast": "Fast path (k-d tree), default bandwidth",
        "BM_LwrRefit_Fast_Avx2": "Fast path, AVX2 kernel, default bandwidth",
        "BM_LwrRefit_Exact": "Exact, default bandwidth",
        "BM_LwrRefit_Fast_Narrow": "Fast path, narrow bandwidth",
        "BM_LwrRefit_Exact_Narrow": "Exact, narrow bandwidth",
    }
    found = r.find_all(r"^BM_LwrRefit")
    if not found:
        out.append(f"| (none) | {NOT_MEASURED} | | |")
    for b in found:
        used = counter(b, "points_used")
        out.append(f"| {labels.get(b['name'], b['name'])} | {fmt_time(seconds(b, 'cpu_time'))} | "
                   f"{f'{used:.0f}' if used is not None else NOT_MEASURED} | `{b['name']}` |")
    return out


def training_table(r):
    """One training per benchmark iteration, single-threaded: CPU time is the code's cost, wall time adds the
    machine's load."""
    out = ["| Experiment | CPU time | Wall time | Benchmark |", "|---|---:|---:|---|"]
    rows = []
    for b in r.find_all(r"^BM_Train"):
        label = b["name"][len("BM_Train"):].strip("_/").split("/")[0]
        rows.append((label, seconds(b, "cpu_time"), seconds(b), b["name"]))
    race = r.find_all(r"^BM_PendulumRaceToBar/")
    if race:
        rows.append(("Pendulum-v1 (`pendulum train`, shipped config, mean over 3 seeds)",
                     statistics.mean(seconds(b, "cpu_time") for b in race),
                     statistics.mean(seconds(b) for b in race), "BM_PendulumRaceToBar"))
    bandwidth = one_thread(r, "BM_BandwidthCrossValidation")
    if bandwidth:
        rows.append(("Helicopter identification (bandwidth cross-validation)", seconds(bandwidth, "cpu_time"),
                     seconds(bandwidth), bandwidth["name"]))
    for label, pattern in (("Helicopter hover (`heli hover`)", "Hover"), ("Helicopter manoeuvres", "Manoeuvre")):
        if not any(pattern in name for _, _, _, name in rows):
            rows.append((label, None, None, f"BM_Train_Heli{pattern}*"))
    for label, cpu, wall, name in rows:
        out.append(f"| {label} | {fmt_time(cpu)} | {fmt_time(wall)} | `{name}` |")
    return out


def efficiency_table(r, mpi):
    out = ["| Workload | 1 | 2 | Speed-up | Parallel efficiency | Benchmark |", "|---|---:|---:|---:|---:|---|"]
    families = []
    for b in r.by_name.values():
        m = re.match(r"^(BM_[^/]+)/(threads:)?2(/|$)", b["name"])
        if m and m.group(1) not in families:
            families.append(m.group(1))
    for family in families:
        b1, b2 = one_thread(r, family), two_threads(r, family)
        if not b1 or not b2:
            continue
        t1, t2 = seconds(b1), seconds(b2)
        # Rate benchmarks (policies per second over a fixed batch) time the same work at both counts.
        out.append(f"| {family} (threads) | {fmt_time(t1)} | {fmt_time(t2)} | {t1 / t2:.2f}x | "
                   f"{100 * t1 / (2 * t2):.0f}% | `{family}` |")
    rank_rows = mpi_rows(mpi)
    if rank_rows is None:
        out.append(f"| U-hat, 1 vs 2 MPI ranks | {NOT_MEASURED} | {NOT_MEASURED} | | | |")
    else:
        for workload, t1, t2 in rank_rows:
            out.append(f"| {workload} (ranks) | {fmt_time(t1)} | {fmt_time(t2)} | {t1 / t2:.2f}x | "
                       f"{100 * t1 / (2 * t2):.0f}% | MPI |")
    return out


def mpi_rows(mpi):
    """[(workload, seconds at 1 rank, seconds at 2 ranks)] from either accepted MPI format, or None."""
    if not mpi:
        return None
    times = {}
    if "benchmarks" in mpi:
        for b in mpi["benchmarks"]:
            if b.get("run_type") == "aggregate":
                continue
            m = re.search(r"ranks:(\d+)", b["name"])
            if m:
                workload = re.sub(r"/?ranks:\d+", "", b["name"])
                times.setdefault(workload, {})[int(m.group(1))] = seconds(b)
    if mpi.get("benchmark") == "mpi_scaling":  # bench/mpi_scaling_model.py
        problem = mpi.get("problem", "?")
        for label, key in (("U-hat", "uhat_seconds"), ("one gradient iteration", "iteration_seconds")):
            if f"{key}_1process" in mpi and f"{key}_2ranks" in mpi:
                times.setdefault(f"{label}, {problem}, wall", {}).update(
                    {1: float(mpi[f"{key}_1process"]), 2: float(mpi[f"{key}_2ranks"])})
        if mpi.get("uhat_cpu_seconds_1process") and mpi.get("uhat_cpu_seconds_slowest_rank_2ranks"):
            times.setdefault(f"U-hat, {problem}, CPU of the slowest rank", {}).update(
                {1: float(mpi["uhat_cpu_seconds_1process"]), 2: float(mpi["uhat_cpu_seconds_slowest_rank_2ranks"])})
    for row in mpi.get("rows", []):
        label = row["workload"] + (f", {row['threads']} thread(s) per rank" if "threads" in row else "")
        times.setdefault(label, {})[int(row["ranks"])] = float(row["seconds"])
    rows = [(w, t[1], t[2]) for w, t in times.items() if 1 in t and 2 in t]
    return rows or None


def race_section(r, race_file):
    out = []
    if race_file and race_file.get("runs"):
        runs = race_file["runs"]
        out.append(f"Measured in one window with both sides interleaved ({race_file.get('machine', '?')}; load "
                   f"{'; '.join(l.split('load average:')[-1].strip() for l in race_file.get('load', [])[:1])} at the "
                   f"start). RLtools: {race_file.get('rltools', '?')}. Pegasus: {race_file.get('pegasus', '?')}.")
        out.append("")
        out.append("| Side | Seed | Wall time to bar | CPU time to bar | Whole training (wall) | "
                   "Final mean return (100 starts) | Final mean return (many starts) |")
        out.append("|---|---:|---:|---:|---:|---:|---:|")
        sides = []
        for run in runs:
            if run["side"] not in sides:
                sides.append(run["side"])
        for side in sides:
            for run in (x for x in runs if x["side"] == side):
                bar = run.get("seconds_to_bar")
                reached = bar is not None and bar > 0
                out.append(f"| {side} | {run['seed']} | {fmt_time(bar) if reached else 'never'} | "
                           f"{fmt_time(run.get('cpu_seconds_to_bar')) if reached else 'never'} | "
                           f"{fmt_time(run.get('total_seconds'))} | {run['final_mean_return_100']:.1f} | "
                           + (f"{run['final_mean_return_large']:.1f} ({run.get('large_starts', '?')})"
                              if run.get("final_mean_return_large") is not None else NOT_MEASURED) + " |")
        out.append("")
        if race_file.get("large"):
            out += [race_file["large"] + ".", ""]
        pegasus = [x for x in runs if x["side"] == "Pegasus" and x.get("seconds_to_bar", -1) > 0]
        for side in sides:
            if side == "Pegasus" or not pegasus:
                continue
            theirs = [x for x in runs if x["side"] == side]
            reached = [x for x in theirs if x.get("seconds_to_bar", -1) > 0]
            if not reached:
                out.append(f"{side}: never reached the bar.")
                continue
            wall = statistics.median(x["seconds_to_bar"] for x in reached)
            cpu = statistics.median(x["cpu_seconds_to_bar"] for x in reached)
            pw = statistics.median(x["seconds_to_bar"] for x in pegasus)
            pc = statistics.median(x["cpu_seconds_to_bar"] for x in pegasus)
            line = (f"- {side} vs Pegasus, medians: {fmt_time(wall)} vs {fmt_time(pw)} wall to the bar "
                    f"(**{wall / pw:.0f}x**), {fmt_time(cpu)} vs {fmt_time(pc)} CPU ({cpu / pc:.0f}x); final mean "
                    f"return over 100 starts {statistics.median(x['final_mean_return_100'] for x in theirs):.1f} vs "
                    f"{statistics.median(x['final_mean_return_100'] for x in runs if x['side'] == 'Pegasus'):.1f}")
            theirs_large = [x["final_mean_return_large"] for x in theirs if x.get("final_mean_return_large") is not None]
            ours_large = [x["final_mean_return_large"] for x in runs
                          if x["side"] == "Pegasus" and x.get("final_mean_return_large") is not None]
            if theirs_large and ours_large:
                line += (f", over many starts {statistics.mean(theirs_large):.1f} vs {statistics.mean(ours_large):.1f} "
                         f"(mean over seeds)")
            out.append(line + f" ({len(reached)} of {len(theirs)} {side} runs reached the bar).")
    else:
        out.append(f"RLtools side: {NOT_MEASURED} (no race file).")
    race = r.find_all(r"^BM_PendulumRaceToBar/")
    if race:
        out.append("")
        out.append("Pegasus in this `make bench` run (its own load, see the header): " + "; ".join(
            f"seed {b['name'].split('seed:')[1].split('/')[0]}: {fmt_time(counter(b, 'seconds_to_bar'))} wall / "
            f"{fmt_time(counter(b, 'cpu_seconds_to_bar'))} CPU to the bar, final mean return "
            f"{counter(b, 'mean_return_100'):.1f} (100 starts)"
            + (f", {counter(b, 'mean_return_5000'):.1f} (5000 other starts)" if counter(b, 'mean_return_5000') else "")
            for b in race) + ".")
    return out


def header(r, bench_path):
    c = r.context
    load = c.get("load_avg")
    load_text = ", ".join(f"{x:.2f}" for x in load) if load else "unknown"
    return [
        "# Benchmarks",
        "",
        "Generated by `scripts/benchmarks_md.py` from the JSON of `make bench` "
        f"(`{bench_path}`); regenerate with `make benchmarks-md`. Do not edit by hand.",
        "",
        f"- Run: {c.get('date', 'unknown date')} on host `{c.get('host_name', '?')}`, {c.get('num_cpus', '?')} CPUs "
        f"at {c.get('mhz_per_cpu', '?')} MHz; Pegasus built Release (Google Benchmark's own library build: "
        f"{c.get('library_build_type', '?')}).",
        f"- Load average at the start (1, 5, 15 min): {load_text}. The machine is shared: wall times and "
        "thread/rank efficiencies are noisy when the load exceeds the core count; rates are per CPU second "
        "(robust to load): a rate that Google Benchmark divided by wall time (`real_time` in the name) is "
        "converted to CPU time for single-threaded runs.",
    ]


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("bench", nargs="?", default="build/bench-results/bench.json")
    p.add_argument("--mpi", default=None, help="default: mpi_scaling.json beside BENCH_JSON")
    p.add_argument("--race", default="bench/pendulum_race.json")
    p.add_argument("--out", default="BENCHMARKS.md")
    a = p.parse_args(argv)
    if a.mpi is None:
        a.mpi = os.path.join(os.path.dirname(a.bench), "mpi_scaling.json")
    data = load(a.bench)
    if data is None:
        print(f"benchmarks_md: {a.bench}: no such file (run `make bench` first)", file=sys.stderr)
        return 2
    r = Results(data)
    lines = header(r, a.bench)
    lines += ["", "## Simulation speed", ""] + steps_table(r)
    lines += ["", "## U-hat evaluation time per training problem", ""] + uhat_table(r)
    lines += ["", "## Local-regression refit (helicopter model)", ""] + refit_table(r)
    lines += ["", "## End-to-end training", ""] + training_table(r)
    lines += ["", "## Parallel efficiency, 1 vs 2 threads and 1 vs 2 ranks", "",
              "Efficiency = T(1) / (2 T(2)) on the same work; 100% is perfect scaling on 2 cores."]
    busy = r.context.get("load_avg") and r.context.get("num_cpus") and r.context["load_avg"][0] > r.context["num_cpus"]
    if busy:
        lines += ["", f"**This run's load average ({r.context['load_avg'][0]:.1f} on {r.context['num_cpus']} CPUs) "
                  "means the 2-thread and 2-rank runs competed with other work for the cores: the wall-time "
                  "efficiencies below describe the machine's load, not the code. Rerun on a quiet machine.**"]
    lines += [""] + efficiency_table(r, load(a.mpi))
    lines += ["", "## Pendulum-v1 race against RLtools", "",
              "Wall time until the mean return over 100 fresh starts is >= -200, and the final policy's mean "
              "return over those starts (Gymnasium's Pendulum-v1, 200-step episodes; each side draws its own "
              "starts, so a 100-start mean carries about +-8 of sampling noise)."]
    lines += [""] + race_section(r, load(a.race))
    with open(a.out, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    print(f"benchmarks_md: wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
