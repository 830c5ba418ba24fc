"""The documentation's sources: complete API reference, links that stay in the repository.

The site itself is built, its tutorials executed, by ``.ci/run`` (``sphinx-build -W``).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import fivdisc

from support.cli import run_cli

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = [ROOT / "README.md", ROOT / "CHANGELOG.md", *sorted(DOCS.rglob("*.md"))]
# Markdown links and images with a relative target: ](target) or ](target "title").
_LINK = re.compile(r"\]\((?!https?:|mailto:|#)([^)\s]+)")

pytestmark = pytest.mark.skipif(not DOCS.is_dir(), reason="needs the repository's docs/")


def test_every_public_name_is_in_the_api_reference():
    """A name added to fivdisc.__all__ needs its entry in docs/api/fivdisc.md."""
    page = (DOCS / "api" / "fivdisc.md").read_text(encoding="utf-8")
    documented = set(re.findall(r"^\.\. auto\w+:: fivdisc\.(\w+)$", page, re.MULTILINE))
    missing = sorted(set(fivdisc.__all__) - documented - {"__version__"})
    assert not missing, f"add to docs/api/fivdisc.md: {', '.join(missing)}"
    assert not documented - set(fivdisc.__all__), "docs/api/fivdisc.md names a private object"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_stay_in_the_repository(page):
    text = page.read_text(encoding="utf-8")
    for target in _LINK.findall(text):
        path = (page.parent / target.split("#")[0]).resolve()
        assert path.is_relative_to(ROOT), f"{target} points outside the repository"
        assert path.exists(), f"{target} does not exist"
    assert "shared/design" not in text and "../shared" not in text


def _conf():
    import importlib.util

    spec = importlib.util.spec_from_file_location("docs_conf", DOCS / "conf.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_parameters_documented_together_are_described_once():
    """Issue 27, item 9: ``rtol, atol : float`` rendered the whole description twice
    (napoleon gives each name the text); the second now refers to the first."""
    import inspect

    from sphinx.ext.napoleon import Config
    from sphinx.ext.napoleon.docstring import NumpyDocstring

    lines = NumpyDocstring(inspect.getdoc(fivdisc.periodic_orbit),
                           Config(napoleon_use_rtype=False)).lines()
    _conf().share_descriptions(lines)
    text = "\n".join(lines)
    assert text.count("Integration tolerances of the shooting runs") == 1
    assert ":param atol: As ``rtol``." in text
    assert ":type atol: float" in text


def test_case_signature_names_the_tables_without_their_defaults():
    """Issue 27, item 9: the Case signature was one line of every default of every table."""
    signature, _ = _conf().short_model_signature(
        None, "class", "fivdisc.Case", fivdisc.Case, {}, "(*, disc: Disc = Disc(...))", None)
    assert signature == "(*, disc=..., sliders=..., friction=..., speed=..., simulation=...)"


def test_plot_help_names_its_argument():


    text = run_cli(["plot", "--help"]).output
    assert "RESULT" in text and "FILE" not in text.split("Options:")[0]


def test_readme_documentation_command_works_as_written():
    """Issue 27, item 10: the README's command builds the site in the set-up's virtual
    environment, with CI's own install and build command, and prints where the site is
    instead of opening a browser a headless machine lacks."""
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    (command,) = [line.strip() for line in readme.splitlines() if "sphinx-build" in line]
    assert command.startswith("python3 -m venv .venv && . .venv/bin/activate && ")
    assert "pip install -e" not in command and "webbrowser" not in command
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    build = next(line for line in ci.splitlines() if line.startswith("sphinx-build"))
    assert f"pip install \".[docs]\" && {build} && echo" in command


def test_the_tutorials_kernel_starts_without_transport_noise(tmp_path):
    """Issue 27, item 10: the docs build ran every tutorial in a kernel that warned, on
    stderr, that it talks over local TCP; the build's own kernel logs errors only."""
    import subprocess
    import sys

    pytest.importorskip("nbclient")
    script = (
        "import runpy, nbformat, nbclient\n"
        f"conf = runpy.run_path({str(DOCS / 'conf.py')!r})\n"
        "(name,) = set(conf['nb_kernel_rgx_aliases'].values())\n"
        "nb = nbformat.v4.new_notebook()\n"
        "nb.cells.append(nbformat.v4.new_code_cell('print(6 * 7)'))\n"
        "nbclient.execute(nb, kernel_name=name)\n"
        "print(nb.cells[0].outputs[0]['text'])\n"
    )
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         cwd=tmp_path, timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "42"
    assert "WARNING" not in run.stderr and "TCP" not in run.stderr, run.stderr
