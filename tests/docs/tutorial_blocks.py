#!/usr/bin/python3
"""Runs the code blocks of the manual's tutorials and guides that say they are tested (the ctest docs.Tutorials).

A page marks a fenced block as tested with an HTML comment on the line before it (Sphinx shows nothing of it):

    <!-- tested -->            the next block runs: ```sh with bash (-e, -o pipefail), ```python with Debian's
                               python3 and the build's Python package; it must exit 0
    <!-- tested: exit N -->    the same, and it must exit N
    <!-- tested: output -->    the next block is output the page shows: each of its non-empty lines must be a line
                               of what the tested block before it printed (stdout and stderr), spaces trimmed

Blocks run in a scratch folder holding links to the checkout's experiments/, examples/ and tests/ (and, beside it,
to the shared data folder ../shared when the checkout has one), with the build's `pegasus` first on PATH (as
`pegasus`, and as build/pegasus), so a page's commands run as a reader types them. Blocks that would take long use
the small settings their page states. A block that needs what this build or machine lacks is skipped, saying what:
the Python package (python blocks, build/python), MuJoCo (`pegasus mujoco`), MPI and mpirun (`mpirun`; not under
the sanitizers, as tests/mpi), the shared data (../shared/). mpirun runs with the settings tests/mpi uses (root
allowed, no cross-memory attach, oversubscription).

Every block a reader would type (sh, bash, console, python, or a fence with no language) is either tested or in
NOT_RUN below with the reason it cannot run here; a block in neither, or an entry of NOT_RUN that names no block,
fails the test, so a new page's commands cannot go untested unnoticed. Code fragments (cpp, c, cmake, toml) are parts
of the programs the tests build (examples/, tests/export); the pages' {literalinclude} files are examples/ run by
tests/python/test_examples.py, test_sysid.py and examples.OwnModel.

    tests/docs/tutorial_blocks.py --source . --build build [PAGE.md ...]

Exit 0: every tested block ran as its page says; 1: one did not (named, with its output); 77: no tested block
could run (e.g. only Python blocks and no Python package in the build).
"""
import argparse
import os
import pathlib
import re
import subprocess
import sys
import shutil
import tempfile

MARK = re.compile(r"^<!--\s*tested(?::\s*(exit\s+(\d+)|output))?\s*-->\s*$")
FENCE = re.compile(r"^(`{3,})(\w+)?\s*$")
ANY_FENCE = re.compile(r"^(`{3,})(\S*)")
TYPED = ("sh", "bash", "console", "python", "")  # the languages of blocks a reader types

# (page, the block's first line) -> why it is not run here. Each names a block of the page; each is shown, in its
# page, beside a tested block that runs the same commands with small settings or files the checkout has, unless
# the reason says otherwise.
NOT_RUN = {
    ("docs/getting-started/install.md", "git clone"):
        "clones the repository and installs Debian packages as root (what the suite's own build did)",
    ("docs/getting-started/demo.md", "make demo"):
        "the demo: minutes on 2 cores; the helicopter tutorial's tested block runs its chain at small settings",
    ("docs/getting-started/demo.md", "build/pegasus heli pipeline --config experiments/heli-demo.toml"):
        "the demo's command: minutes; the helicopter tutorial's tested block runs its chain at small settings",
    ("docs/getting-started/tour.md", "build/pegasus hover --config experiments/quadrotor-hover-fast.toml"):
        "needs the quadrotor's pilot logs and model first; the quadrotor tutorial's tested block trains this config",
    ("docs/getting-started/tour.md", "cmake --build build --target pegasus_python"):
        "builds the Python module, which the suite's build holds (a build inside a test would race ctest -j)",
    ("docs/tutorials/own-simulator-numpy.md", "cmake --build build --target pegasus_python"):
        "builds the Python module, which the suite's build holds (a build inside a test would race ctest -j)",
    ("docs/tutorials/own-simulator-numpy.md", "sudo cmake --install build"):
        "installs as root; examples.OwnModel installs into a scratch prefix instead",
    ("docs/tutorials/own-simulator-cpp.md", "sudo apt install libeigen3-dev"):
        "installs Debian packages as root (the suite's machine has them: examples.OwnModel builds against them)",
    ("docs/tutorials/own-simulator-cpp.md", "make install PREFIX=/opt/pegasus"):
        "installs system-wide; examples.OwnModel installs into a scratch prefix and builds the example against it",
    ("docs/tutorials/aircraft-from-logs.md", "pegasus log import flight.ulg --vehicle my.toml"):
        "the outline, with placeholder files (my.toml, flight.ulg); the page's tested block runs every command",
    ("docs/tutorials/aircraft-from-logs.md", "pegasus identify --vehicle my.toml"):
        "placeholder files (my.toml, train.csv); the page's tested block runs these commands",
    ("docs/tutorials/mpi.md", "mpirun -np N pegasus <command>"):
        "the form of every such command (N, T, <command> are placeholders); the tested block below runs one",
    ("docs/tutorials/quadrotor.md", "pegasus pilot    --config experiments/quadrotor-pilot-train.toml"):
        "the measured chain: minutes (the hover alone 122 s); the tested block below runs it at small settings",
    ("docs/tutorials/quadrotor.md", "pegasus pipeline --vehicle experiments/vehicles/crazyflie2.toml"):
        "the whole chain at its defaults: minutes; tests/heli/quadrotor_cli_test.cpp runs it at small settings",
    ("docs/tutorials/quadrotor.md", "pegasus maneuver-pilot --config experiments/quadrotor-maneuver-pilot.toml"):
        "the measured figure-eight chain: about 25 minutes; the tested block below runs it at small settings",
    ("docs/tutorials/helicopter.md", "pegasus heli maneuver-pilot --config experiments/heli-maneuver-pilot.toml"):
        "the measured manoeuvre chain: many minutes; the tested block below runs it at small settings",
    ("docs/tutorials/gymnasium.md", "pegasus mujoco train --config experiments/mujoco/gymnasium/swimmer-train"):
        "needs the reader's copy of Gymnasium's swimmer.xml (not shipped); the tested block below runs the same "
        "commands on the tests' stand-in model",
    ("docs/how-to/performance.md", "/usr/bin/python3 bench/pipeline_cpu.py --rates 10,25"):
        "a Release benchmark of identify + hover at the defaults on 10-minute logs (CPU-minutes; bench/, run by "
        "hand, not a test)",
    ("docs/how-to/choose-optimizer.md", "./build/bench/pegasus_optimizer_comparison --problems cartpole"):
        "a Release benchmark of minutes (bench/, run by hand, not a test)",
    ("docs/how-to/choose-optimizer.md", "./build/bench/pegasus_optimizer_comparison --problems hover"):
        "Release benchmarks of 2-10 minutes each (bench/, run by hand, not a test)",
}


def blocks(page):
    """(line, kind, language, text, expected exit) of each fenced block of a page; kind is "run" or "output" for
    the marked ones, "unmarked" for the rest (language "{...}" for a directive such as literalinclude)."""
    lines = page.read_text(encoding="utf-8").splitlines()
    out = []
    i = 0
    while i < len(lines):
        mark = MARK.match(lines[i])
        fence = ANY_FENCE.match(lines[i + 1] if mark and i + 1 < len(lines) else lines[i])
        if mark and not (fence and FENCE.match(lines[i + 1])):
            raise SystemExit(f"{page}:{i + 1}: a 'tested' mark must be followed by a fenced code block")
        if not fence:
            i += 1
            continue
        start = i + 2 if mark else i + 1
        end = start
        while end < len(lines) and lines[end].strip() != fence.group(1):
            end += 1
        kind = "unmarked" if not mark else "output" if mark.group(1) == "output" else "run"
        code = int(mark.group(2)) if mark and mark.group(2) else 0
        out.append((start, kind, fence.group(2), "\n".join(lines[start:end]) + "\n", code))
        i = end + 1
    return out


def cmake_option(build, name):
    """Whether the build's CMakeCache.txt has NAME:BOOL=ON."""
    cache = build / "CMakeCache.txt"
    return cache.exists() and f"\n{name}:BOOL=ON" in cache.read_text(errors="replace")


def missing(language, text, build, shared):
    """What a block needs that this build or machine lacks, in words; None when it can run."""
    if (language == "python" or "build/python" in text) and not any((build / "python" / "pegasus").glob(
            "_pegasus*.so")):
        return f"no Python package in {build}/python"
    if "pegasus mujoco" in text and not cmake_option(build, "PEGASUS_MUJOCO"):
        return "this build has no MuJoCo (PEGASUS_MUJOCO off)"
    if "mpirun" in text:
        if not cmake_option(build, "PEGASUS_MPI"):
            return "this build has no MPI (PEGASUS_MPI off)"
        if not shutil.which("mpirun"):
            return "mpirun is not on PATH (Debian: openmpi-bin)"
        if os.environ.get("PEGASUS_SANITIZED"):
            return "sanitizer build: the mpirun runs are Release only, as in tests/mpi"
    if "../shared/" in text and not shared.is_dir():
        return f"no shared data folder {shared} beside the checkout"
    return None


def not_run_entry(where_page, text):
    """The NOT_RUN key of an unmarked block, or None."""
    first = next((l for l in text.splitlines() if l.strip()), "")
    for (page, prefix) in NOT_RUN:
        if page == where_page and first.startswith(prefix):
            return (page, prefix)
    return None


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--source", default=".")
    parser.add_argument("--build", default="build")
    parser.add_argument("pages", nargs="*")
    args = parser.parse_args()
    source = pathlib.Path(args.source).resolve()
    build = pathlib.Path(args.build).resolve()
    all_pages = not args.pages
    pages = [pathlib.Path(p).resolve() for p in args.pages] or sorted(
        p for folder in ("tutorials", "how-to", "getting-started") for p in (source / "docs" / folder).glob("*.md"))
    shared = source.parent / "shared"

    env = dict(os.environ, PATH=f"{build}:{os.environ.get('PATH', '')}", PYTHONPATH=str(build / "python"),
               # mpirun as tests/mpi runs it: as root in CI, in containers, more ranks than cores
               OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_btl_vader_single_copy_mechanism="none", OMPI_MCA_rmaps_base_oversubscribe="1")
    ran = skipped = 0
    failures = []
    used = set()
    with tempfile.TemporaryDirectory(prefix="pegasus-tutorials-") as scratch:
        work = pathlib.Path(scratch) / "pegasus"  # a checkout's place: ../shared beside it
        work.mkdir()
        env["TMPDIR"] = scratch  # Open MPI's session files stay in the scratch folder
        for name in ("experiments", "examples", "tests"):
            (work / name).symlink_to(source / name)
        (work / "build").symlink_to(build)
        if shared.is_dir():
            (pathlib.Path(scratch) / "shared").symlink_to(shared)
        for page in pages:
            page_name = str(page.relative_to(source)) if page.is_relative_to(source) else str(page)
            last = None  # what the previous tested block printed
            last_skipped = False  # the previous tested block was skipped (its output cannot be checked)
            for line, kind, language, text, code in blocks(page):
                where = f"{page_name}:{line}"
                if kind == "unmarked":
                    entry = not_run_entry(page_name, text)
                    if entry:
                        used.add(entry)
                    elif language in TYPED:
                        failures.append(f"{where}: a block a reader types is neither tested nor in NOT_RUN "
                                        f"(tests/docs/tutorial_blocks.py) with the reason it cannot run")
                    continue
                if kind == "output":
                    if last_skipped:
                        continue  # the block that prints it was skipped, saying why
                    if last is None:
                        failures.append(f"{where}: output shown, but the block before it did not run")
                        continue
                    printed = {l.strip() for l in last.splitlines()}
                    lines_missing = [l.strip() for l in text.splitlines() if l.strip() and l.strip() not in printed]
                    if lines_missing:
                        failures.append(f"{where}: the page shows lines the block did not print: {lines_missing}")
                    continue
                lacking = missing(language, text, build, shared)
                if lacking:
                    print(f"skip {where}: {lacking}")
                    skipped += 1
                    last = None
                    last_skipped = True
                    continue
                last_skipped = False
                if language == "python":
                    argv = ["/usr/bin/python3", "-c", text]
                elif language in ("sh", "bash", "console"):
                    argv = ["bash", "-e", "-o", "pipefail", "-c", text]
                else:
                    raise SystemExit(f"{where}: a tested block must be sh or python, not '{language}'")
                result = subprocess.run(argv, cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                        text=True, timeout=300)
                ran += 1
                last = result.stdout
                if result.returncode != code:
                    failures.append(f"{where}: exit {result.returncode}, the page expects {code}; it printed:\n"
                                    f"{result.stdout}")
                else:
                    print(f"ok   {where} ({language}, exit {code})")
    if all_pages:
        for page, prefix in sorted(set(NOT_RUN) - used):
            failures.append(f"{page}: NOT_RUN names a block that is not there any more: {prefix!r}")
    for f in failures:
        print(f"FAIL {f}")
    if failures:
        return 1
    if ran == 0:
        print(f"tutorial blocks: none ran ({skipped} skipped)")
        return 77
    print(f"tutorial blocks: {ran} ran as their pages say ({skipped} skipped, {len(used)} not run: NOT_RUN)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
