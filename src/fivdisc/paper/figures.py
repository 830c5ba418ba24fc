"""The paper's Figs. 3-28: the data behind each, its drawing, and its comparison rows.

``compute(figure)`` simulates (or maps) what a figure shows and returns an
:class:`xarray.Dataset` holding the time histories it draws, with the comparison of
the paper's statements against fivdisc's numbers in ``attrs["comparison"]`` (JSON,
see :class:`Row`). ``plot(data)`` draws the figure from that dataset alone, so a
stored dataset can be drawn again without simulating.

Several figures show the same run (Figs. 8 and 9, 10-12, ...). A :class:`Runs`
object shared by their ``compute`` calls simulates each case once.

Where the paper's separation results are concerned, every run is repeated with the
printed paper's sign of the D-equation gyroscopic term
(``simulation.printed_gyroscopic_sign``), and the rows give both results (see
``docs/deviations.md``).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import asdict
from typing import TYPE_CHECKING

import xarray as xr

from fivdisc.paper.cases import FIGURES, PaperCase
from fivdisc.paper.fig_impact import impact_compute, impact_plot
from fivdisc.paper.fig_responses import (
    normal_compute,
    normal_plot,
    responses_compute,
    responses_plot,
)
from fivdisc.paper.fig_separation import sweep_compute, sweep_plot
from fivdisc.paper.fig_spectra import (
    spectra_compute,
    spectra_plot,
    windows_compute,
    windows_plot,
)
from fivdisc.paper.fig_stability import map_compute, map_plot
from fivdisc.paper.fig_transients import decay_compute, transient_compute, two_panel_plot
from fivdisc.paper.runs import Row, Runs

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["RECIPE", "Row", "Runs", "compute", "plot", "rows"]

RECIPE = 1
"""Version of what :func:`compute` stores; stored figures of another version are redone."""

# --- public API ------------------------------------------------------------------------------


def compute(figure: int | PaperCase, runs: Runs | None = None) -> xr.DataTree:
    """The data behind one figure, with its comparison rows.

    Parameters
    ----------
    figure
        Figure number (3-28) or its :class:`~fivdisc.paper.cases.PaperCase`.
    runs
        Simulations to share with other figures' calls; default a fresh set.

    Returns
    -------
    xarray.DataTree
        One group per run (``main``; ``a``, ``b``; ``a_printed``, ...), each a result
        in the layout of :func:`fivdisc.simulate` with the variables the figure draws
        (:func:`fivdisc.open_result` and ``fivdisc plot`` read them); Fig. 3's groups
        are stability maps, Fig. 27's separation maps. The root's attributes:
        ``figure``, ``title``, ``caption``, ``parameters`` (see
        :meth:`PaperCase.parameters`), ``recipe`` and ``comparison`` (JSON list of
        :class:`Row`), with the CF global attributes.
    """
    from fivdisc.engine.conventions import global_attrs

    pc = FIGURES[figure] if isinstance(figure, int) else figure
    runs = runs if runs is not None else Runs()
    data, table = _KINDS[pc.figure][0](pc, runs)
    data.attrs.update(
        global_attrs(f"fivdisc reproduction of Fig. {pc.figure} of the paper: {pc.title}",
                     "fivdisc.paper.compute"),
        fivdisc_kind="paper_figure",
        figure=pc.figure,
        caption=pc.caption,
        choices=pc.choices,
        parameters=pc.parameters(),
        recipe=RECIPE,
        comparison=json.dumps([asdict(r) for r in table]),
    )
    data.attrs["figure_title"] = pc.title
    return data


def plot(data: xr.DataTree) -> Figure:
    """Draw a figure from the data :func:`compute` returned (or its netCDF file's, read
    with :func:`xarray.open_datatree`)."""
    return _KINDS[int(data.attrs["figure"])][1](data)


def rows(data: xr.DataTree | xr.Dataset) -> list[Row]:
    """The comparison rows stored in a figure's data (its root attributes)."""
    return [Row(**r) for r in json.loads(data.attrs["comparison"])]




_Compute = Callable[[PaperCase, Runs], tuple[xr.Dataset, list[Row]]]
_Plot = Callable[[xr.Dataset], "Figure"]

_KINDS: dict[int, tuple[_Compute, _Plot]] = {
    3: (map_compute, map_plot),
    4: (decay_compute, two_panel_plot),
    5: (transient_compute, two_panel_plot),
    6: (decay_compute, two_panel_plot),
    7: (transient_compute, two_panel_plot),
    **{n: (spectra_compute, spectra_plot) for n in (8, 9, 10, 11, 13, 14, 15, 16)},
    12: (windows_compute, windows_plot),
    17: (windows_compute, windows_plot),
    **{n: (normal_compute, normal_plot) for n in (18, 19, 24)},
    **{n: (responses_compute, responses_plot) for n in (20, 21, 22, 23, 25, 26)},
    27: (sweep_compute, sweep_plot),
    28: (impact_compute, impact_plot),
}

