# Sphinx configuration of the Pegasus manual (`make docs`). Everything comes from Debian packages
# (scripts/install-deps.sh): python3-sphinx, python3-myst-parser, furo, python3-sphinx-copybutton, doxygen and
# python3-breathe. Nothing is fetched from the network at build time. Run with Debian's /usr/bin/python3.
import __future__
import os
import pathlib
import subprocess
import sys
import types

DOCS = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(DOCS)

project = "Pegasus"
author = "the Pegasus authors"
copyright = "2026, the Pegasus authors"
release = "0.1.0"

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx_copybutton",
    "breathe",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
# Files whose names start with "_" are fragments included by other pages (docs/reference/_exit-codes-table.md).
exclude_patterns = ["_*", "**/_*", "Doxyfile", "check.sh"]

# MyST: headings get anchors down to level 3, so that pages can link to sections as
# [text](page.md#anchor) and a missing anchor is a warning (an error under -W).
myst_enable_extensions = ["colon_fence", "deflist"]
myst_heading_anchors = 3
# Nitpicky mode (-n) is off: it would also ask every type named in a C++ or Python signature to resolve, and some
# 700 of them are types outside the manual (nlohmann::json, Eigen, numpy) or files breathe does not render.
# Without it, a broken link between pages or to a heading ('myst' reference target not found) is still a warning,
# and so an error under -W.

html_theme = "furo"
html_title = "Pegasus manual"
html_static_path = []

# ---- C++ API: Doxygen XML of include/pegasus, generated into the build folder on every build ----------------------
# The XML goes to PEGASUS_DOXYGEN_OUT (the Makefile sets build-docs/doxygen). Doxygen's warnings on the headers go
# to doxygen-warnings.log there and are passed on as Sphinx warnings, so `make docs` (-W) fails on them as on any
# other: the headers give none today (docs/Doxyfile, docs/doxygen-filter.sed). Sphinx's own warnings about what
# breathe renders fail it too.
_DOXYGEN_OUT = os.environ.get("PEGASUS_DOXYGEN_OUT") or os.path.join(ROOT, "build-docs", "doxygen")


def _run_doxygen(app):
    from sphinx.util import logging

    os.makedirs(_DOXYGEN_OUT, exist_ok=True)
    env = dict(os.environ, PEGASUS_DOXYGEN_OUT=_DOXYGEN_OUT)
    subprocess.run(["doxygen", "Doxyfile"], cwd=DOCS, env=env, check=True)
    log = os.path.join(_DOXYGEN_OUT, "doxygen-warnings.log")
    with open(log, encoding="utf-8", errors="replace") as f:
        for line in f:
            if line.strip():
                logging.getLogger(__name__).warning("doxygen: %s", line.rstrip())


breathe_projects = {"pegasus": os.path.join(_DOXYGEN_OUT, "xml")}
breathe_default_project = "pegasus"
breathe_domain_by_extension = {"hpp": "cpp", "h": "cpp"}
breathe_default_members = ("members",)

# ---- Python API: autodoc from the checked-in type stubs, not the compiled extension --------------------------------
# `pegasus._pegasus` is a pybind11 extension that a docs build does not compile. Its stub, python/pegasus/_pegasus.pyi,
# is valid Python: it is executed here as the module `pegasus._pegasus` (annotations postponed, so that no name has to
# exist when a signature is read), after which python/pegasus/__init__.py and its pure-Python modules import as usual.
# The signatures in the manual are therefore the stubs' (the ones type checkers see); the docstrings are the
# pure-Python modules'. This works offline with no build of the extension.
sys.path.insert(0, os.path.join(ROOT, "python"))


def _load_stub_extension():
    name = "pegasus._pegasus"
    if name in sys.modules:
        return
    path = os.path.join(ROOT, "python", "pegasus", "_pegasus.pyi")
    module = types.ModuleType(name)
    module.__file__ = path
    with open(path, encoding="utf-8") as f:
        code = compile(f.read(), path, "exec", flags=__future__.annotations.compiler_flag, dont_inherit=True)
    sys.modules[name] = module
    exec(code, module.__dict__)
    # The extension's classes and functions are documented where users meet them, as pegasus.X.
    for value in list(module.__dict__.values()):
        if isinstance(value, (type, types.FunctionType)) and value.__module__ == name:
            value.__module__ = "pegasus"


_load_stub_extension()

autodoc_member_order = "bysource"
autodoc_typehints = "signature"
autodoc_preserve_defaults = True


def _module_docstring_verbatim(app, what, name, obj, options, lines):
    # The package's and its modules' docstrings are written for help() (aligned columns), not as reStructuredText:
    # the manual shows them as they are, in a literal block.
    if what == "module" and lines:
        lines[:] = ["::", ""] + ["   " + line for line in lines] + [""]


def _furo_offline(app, exception):
    # Debian's furo (2022) loads its page script, an ES module ("import Gumshoe from ..."), by a classic <script>,
    # and its stylesheet imports /javascript/normalize.css/normalize.css, a path only Debian's web-server alias
    # serves: opened from disk, every page logged two errors and ran none of furo's script (the manual's browser
    # test, tests/browser/manual_test.mjs, found both). The built site gets them whole: the scrollspy (a UMD script
    # that sets window.Gumshoe) ahead of furo.js without the import, and normalize.css inlined.
    if exception is not None or app.builder.format != "html":
        return
    static = pathlib.Path(app.outdir) / "_static"
    script, gumshoe = static / "scripts" / "furo.js", static / "scripts" / "gumshoe-patched.js"
    module_import = 'import Gumshoe from "./gumshoe-patched.js";\n'
    if script.exists() and gumshoe.exists() and script.read_text().startswith(module_import):
        script.write_text(gumshoe.read_text() + "\n" + script.read_text()[len(module_import):])
    css = static / "styles" / "furo.css"
    normalize = pathlib.Path("/usr/share/javascript/normalize.css/normalize.css")
    css_import = "@import url(/javascript/normalize.css/normalize.css);"
    if css.exists() and normalize.exists() and css_import in css.read_text():
        css.write_text(css.read_text().replace(css_import, normalize.read_text()))


def setup(app):
    app.connect("builder-inited", _run_doxygen)
    app.connect("build-finished", _furo_offline)
    app.connect("autodoc-process-docstring", _module_docstring_verbatim)
