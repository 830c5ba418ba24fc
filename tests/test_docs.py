"""The documentation's sources: complete API reference, links that stay in the repository.

The site itself is built, its tutorials executed, by ``.ci/run`` (``sphinx-build -W``).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import fivdisc

ROOT = Path(__file__).resolve().parents[1]
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
    from click.testing import CliRunner

    from fivdisc.cli import cli

    text = CliRunner().invoke(cli, ["plot", "--help"]).output
    assert "RESULT" in text and "FILE" not in text.split("Options:")[0]
