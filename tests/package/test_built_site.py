"""The built documentation shows what it says: every executed tutorial cell that makes a
figure has an image among its outputs (issue 27, item 1).

Runs on a built site only: ``.ci/run`` runs it after ``sphinx-build`` (the site in
``docs/_build/html``, or where ``FIVDISC_SITE`` points); skipped otherwise.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SITE = Path(os.environ.get("FIVDISC_SITE", ROOT / "docs" / "_build" / "html"))
# MyST-NB keeps the executed notebooks beside the HTML output.
EXECUTED = sorted((SITE.parent / "jupyter_execute").rglob("*.ipynb"))

pytestmark = pytest.mark.skipif(not EXECUTED, reason=f"no built site at {SITE}")

# A cell makes a figure when it calls a drawing function or method of fivdisc or
# matplotlib, or displays an image file.
_DRAWS = re.compile(r"\bplot\w*\(|\.plot\(|\bplt\.\w+\(|\bsubplots\(|\bImage\(")
_IMAGES = ("image/png", "image/svg+xml", "image/jpeg")


def _cells(path: Path) -> list[dict]:
    return [c for c in json.loads(path.read_text(encoding="utf-8"))["cells"]
            if c["cell_type"] == "code"]


def _source(cell: dict) -> str:
    source = cell["source"]
    return source if isinstance(source, str) else "".join(source)


def _shows_an_image(cell: dict) -> bool:
    return any(kind in output.get("data", {}) for output in cell.get("outputs", [])
               for kind in _IMAGES)


def test_the_check_recognises_cells_that_draw():
    assert _DRAWS.search('fig = plot_bifurcation("bifurcation.zarr")')
    assert _DRAWS.search('result.plot("phase", slider=0);')
    assert not _DRAWS.search('print(spectrum.to_json())')


@pytest.mark.parametrize("notebook", EXECUTED, ids=lambda p: p.stem)
def test_every_figure_making_cell_shows_its_figure(notebook):
    missing = [_source(cell).strip().splitlines()[-1] for cell in _cells(notebook)
               if _DRAWS.search(_source(cell)) and not _shows_an_image(cell)]
    assert not missing, f"{notebook.name}: cells that draw but show no figure: {missing}"
