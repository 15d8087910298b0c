"""Sphinx configuration of the visco-sweep site (``make docs`` builds it into docs/_build/html).

The site is built offline (no intersphinx, no link check) with warnings as errors (``-W``):
every page, the API reference from the numpy-style docstrings (napoleon), the CLI reference
from the click group ``sweep.cli:cli`` (sphinx-click) and the gallery of docs/examples/
(sphinx-gallery, each script executed at build time).
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))          # import sweep from this checkout
os.environ.setdefault("MPLBACKEND", "Agg")
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import sweep  # noqa: E402

project = "visco-sweep"
author = "visco-sweep contributors"
copyright = "2026, visco-sweep contributors"     # noqa: A001 - Sphinx's name
release = sweep.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "sphinx_click",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "examples/README.txt", "examples/*.py",
                    "auto_examples/*.ipynb", "auto_examples/*.py", "sg_execution_times.rst"]
html_theme = "furo"
html_title = f"visco-sweep {release}"
# MathJax is loaded from the page's own copy only if present; the site needs no network to
# build (a reader's browser fetches MathJax to render formulas, as every Sphinx site does)

# -- MyST (the Markdown pages) ---------------------------------------------------------------
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3

# -- API reference (numpy-style docstrings through napoleon) ------------------------------------
autodoc_member_order = "bysource"
autodoc_typehints = "none"          # the docstrings state types with their units
autodoc_default_options = {"members": True}
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
napoleon_use_ivar = True
autosummary_generate = False

# -- the gallery (docs/examples/plot_*.py, executed at every build) --------------------------
sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",       # every plot_*.py runs
    "abort_on_example_error": True,
    "only_warn_on_example_error": False,
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "reference_url": {},
    "show_memory": False,
    "plot_gallery": "True",
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "min_reported_time": 0,
    "write_computation_times": True,
}

# -- the CLI reference -----------------------------------------------------------------------
# `sweep` is a lazy click group (sweep.cli.LazyGroup): `reproduce` is imported only when it is
# invoked, so that `sweep --help` starts at once. sphinx-click documents a group's loaded
# `commands`, not its `list_commands()`: load the lazy ones here so that the reference lists
# every command (tests/test_site.py checks the two agree).
from sweep.cli import cli as _cli  # noqa: E402

for _name in getattr(_cli, "lazy", {}):
    _cli.get_command(None, _name)


# -- docstrings as the build reads them -------------------------------------------------------
# The docstrings are written for help() first: plain text in numpy style. Two of their habits
# are markup in reStructuredText, and are made literal here rather than in the source:
# * |x| (an absolute value, e.g. "|min P|") is a substitution reference: escape the bars;
# * a paragraph right after a Parameters section (napoleon turns the section into a field
#   list) needs a blank line before it;
# * a closing paragraph written inside a Parameters section (after the last parameter, at the
#   parameters' indentation, e.g. sweep.materials.Prony) reads as more parameters to numpydoc
#   and napoleon: it is given a "Notes" heading before napoleon parses the section.
import re  # noqa: E402

_LITERAL = re.compile(r"(``.*?``|`[^`]*`)")
_ABS = re.compile(r"(?<![\\|])\|(?=[^\s|])([^|\n]*?[^\s|\\])\|(?![|_])")


def _escape_bars(text: str) -> str:
    parts = _LITERAL.split(text)
    return "".join(p if i % 2 else _ABS.sub(r"\\|\1\\|", p) for i, p in enumerate(parts))


def _plain_docstring(app, what, name, obj, options, lines):
    out: list[str] = []
    in_fields = False
    for line in lines:
        if line.startswith(":"):
            in_fields = True
        elif in_fields and line and not line[0].isspace():
            out.append("")
            in_fields = False
        elif not line:
            in_fields = False
        out.append(_escape_bars(line))
    lines[:] = out


_SECTION = re.compile(r"^(Parameters|Other Parameters|Attributes)$")
_PARAM = re.compile(r"^\*{0,2}\w+(\s*,\s*\*{0,2}\w+)*(\s+:.*)?$")


def _notes_after_parameters(app, what, name, obj, options, lines):
    section = None
    for i, line in enumerate(lines):
        if i + 1 < len(lines) and set(lines[i + 1].strip()) == {"-"} and line.strip():
            section = line.strip()
            continue
        if (section and _SECTION.match(section) and line and not line[0].isspace()
                and not set(line.strip()) <= {"-"} and not _PARAM.match(line.strip())
                and i > 0 and not lines[i - 1].strip()):
            lines[i:i] = ["Notes", "-----"]
            return


def _plain_click(app, ctx, lines):
    lines[:] = [_escape_bars(line) for line in lines]


def setup(app):
    app.connect("autodoc-process-docstring", _notes_after_parameters, priority=400)
    # after napoleon (priority 500) has turned the numpy sections into field lists
    app.connect("autodoc-process-docstring", _plain_docstring, priority=600)
    app.connect("sphinx-click-process-description", _plain_click)
    app.connect("sphinx-click-process-options", _plain_click)
    app.connect("sphinx-click-process-arguments", _plain_click)
    app.connect("sphinx-click-process-epilog", _plain_click)
