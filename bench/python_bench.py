#!/usr/bin/python3
"""The Python package against the C++ library (issue 17's targets), Release build:
  1. U-hat of the built-in bicycle called from Python (pegasus.bicycle_uhat) against the same call in C++
     (BM_BicycleUhat_m30_H500/1 of pegasus_bench): target within 5%.
  2. The numpy bicycle (tests/python/numpy_bicycle.py, the same equations), batch U-hat of 31 policies x 30
     scenarios x 500 steps through pegasus.VectorizedProblem, with the policy in numpy and with the built-in
     SigmoidPolicy, against the C++ bicycle on the same batch (BM_BicycleUhatBatch_31x30_H500): target within 5x.
  3. `import pegasus` in a fresh interpreter: target under 0.3 s.
Usage: PYTHONPATH=build/python /usr/bin/python3 bench/python_bench.py [--bench build/bench/pegasus_bench]
Each figure is the best of several repeats (the machine may be shared and loaded: say so with the figures)."""
import argparse
import json
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
    args = parser.parse_args()

    theta = pegasus.bicycle_balancing_theta()
    options = pegasus.BicycleTrainingOptions()
    py_uhat = best_of(lambda: pegasus.bicycle_uhat(options, theta), 6 * args.repeats)
    cpp_uhat = cpp_figure(args.bench, "BM_BicycleUhat_m30_H500/1/real_time", 6 * args.repeats)
    print(f"U-hat, built-in bicycle, m=30 H=500: Python {py_uhat * 1e3:.2f} ms, C++ {cpp_uhat * 1e3:.2f} ms, "
          f"ratio {py_uhat / cpp_uhat:.3f}")

    gamma = 0.998
    thetas = batch_thetas()
    model = numpy_bicycle.NumpyBicycle(goal=None, goal_direction=0.0, shaping_per_metre=1.0, gamma=gamma)
    numpy_policy = pegasus.VectorizedProblem(model, numpy_bicycle.NumpyBicyclePolicy(), seed=1, scenarios=30,
                                             horizon=500, gamma=gamma)
    features = numpy_bicycle.FeatureBicycle(goal=None, goal_direction=0.0, shaping_per_metre=1.0, gamma=gamma)
    builtin_policy = pegasus.VectorizedProblem(features, numpy_bicycle.feature_policy(), seed=1, scenarios=30,
                                               horizon=500, gamma=gamma)
    t_numpy = best_of(lambda: numpy_policy.uhat_batch(thetas), max(2, args.repeats // 2))
    t_builtin = best_of(lambda: builtin_policy.uhat_batch(thetas), max(2, args.repeats // 2))
    cpp_batch = cpp_figure(args.bench, "BM_BicycleUhatBatch_31x30_H500", args.repeats)
    print(f"batch U-hat 31 x 30 x 500: numpy bicycle + numpy policy {t_numpy:.3f} s "
          f"({t_numpy / cpp_batch:.1f}x C++), numpy bicycle + built-in SigmoidPolicy {t_builtin:.3f} s "
          f"({t_builtin / cpp_batch:.1f}x C++), C++ bicycle {cpp_batch:.3f} s")

    def fresh(code):
        return best_of(lambda: subprocess.run([sys.executable, "-c", code], check=True), args.repeats)
    baseline = fresh("pass")
    print(f"import in a fresh interpreter, interpreter start ({baseline:.3f} s) subtracted: "
          f"import pegasus {fresh('import pegasus') - baseline:.3f} s, "
          f"import numpy {fresh('import numpy') - baseline:.3f} s, "
          f"import pegasus then a first numpy call {fresh('import pegasus; pegasus.bicycle_balancing_theta()') - baseline:.3f} s")


if __name__ == "__main__":
    main()
