"""Sphinx configuration of the fivdisc documentation (see docs/contributing.md)."""

import re
from importlib.metadata import version as _version

project = "fivdisc"
author = "fivdisc developers"
copyright = "2026, fivdisc developers"
release = _version("fivdisc")
version = release

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "sphinx_click",
]

exclude_patterns = ["_build", "jupyter_execute"]

# MyST: $...$ and $$...$$ math, ::: fences, and anchors for ## headings.
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# Tutorials are executed on every build, in a temporary directory, so that they are
# tested; a failing cell fails the build. The timeout covers the one-off compilation of
# the kernel in a fresh installation.
nb_execution_mode = "force"
nb_execution_raise_on_error = True
nb_execution_timeout = 600
nb_execution_in_temp = True
nb_merge_streams = True

# API reference from the numpy-style docstrings.
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_typehints_format = "short"
autodoc_preserve_defaults = True
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False

html_theme = "pydata_sphinx_theme"
html_title = f"fivdisc {release}"
html_static_path = []
html_theme_options = {
    "github_url": "https://github.com/fivdisc/fivdisc",
    "navigation_with_keys": False,
    "show_toc_level": 2,
}


# Docstrings and command help write absolute values as plain text, |x|, which is how
# `--help` and `help()` show them; reStructuredText would read |x| as a substitution,
# so the bars are escaped outside ``literals``.
_BARS = re.compile(r"(?<![\\|\w])\|(?=[^\s|])([^|\n]*?[^\s|\\])\|(?![|\w])")


def _escape_bars(lines: list[str]) -> None:
    for i, line in enumerate(lines):
        parts = line.split("``")
        parts[::2] = [_BARS.sub(r"\\|\1\\|", part) for part in parts[::2]]
        lines[i] = "``".join(parts)


def setup(app):
    app.connect("autodoc-process-docstring", lambda app, what, name, obj, opts, lines:
                _escape_bars(lines))
    for event in ("description", "options", "arguments", "epilog"):
        app.connect(f"sphinx-click-process-{event}", lambda app, ctx, lines:
                    _escape_bars(lines))
