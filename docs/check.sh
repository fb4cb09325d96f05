#!/usr/bin/env bash
# Checks the manual (make docs-check, and the ctest docs.Manual): builds it as `make docs` does, into a scratch folder, and
# fails on
#   - any Sphinx warning (the build runs -W --keep-going, so every warning is listed before it fails; a broken
#     internal link or a missing anchor is one), and on any line Sphinx or Doxygen's XML step printed as WARNING/ERROR;
#   - a README.md of 400 lines or more (the README is the front door; the manual holds the rest);
#   - a page named in a toctree of docs/ that does not exist;
#   - a relative link of README.md to a file that does not exist, or to a heading anchor its Markdown page lacks
#     (the README is read on a Git host, outside Sphinx, so Sphinx does not check its links);
#   - a page of the built site that headless chromium shows with a console error, or without its text
#     (tests/browser/manual_test.mjs: home, a tutorial, the command reference, the C++ and Python APIs), where
#     node, playwright-core (NODE_MODULES) and chromium are installed; skipped with a line otherwise.
# Usage: docs/check.sh [BUILD_DIR [NODE_MODULES]]   (default build-docs and build/web/node_modules; the site goes
# to BUILD_DIR/check-html)
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build-docs}"
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac   # absolute: ctest passes its own folder
python=/usr/bin/python3   # Debian's own, with the Debian Sphinx packages (the first python3 on PATH may be another)
status=0

lines=$(wc -l < README.md)
if [ "$lines" -ge 400 ]; then
  echo "docs/check: README.md has $lines lines; it must stay under 400 (move the rest into docs/)"; status=1
else
  echo "docs/check: README.md has $lines lines (< 400)"
fi

# Every entry of every {toctree} block in docs/*.md names a page that exists (relative to the page's folder).
missing=$("$python" - <<'PY'
import pathlib, re
root = pathlib.Path("docs")
bad = []
for page in sorted(root.rglob("*.md")):
    text = page.read_text(encoding="utf-8")
    for block in re.findall(r"```\{toctree\}\n(.*?)```", text, re.S):
        for line in block.splitlines():
            entry = line.strip()
            if not entry or entry.startswith(":"):
                continue
            entry = re.sub(r"^.*<(.*)>$", r"\1", entry)   # "Title <page>"
            target = page.parent / entry
            if not any(target.with_suffix(s).exists() for s in (".md", ".rst")) and not target.exists():
                bad.append(f"{page}: toctree names {entry}, which does not exist")
print("\n".join(bad))
PY
)
if [ -n "$missing" ]; then echo "$missing"; status=1; else echo "docs/check: every toctree entry exists"; fi

# README.md's relative links: the file exists, and an anchor is one of the target page's headings (slugs as MyST
# and Git hosts make them: lower case, punctuation dropped, spaces to hyphens).
broken=$("$python" - <<'PY'
import pathlib, re
readme = pathlib.Path("README.md").read_text(encoding="utf-8")
def slug(title):
    title = re.sub(r"[`*]", "", title).strip().lower()
    title = re.sub(r"[^\w\- ]", "", title)
    return title.replace(" ", "-")
bad = []
for target in re.findall(r"\]\(([^)\s]+)\)", readme):
    if re.match(r"^[a-z]+:", target):
        continue
    path, _, anchor = target.partition("#")
    page = pathlib.Path(path)
    if not page.exists():
        bad.append(f"README.md: link to {target}: no such file")
    elif anchor:
        headings = re.findall(r"^#{1,6} (.*)$", page.read_text(encoding="utf-8"), re.M)
        if anchor not in {slug(h) for h in headings}:
            bad.append(f"README.md: link to {target}: {path} has no heading with that anchor")
print("\n".join(bad))
PY
)
if [ -n "$broken" ]; then echo "$broken"; status=1; else echo "docs/check: every relative link of README.md resolves"; fi

log="$build/check-sphinx.log"
mkdir -p "$build"
if ! PEGASUS_DOXYGEN_OUT="$build/doxygen" "$python" -m sphinx -b html -W --keep-going -q -E \
     -d "$build/check-doctrees" docs "$build/check-html" > "$log" 2>&1; then
  cat "$log"; echo "docs/check: the Sphinx build failed (above)"; status=1
elif grep -E "WARNING|ERROR|CRITICAL" "$log"; then
  echo "docs/check: the Sphinx build printed warnings (above)"; status=1
else
  echo "docs/check: the manual builds with no warnings ($build/check-html/index.html)"
  node_modules="${2:-build/web/node_modules}"
  if ! command -v node > /dev/null; then
    echo "docs/check: no node: the manual's browser test is skipped"
  else
    browser=0
    node tests/browser/manual_test.mjs --site "$build/check-html" --node-modules "$node_modules" || browser=$?
    if [ "$browser" -ne 0 ] && [ "$browser" -ne 77 ]; then
      echo "docs/check: the manual's browser test failed (above)"; status=1
    fi
  fi
fi
exit $status
