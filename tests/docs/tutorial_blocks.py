#!/usr/bin/python3
"""Runs the code blocks of the manual's tutorials and guides that say they are tested (the ctest docs.Tutorials).

A page marks a fenced block as tested with an HTML comment on the line before it (Sphinx shows nothing of it):

    <!-- tested -->            the next block runs: ```sh with bash (-e, -o pipefail), ```python with Debian's
                               python3 and the build's Python package; it must exit 0
    <!-- tested: exit N -->    the same, and it must exit N
    <!-- tested: output -->    the next block is output the page shows: each of its non-empty lines must be a line
                               of what the tested block before it printed (stdout and stderr), spaces trimmed

Blocks run in a scratch folder holding links to the checkout's experiments/ and examples/, with the build's
`pegasus` first on PATH (as `pegasus`, and as build/pegasus), so a page's commands run as a reader types them.
Blocks that would take long use the small settings their page states.

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
import tempfile

MARK = re.compile(r"^<!--\s*tested(?::\s*(exit\s+(\d+)|output))?\s*-->\s*$")
FENCE = re.compile(r"^(`{3,})(\w+)?\s*$")


def blocks(page):
    """(line, kind, language, text, expected exit) of each marked block of a page."""
    lines = page.read_text(encoding="utf-8").splitlines()
    out = []
    i = 0
    while i < len(lines):
        mark = MARK.match(lines[i])
        if not mark:
            i += 1
            continue
        fence = FENCE.match(lines[i + 1]) if i + 1 < len(lines) else None
        if not fence:
            raise SystemExit(f"{page}:{i + 1}: a 'tested' mark must be followed by a fenced code block")
        end = i + 2
        while end < len(lines) and lines[end].strip() != fence.group(1):
            end += 1
        kind = "output" if mark.group(1) == "output" else "run"
        code = int(mark.group(2)) if mark.group(2) else 0
        out.append((i + 2, kind, fence.group(2) or "", "\n".join(lines[i + 2:end]) + "\n", code))
        i = end + 1
    return out


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--source", default=".")
    parser.add_argument("--build", default="build")
    parser.add_argument("pages", nargs="*")
    args = parser.parse_args()
    source = pathlib.Path(args.source).resolve()
    build = pathlib.Path(args.build).resolve()
    pages = [pathlib.Path(p).resolve() for p in args.pages] or sorted(
        p for folder in ("tutorials", "how-to", "getting-started") for p in (source / "docs" / folder).glob("*.md"))

    python_package = any((build / "python" / "pegasus").glob("_pegasus*.so"))
    env = dict(os.environ, PATH=f"{build}:{os.environ.get('PATH', '')}", PYTHONPATH=str(build / "python"))
    ran = skipped = 0
    failures = []
    with tempfile.TemporaryDirectory(prefix="pegasus-tutorials-") as scratch:
        work = pathlib.Path(scratch)
        for name in ("experiments", "examples"):
            (work / name).symlink_to(source / name)
        (work / "build").symlink_to(build)
        for page in pages:
            last = None  # what the previous tested block printed
            for line, kind, language, text, code in blocks(page):
                where = f"{page.relative_to(source) if page.is_relative_to(source) else page}:{line}"
                if kind == "output":
                    if last is None:
                        failures.append(f"{where}: output shown, but the block before it did not run")
                        continue
                    printed = {l.strip() for l in last.splitlines()}
                    missing = [l.strip() for l in text.splitlines() if l.strip() and l.strip() not in printed]
                    if missing:
                        failures.append(f"{where}: the page shows lines the block did not print: {missing}")
                    continue
                if language == "python" and not python_package:
                    print(f"skip {where}: no Python package in {build}/python")
                    skipped += 1
                    last = None
                    continue
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
    for f in failures:
        print(f"FAIL {f}")
    if failures:
        return 1
    if ran == 0:
        print(f"tutorial blocks: none ran ({skipped} skipped)")
        return 77
    print(f"tutorial blocks: {ran} ran as their pages say ({skipped} skipped)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
