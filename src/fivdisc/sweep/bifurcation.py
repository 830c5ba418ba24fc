"""Bifurcation diagrams: the values of a section over the one swept key of a sweep.

Every point's section values (see :mod:`fivdisc.sweep.sections`) are drawn as dots above
its value of the swept key (small ones where the points are many, visible ones where they
are few); where the sweep keeps ``largest_lyapunov``, a second panel below, sharing the
axis, draws the exponent with a line at zero, and its uncertainty as error bars where
the sweep keeps ``largest_lyapunov_uncertainty`` too: a finite-time exponent whose bar
reaches across zero does not tell chaos from a regular motion. Exponents stored as
inconclusive (``largest_lyapunov_inconclusive``: uncertainty unknown or larger than the
exponent) are ringed and named in a legend.
"""

from __future__ import annotations

import json
from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from fivdisc.errors import SweepError, nearest
from fivdisc.files import write_atomic
from fivdisc.sweep.sections import VARIABLES, Section

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from fivdisc.sweep.spec import Sweep

__all__ = ["check_diagram", "diagram_section", "plot_bifurcation"]

_DPI = 150
_DOT = 1.5  # marker size of the section values [pt] where they are many
_FEW = 2_000  # below this many values, markers grow to stay visible


def diagram_section(axes: list[str], sections: list[dict[str, Any]],
                    section: str | None = None) -> dict[str, Any]:
    """The section a diagram draws, after checking that the sweep can give one.

    Parameters
    ----------
    axes
        The swept keys.
    sections
        The sweep's sections, as :meth:`Section.to_dict` gives them.
    section
        Name of the section to draw; None: the first.

    Raises
    ------
    SweepError
        Not exactly one swept key, no section, or no section named `section`.
    """
    if len(axes) != 1:
        raise SweepError(
            f"a bifurcation diagram needs a sweep over one key; this one sweeps "
            f"{len(axes)}: {', '.join(repr(a) for a in axes)}"
        )
    if not sections:
        raise SweepError(
            "a bifurcation diagram needs a section: add a [[reduce.section]] table to the "
            "sweep file (e.g. variable = \"phi_dot\", at = \"maxima\")"
        )
    names = [s["name"] for s in sections]
    if section is None:
        return sections[0]
    if section not in names:
        raise SweepError(f"section = {section!r} is invalid: the sweep's sections are "
                         f"{', '.join(names)}{nearest(section, names)}")
    return sections[names.index(section)]


def check_diagram(spec: Sweep, section: str | None = None) -> dict[str, Any]:
    """:func:`diagram_section` of a sweep, before it runs."""
    return diagram_section(list(spec.axes), [s.to_dict() for s in spec.sections], section)


def plot_bifurcation(
    data: xr.Dataset | str | PathLike[str],
    path: str | PathLike[str] | None = None,
    section: str | None = None,
    name: str | None = None,
    branch=None,
) -> Figure:
    """Draw the bifurcation diagram of a sweep over one key.

    The values of a section at every computed point are small dots over the swept key;
    failed points are marked along the bottom of the panel, points not yet computed are
    left out. If the sweep keeps ``largest_lyapunov``, a second panel shows it, the
    inconclusive values ringed.

    Parameters
    ----------
    data
        A sweep over one key with at least one section (a dataset from
        :func:`~fivdisc.sweep.store.open_sweep`, or the store's path).
    path
        Image file to write (format from its suffix); None only returns the figure.
    section
        Name of the section to draw (default: the sweep's first).
    name
        Name of the case, for the title (default: the store's name without suffix).
    branch : Branch or str, optional
        A branch of periodic orbits in the same key (:func:`fivdisc.continue_orbit`, or
        its netCDF file) to lay over the diagram, stable solid and unstable dashed.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    SweepError
        Not a sweep over one key, no section, or no section named `section`.
    """
    from fivdisc.extras import require
    from fivdisc.sweep.store import open_sweep

    require("plot", "a bifurcation diagram")
    from matplotlib.figure import Figure

    from fivdisc.conventions import axis_label

    if not isinstance(data, xr.Dataset):
        name = name if name is not None else Path(data).stem
        data = open_sweep(data)
    axes = json.loads(data.attrs["sweep_axes"])
    chosen = Section(**diagram_section(axes, json.loads(data.attrs.get("sweep_sections", "[]")),
                                       section))
    key = axes[0]
    x = np.ravel(data[key].values)
    ok = np.ravel(data["done"].values) & (np.ravel(data["error"].values) == "")
    failed = np.ravel(data["done"].values) & ~ok
    values = np.reshape(data[chosen.name].values, (x.size, chosen.max_points))
    counts = np.ravel(data[chosen.count_name].values)
    keep = np.arange(chosen.max_points)[None, :] < counts[:, None]
    keep &= ok[:, None]
    xs = np.broadcast_to(x[:, None], values.shape)[keep]
    ys = values[keep]

    lyapunov = "largest_lyapunov" in data
    fig = Figure(figsize=(7.0, 6.0 if lyapunov else 4.5), layout="constrained")
    if lyapunov:
        top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(2.2, 1.0))
    else:
        top = bottom = fig.add_subplot()
    dot = _DOT if ys.size >= _FEW else _DOT + 3.0 * (1.0 - ys.size / _FEW)
    top.plot(xs, ys, linestyle="none", marker=".", ms=dot, mew=0.0, color="k",
             rasterized=ys.size > 20_000)
    if branch is not None:
        from fivdisc.analysis.branch import Branch, open_branch
        from fivdisc.branch_plots import overlay_branch

        branch = branch if isinstance(branch, Branch) else open_branch(branch)
        overlay_branch(top, branch, key, chosen.variable, chosen.slider or 0,
                       chosen.at == "maxima")
    variable = VARIABLES[chosen.variable]
    label = f"{variable.long_name}{chosen.selection}"
    top.set_ylabel(f"{label} [{variable.units}]" if variable.units != "1" else label)
    if failed.any():
        top.plot(x[failed], np.zeros(failed.sum()), "x", color="tab:red", ms=5,
                 transform=top.get_xaxis_transform(), clip_on=False, label="run failed")
        top.legend(loc="upper left", fontsize="small")
    if lyapunov:
        exponent = np.ravel(data["largest_lyapunov"].values)
        bottom.axhline(0.0, color="0.5", lw=0.8, zorder=1)
        error = (np.ravel(data["largest_lyapunov_uncertainty"].values)[ok]
                 if "largest_lyapunov_uncertainty" in data else None)
        bottom.errorbar(x[ok], exponent[ok], yerr=error, fmt=".-", color="tab:blue", ms=3,
                        lw=0.8, elinewidth=0.6, ecolor="tab:blue", capsize=0)
        if "largest_lyapunov_inconclusive" in data:
            marked = ok & np.ravel(data["largest_lyapunov_inconclusive"].values).astype(bool)
            if marked.any():
                bottom.plot(x[marked], exponent[marked], "o", mfc="none", mec="tab:orange",
                            ms=7, label="inconclusive (uncertainty unknown or above |value|)")
                bottom.legend(loc="best", fontsize="small")
        bottom.set_ylabel("largest Lyapunov\n" r"exponent $\lambda_1$ [1/s]")
    bottom.set_xlabel(axis_label(data[key]))
    fig.align_ylabels()
    if chosen.at == "maxima":
        where = "its local maxima"
    elif variable.dim == "slider":
        where = f"its {chosen.at} switches"
    else:
        where = f"the {chosen.at} switches of slider {chosen.slider}"
    title = (f"{name + ': ' if name else ''}{chosen.variable}{chosen.selection} at {where}, "
             f"t >= {chosen.after:g} s")
    others = [s["name"] for s in json.loads(data.attrs.get("sweep_sections", "[]"))
              if s["name"] != chosen.name]
    if others:  # e.g. one section per slider
        title += f"\n(other sections: {', '.join(others)}; pick one with --section NAME)"
    top.set_title(title, fontsize="medium")
    if path is not None:
        write_atomic(path, lambda p: fig.savefig(p, dpi=_DPI))
    return fig
