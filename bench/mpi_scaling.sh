#!/usr/bin/env bash
# Distributed evaluation of the hover problem (bench/mpi_scaling.cpp) at one process and at 2 ranks x 1 thread,
# then the scaling model (bench/mpi_scaling_model.py): writes BUILD/bench-results/mpi_scaling.json (keys in
# docs/scaling.md). Usage: bench/mpi_scaling.sh [BUILD_DIR]. Skips, saying why, without MPI or mpirun.
set -euo pipefail
build="${1:-build}"
exe="$build/bench/pegasus_mpi_bench"
results="$build/bench-results"
mkdir -p "$results"
if [ ! -x "$exe" ]; then echo "mpi_scaling: $exe is not built; skipped" >&2; exit 0; fi
if ! command -v mpirun >/dev/null 2>&1; then echo "mpi_scaling: mpirun not found (openmpi-bin); skipped" >&2; exit 0; fi
# CI runs as root; containers often forbid Open MPI's cross-memory attach; small machines have few cores.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_rmaps_base_oversubscribe=1
"$exe" --threads 1 --out "$results/mpi_scaling_np1.json"
if ! mpirun -np 2 "$exe" --threads 1 --out "$results/mpi_scaling_np2.json"; then
  echo "mpi_scaling: the 2-rank run failed (a build without MPI?); skipped" >&2
  exit 0
fi
python3 "$(dirname "$0")/mpi_scaling_model.py" "$results/mpi_scaling_np1.json" "$results/mpi_scaling_np2.json" \
  > "$results/mpi_scaling.json"
echo "mpi_scaling: results in $results/mpi_scaling.json"
