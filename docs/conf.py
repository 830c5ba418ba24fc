"""Sphinx configuration of the fivdisc documentation (see docs/contributing.md)."""

import json
import os
import re
import sys
from importlib.metadata import version as _version
from pathlib import Path

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
# tested; a failing cell fails the build.
nb_execution_mode = "force"
nb_kernel_rgx_aliases = {".*": "fivdisc-docs"}
nb_execution_raise_on_error = True
nb_execution_timeout = 600
nb_execution_in_temp = True
nb_merge_streams = True

# The tutorials' kernel: this Python, logging errors only. ipykernel warns at every start
# that it talks to the build over local TCP, unencrypted: a warning per tutorial that
# says nothing about the documentation (issue 27, item 10).
_KERNELS = Path(__file__).resolve().parent / "_build" / "kernels"
(_KERNELS / "kernels" / "fivdisc-docs").mkdir(parents=True, exist_ok=True)
(_KERNELS / "kernels" / "fivdisc-docs" / "kernel.json").write_text(json.dumps({
    "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}",
             "--IPKernelApp.log_level=ERROR"],
    "display_name": "Python 3 (fivdisc docs)", "language": "python"}))
os.environ["JUPYTER_PATH"] = os.pathsep.join(
    filter(None, [str(_KERNELS), os.environ.get("JUPYTER_PATH")]))

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


_PARAM = re.compile(r":param (\w+):(.*)")


def share_descriptions(lines: list[str]) -> None:
    """Parameters documented together (``rtol, atol : float``) are split by napoleon into
    one field each, with the whole description repeated: keep it on the first and refer
    the others to it."""
    fields: list[tuple[int, int, str]] = []  # (start, end, name) of each :param: field
    for i, line in enumerate(lines):
        match = _PARAM.match(line)
        if match:
            end = i + 1
            while end < len(lines) and lines[end].startswith((" ", "\t")) and lines[end].strip():
                end += 1
            fields.append((i, end, match.group(1)))
    for start, end, name in reversed(fields):
        text = (_PARAM.match(lines[start]).group(2), *lines[start + 1:end])
        first = next((n for s, e, n in fields if s < start and
                      (_PARAM.match(lines[s]).group(2), *lines[s + 1:e]) == text), None)
        if first is not None and text != ("",):
            lines[start:end] = [f":param {name}: As ``{first}``."]


def short_model_signature(app, what, name, obj, options, signature, return_annotation):
    """A pydantic model's signature names its fields without their defaults: the
    defaults of a case's tables are documented with the tables, not dumped in one line."""
    fields = getattr(obj, "model_fields", None)
    if what == "class" and isinstance(fields, dict) and signature:
        return "(*, " + ", ".join(f"{field}=..." for field in fields) + ")", return_annotation
    return None


def setup(app):
    app.connect("autodoc-process-docstring", lambda app, what, name, obj, opts, lines:
                (_escape_bars(lines), share_descriptions(lines)))
    app.connect("autodoc-process-signature", short_model_signature)
    for event in ("description", "options", "arguments", "epilog"):
        app.connect(f"sphinx-click-process-{event}", lambda app, ctx, lines:
                    _escape_bars(lines))
