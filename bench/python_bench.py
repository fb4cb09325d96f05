#!/usr/bin/python3
"""The Python package against the C++ library (issue 17's targets), Release build:
  1. U-hat of the built-in bicycle called from Python (pegasus.bicycle_uhat) against the same call in C++
     (BM_BicycleUhat_m30_H500/1 of pegasus_bench): target within 5%.
  2. The numpy bicycle (tests/python/numpy_bicycle.py, the same equations), batch U-hat of 31 policies x 30
     scenarios x 500 steps through pegasus.VectorizedProblem, with the policy in numpy and with the built-in
     SigmoidPolicy, against the C++ bicycle on the same batch (BM_BicycleUhatBatch_31x30_H500's evaluator, called
     in this process, interleaved round by round): target within 5x.
  3. `import pegasus` in a fresh interpreter: target under 0.3 s.
Usage: PYTHONPATH=build/python /usr/bin/python3 bench/python_bench.py [--bench build/bench/pegasus_bench]
Each figure is the best of several repeats (the machine may be shared and loaded: say so with the figures)."""
import argparse
import json
import os
import pathlib
import subprocess
import sys
import time

import numpy as np

import pegasus

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / "tests" / "python"))
import numpy_bicycle  # noqa: E402


def best_of(f, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return min(times)


def cpp_figure(bench, name, repetitions):
    """Best of `repetitions` single calls (min_time 1 ms: one iteration each), measured as the Python side is."""
    out = subprocess.run([bench, f"--benchmark_filter=^{name}$", "--benchmark_format=json",
                          "--benchmark_min_time=0.001", f"--benchmark_repetitions={repetitions}"],
                         capture_output=True, text=True, check=True)
    runs = [b for b in json.loads(out.stdout)["benchmarks"] if b.get("run_type") == "iteration"]
    scale = {"ms": 1e-3, "us": 1e-6, "ns": 1e-9, "s": 1.0}[runs[0]["time_unit"]]
    return min(b["real_time"] for b in runs) * scale


def batch_thetas():
    thetas = np.tile(pegasus.bicycle_balancing_theta(), (31, 1))
    for k in range(15):
        thetas[1 + 2 * k, k] += 0.05
        thetas[2 + 2 * k, k] -= 0.05
    return thetas


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--bench", default="build/bench/pegasus_bench")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--rounds", type=int, default=15, help="interleaved rounds of the batch comparison")
    args = parser.parse_args()

    theta = pegasus.bicycle_balancing_theta()
    options = pegasus.BicycleTrainingOptions()
    py_uhat = best_of(lambda: pegasus.bicycle_uhat(options, theta), 6 * args.repeats)
    cpp_uhat = cpp_figure(args.bench, "BM_BicycleUhat_m30_H500/1/real_time", 6 * args.repeats)
    print(f"U-hat, built-in bicycle, m=30 H=500: Python {py_uhat * 1e3:.2f} ms, C++ {cpp_uhat * 1e3:.2f} ms, "
          f"ratio {py_uhat / cpp_uhat:.3f}")

    # The batch comparison is measured interleaved in this one process: each round times the C++ bicycle
    # (pegasus.bicycle_training_problem: PegasusEvaluator on the shaped bicycle, BM_BicycleUhatBatch_31x30_H500's
    # evaluator and problem) and then each numpy variant on the same 31 x 30 x 500 batch, so a load change on a
    # shared machine hits both sides of a ratio alike; the figure is the median of the per-round ratios, in
    # wall time and in process CPU time.
    options = pegasus.BicycleTrainingOptions()
    gamma = options.gamma
    thetas = batch_thetas()
    cpp_problem = pegasus.bicycle_training_problem(options)
    model = numpy_bicycle.NumpyBicycle(goal=None, goal_direction=0.0, shaping_per_metre=1.0, gamma=gamma)
    numpy_policy = pegasus.VectorizedProblem(model, numpy_bicycle.NumpyBicyclePolicy(), seed=1, scenarios=30,
                                             horizon=500, gamma=gamma)
    features = numpy_bicycle.FeatureBicycle(goal=None, goal_direction=0.0, shaping_per_metre=1.0, gamma=gamma)
    builtin_policy = pegasus.VectorizedProblem(features, numpy_bicycle.feature_policy(), seed=1, scenarios=30,
                                               horizon=500, gamma=gamma)
    contenders = {"cpp": lambda: cpp_problem.uhat_batch(thetas), "numpy": lambda: numpy_policy.uhat_batch(thetas),
                  "builtin": lambda: builtin_policy.uhat_batch(thetas)}
    for f in contenders.values():  # warm up
        f()
    wall = {k: [] for k in contenders}
    cpu = {k: [] for k in contenders}
    for _ in range(args.rounds):
        for name, f in contenders.items():
            w, c = time.perf_counter(), time.process_time()
            f()
            wall[name].append(time.perf_counter() - w)
            cpu[name].append(time.process_time() - c)

    def ratio(times, name):
        return float(np.median(np.array(times[name]) / np.array(times["cpp"])))
    print(f"batch U-hat 31 x 30 x 500, {args.rounds} interleaved rounds (median of per-round ratios): "
          f"C++ bicycle median {np.median(wall['cpp']):.3f} s; "
          f"numpy bicycle + numpy policy median {np.median(wall['numpy']):.3f} s, ratio {ratio(wall, 'numpy'):.2f}x wall "
          f"{ratio(cpu, 'numpy'):.2f}x CPU; numpy bicycle + built-in SigmoidPolicy median "
          f"{np.median(wall['builtin']):.3f} s, ratio {ratio(wall, 'builtin'):.2f}x wall {ratio(cpu, 'builtin'):.2f}x CPU; "
          f"worst round {max(np.array(wall['numpy']) / np.array(wall['cpp'])):.2f}x")
    cpp_batch = cpp_figure(args.bench, "BM_BicycleUhatBatch_31x30_H500", args.repeats)
    print(f"  (pegasus_bench's BM_BicycleUhatBatch_31x30_H500, another process, best of {args.repeats}: "
          f"{cpp_batch:.3f} s)")
    flags = open("/proc/cpuinfo").read().split("flags", 2)[1].split("\n", 1)[0] if pathlib.Path("/proc/cpuinfo").exists() else ""
    simd = sorted({f for f in flags.split() if f.startswith(("avx", "sse4", "fma"))})
    print(f"CPU: {os.cpu_count()} logical cores, load average {os.getloadavg()[0]:.2f}, SIMD flags: {' '.join(simd)}")

    def fresh(code):
        return best_of(lambda: subprocess.run([sys.executable, "-c", code], check=True), args.repeats)
    baseline = fresh("pass")
    print(f"import in a fresh interpreter, interpreter start ({baseline:.3f} s) subtracted: "
          f"import pegasus {fresh('import pegasus') - baseline:.3f} s, "
          f"import numpy {fresh('import numpy') - baseline:.3f} s, "
          f"import pegasus then a first numpy call {fresh('import pegasus; pegasus.bicycle_balancing_theta()') - baseline:.3f} s")


if __name__ == "__main__":
    main()
