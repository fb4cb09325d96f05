#!/usr/bin/env bash
# Installs every Debian package Pegasus needs to build, test and benchmark.
# Idempotent: when everything is present it prints nothing and returns at once;
# `apt-get update` runs only when something is missing.
set -euo pipefail

packages=(
  # toolchain
  g++ make cmake ninja-build ccache pkg-config git clang-format clang-tidy
  # libraries (the manual's "Install and build", docs/getting-started/install.md, says why each is here)
  libeigen3-dev libnlopt-cxx-dev librandom123-dev libboost-dev
  libcli11-dev libtomlplusplus-dev nlohmann-json3-dev libfmt-dev
  # SHA-256 of imported flight logs (their provenance)
  libssl-dev
  # the report's embedded chart data is gzip-compressed
  zlib1g-dev
  # distributed evaluation (optional at configure time; mpirun runs the MPI tests)
  libopenmpi-dev openmpi-bin
  # MuJoCo physics (optional at configure time: PEGASUS_MUJOCO) and its sample models (a shipped task loads one)
  libmujoco-dev libmujoco-samples
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev python3
  # `make package`: dpkg-shlibdeps gives the Debian package its Depends
  dpkg-dev
  # the C compiler that builds exported controllers (pegasus export) in tests/export and the export benchmark
  gcc
  # make test (its sanitizer pass) and make fuzz: clang++ 14 with the sanitizers' runtimes and libFuzzer
  clang libclang-rt-14-dev
  # the HTML report's browser test
  chromium
  # the Python package (python/, `import pegasus`): pybind11 bindings for Debian's /usr/bin/python3, numpy
  # arrays, scipy.sparse MDPs, and the pytest suite in tests/python
  python3-dev python3-numpy python3-scipy python3-pytest pybind11-dev
  # the manual (make docs): Sphinx with Markdown pages, its theme and copy buttons, and the C++ API from the public
  # headers through Doxygen's XML and breathe; run by Debian's /usr/bin/python3, nothing fetched at build time
  python3-sphinx python3-myst-parser furo python3-sphinx-copybutton doxygen python3-breathe
)
# the report's JavaScript comes from npm; a node/npm installed some other way (e.g. NodeSource) is kept
command -v node >/dev/null 2>&1 || packages+=(nodejs)
command -v npm >/dev/null 2>&1 || packages+=(npm)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "install-deps: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
