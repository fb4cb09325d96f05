#!/usr/bin/env bash
# The ctest report.SummaryKeysOfFastRuns: the commands the digest test (scripts/summary_digests.py) does not run,
# and a vehicle file's chain, at small settings (about 6 s); every key of their summaries must have its unit and
# meaning in the key table (`pegasus --undescribed-summary-keys`, src/report/summary_keys_table.cpp).
# Usage: summary_keys_runs.sh CLI SOURCE_DIR WORK_DIR MUJOCO(0|1)
set -euo pipefail
cli="$1"; root="$2"; work="$3"; mujoco="$4"
rm -rf "$work"; mkdir -p "$work"
cd "$root"
run() { local out="$1"; shift; "$cli" "$@" --out "$work/$out" --quiet --threads 1 > "$work/$out.stdout"; }
audit=experiments/audit
run horizon horizon --gamma 0.9 --epsilon 0.1
run audit-potential shaping audit --mdp $audit/gridworld-4x4.mdp.json --shaping $audit/gridworld-4x4-phi0.shaping.json
# exit 1: not potential-based; its summary carries the witness and the counterexample
run audit-bonus shaping audit --mdp $audit/gridworld-4x4.mdp.json \
  --shaping $audit/gridworld-4x4-action-bonus.shaping.json || [ $? -eq 1 ]
run bicycle-train bicycle train --scenarios 2 --horizon 50 --rides 2 --max-km 0.05 \
  --optimizer.gradient.max-iterations 2
run bicycle-ride bicycle ride --policy "$work/bicycle-train/policy.json" --rides 2 --max-km 0.05
run bicycle-variance bicycle variance --policy "$work/bicycle-train/policy.json" --sets 2 --scenarios 2 --horizon 50
run export export --policy "$work/bicycle-train/policy.json"
# A vehicle file's chain (the crazyflie2), with the keys only such runs write: the vehicle, the calibrated noise,
# the LQR start and integral action, a steady wind (a few seconds in all).
run pilot-train pilot --config experiments/quadrotor-pilot-train.toml --seconds 90
run pilot-test pilot --config experiments/quadrotor-pilot-test.toml --seconds 40
run identify identify --config experiments/quadrotor-identify.toml --train "$work/pilot-train/log.csv" \
  --test "$work/pilot-test/log.csv" --variants=false --noise ar1+measurement --calibrate-noise
run hover hover --config experiments/quadrotor-hover-fast.toml --model "$work/identify/model.json" --scenarios 2 \
  --seconds 2 --optimizer.hill-climbing.max-iterations 1
run fly fly --config experiments/quadrotor-fly.toml --policy "$work/hover/policy.json" --flights 2 --seconds 3 \
  --wind 1,0,0
# The hand-tuned baseline beside the policy, judged by a vehicle file's [cost] (the same ground truth in ROS terms).
run fly-baseline fly --config experiments/quadrotor-fly.toml --vehicle experiments/vehicles/ros-crazyflie.toml \
  --policy "$work/hover/policy.json" --compare-baseline --flights 2 --seconds 3
run maneuver-pilot maneuver-pilot --config experiments/quadrotor-maneuver-pilot.toml
if [ "$mujoco" = 1 ]; then
  run mujoco-train mujoco train --config experiments/mujoco/cartpole-train.toml --scenarios 2 \
    --optimizer.cmaes.max-iterations 2 --optimizer.cmaes.population-size 4
  run mujoco-rollout mujoco rollout --policy "$work/mujoco-train/policy.json" --episodes 2
fi
"$cli" --undescribed-summary-keys "$work"
