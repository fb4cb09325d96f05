#!/usr/bin/env python3
"""The scaling model of docs/scaling.md from two runs of pegasus_mpi_bench (1 process; 2 ranks x 1 thread).

One gradient-ascent iteration of the hover problem (n = 34 weights, m scenarios) is
    T(N) = T_serial + t_pair * (ceil(P_batch / N) + L * ceil(m / N)) + (1 + L) * T_comm(N)
    T_comm(N) for a message of B bytes = alpha * ceil(log2 N) + beta * B * (N - 1) / N   (0 for N = 1)
P_batch = 2 n m (theta, scenario) pairs of the derivative probes, L the line-search evaluations of m pairs
each, t_pair one 35 s rollout (U-hat time / m on one process), T_serial the optimizer's own time (bookkeeping,
reductions, the checkpoint), alpha and beta fitted to the allgathers of the two real message sizes at N = 2.
Prints the JSON that bench/mpi_scaling.sh stores as mpi_scaling.json.
"""
import json
import math
import sys


def comm(alpha, beta, nbytes, n):
    return 0.0 if n == 1 else alpha * math.ceil(math.log2(n)) + beta * nbytes * (n - 1) / n


def main():
    one, two = (json.load(open(p)) for p in sys.argv[1:3])
    m, n = one["scenarios"], one["parameters"]
    it1, it2 = one["iteration"], two["iteration"]
    p_batch = it1["batch_pairs"]
    line = max(1, it1["line_search_evaluations"])
    # One rollout: CPU seconds (what a dedicated core takes; on a shared machine wall time also counts the
    # waiting for a core), or wall seconds when CPU time was not recorded.
    t_pair = one.get("uhat_cpu_seconds", one["uhat_seconds"]) / m
    pairs = one.get("pair_cpu_seconds") or [t_pair]
    t_pair_max = max(pairs)
    t_serial = it1["serial_seconds"]
    small, large = two["allgather"][0], two["allgather"][1]
    # alpha + beta * B / 2 at N = 2 (each rank receives half the message).
    beta = max(0.0, (large["seconds_per_call"] - small["seconds_per_call"]) / (0.5 * (large["bytes"] - small["bytes"])))
    alpha = max(0.0, small["seconds_per_call"] - beta * 0.5 * small["bytes"])
    batch_bytes, single_bytes = 8 * p_batch, 8 * m

    checkpoint = it1.get("checkpoint_seconds") or 0.0

    def iteration(ranks, a, b, slowest=False, serial=None):
        # slowest: each collective waits for the rank that holds the slowest rollout (one rollout of
        # t_pair_max instead of t_pair per collective).
        extra = (t_pair_max - t_pair) if slowest and ranks > 1 else 0.0
        compute = t_pair * (math.ceil(p_batch / ranks) + line * math.ceil(m / ranks)) + (1 + line) * extra
        fixed = t_serial if serial is None else serial
        return fixed + compute + comm(a, b, batch_bytes, ranks) + line * comm(a, b, single_bytes, ranks)

    base = iteration(1, alpha, beta)
    # A cluster network instead of loopback: 50 us latency, 1 GB/s per rank (10 GbE-like).
    net_alpha, net_beta = 50e-6, 1e-9
    projection = []
    for ranks in (1, 2, 8, 64, 512):
        t = iteration(ranks, alpha, beta)
        t_net = iteration(ranks, net_alpha, net_beta)
        projection.append({
            "ranks": ranks,
            "iteration_seconds": t,
            "speedup": base / t,
            "efficiency": base / t / ranks,
            "comm_fraction": (t - t_serial - t_pair * (math.ceil(p_batch / ranks) + line * math.ceil(m / ranks))) / t,
            "speedup_cluster_network": base / t_net,
            # A checkpoint every 10 iterations instead of every one (the serial part's remedy at scale).
            "speedup_checkpoint_every_10": iteration(1, alpha, beta, serial=t_serial - 0.9 * checkpoint)
            / iteration(ranks, alpha, beta, serial=t_serial - 0.9 * checkpoint),
            "speedup_slowest_pairs": base / iteration(ranks, alpha, beta, slowest=True) if ranks > 1 else 1.0,
            # Splitting only the thetas of a batch across ranks (a single evaluation on one rank) instead:
            "speedup_theta_split": base / (t_serial + t_pair * m * (math.ceil(p_batch / m / ranks) + line)),
        })
    result = {
        "benchmark": "mpi_scaling",
        "problem": one["problem"],
        "note": "wall times on a shared machine: other work ran at the same time, so ratios matter more than seconds",
        "uhat_seconds_1process": one["uhat_seconds"],
        "uhat_seconds_2ranks": two["uhat_seconds"],
        "uhat_speedup_2ranks": one["uhat_seconds"] / two["uhat_seconds"],
        "uhat_efficiency_2ranks": one["uhat_seconds"] / two["uhat_seconds"] / 2,
        "uhat_cpu_seconds_1process": one.get("uhat_cpu_seconds"),
        "uhat_cpu_seconds_slowest_rank_2ranks": two.get("uhat_cpu_seconds_slowest_rank"),
        "uhat_cpu_speedup_2ranks": one["uhat_cpu_seconds"] / two["uhat_cpu_seconds_slowest_rank"]
        if "uhat_cpu_seconds_slowest_rank" in two else None,
        "iteration_seconds_1process": it1["seconds"],
        "iteration_seconds_2ranks": it2["seconds"],
        "iteration_speedup_2ranks": it1["seconds"] / it2["seconds"],
        "iteration_comm_seconds_2ranks": it2["comm_seconds"],
        "iteration_wait_seconds_2ranks": it2["wait_seconds"],
        "iteration_comm_fraction_2ranks": it2["comm_seconds"] / it2["seconds"],
        "iteration_flight_seconds": it1["flight_seconds"],
        "model": {
            "formula": "T(N) = T_serial + t_pair (ceil(P_batch/N) + L ceil(m/N)) + T_comm(batch) + L T_comm(single); "
                       "T_comm = alpha ceil(log2 N) + beta B (N-1)/N",
            "scenarios": m,
            "parameters": n,
            "batch_pairs": p_batch,
            "line_search_evaluations": line,
            "checkpoint_seconds": it1.get("checkpoint_seconds"),
            "t_pair_seconds": t_pair,
            "t_pair_max_seconds": t_pair_max,
            "serial_seconds": t_serial,
            "serial_fraction": t_serial / base,
            "alpha_seconds": alpha,
            "beta_seconds_per_byte": beta,
            "batch_bytes": batch_bytes,
            "single_bytes": single_bytes,
            "iteration_seconds_1process": base,
        },
        "projection": projection,
        "runs": {"1process": one, "2ranks": two},
    }
    json.dump(result, sys.stdout, indent=2)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
