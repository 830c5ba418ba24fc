"""Figures of sweeps: the bifurcation diagram over one swept key and the separation map
over two (paper Fig. 27)."""

from __future__ import annotations

import json
from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from fivdisc.errors import SweepError
from fivdisc.files import write_atomic
from fivdisc.sweep.bifurcation import diagram_section
from fivdisc.sweep.sections import VARIABLES, Section

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["plot_bifurcation", "plot_separation_map"]

_DPI = 150
_DOT = 1.5  # marker size of the section values [pt] where they are many
_FEW = 2_000  # below this many values, markers grow to stay visible
_LABELS = {
    ("decelerating", "speed.initial"): r"initial disc speed $\Omega_0$ [rad/s]",
    ("decelerating", "speed.duration"): r"time to stop $t_{\max}$ [s]",
    ("accelerating", "speed.initial"): r"initial disc speed $\Omega_1$ [rad/s]",
    ("accelerating", "speed.rate"): r"acceleration $c$ [rad/s$^2$]",
}


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
        :func:`~fivdisc.sweep.store.sweep_store.open_sweep`, or the store's path).
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
    from fivdisc.engine.conventions import axis_label
    from fivdisc.extras import require
    from fivdisc.sweep.store.sweep_store import open_sweep

    require("plot", "a bifurcation diagram")
    from matplotlib.figure import Figure


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
    # The key's entry for the dots, with a marker large enough to see in it.
    top.plot([], [], linestyle="none", marker=".", ms=8, color="k",
             label=f"{chosen.variable}{chosen.selection} at the section, one dot per value")
    if branch is not None:
        from fivdisc.continuation.branch import Branch, open_branch
        from fivdisc.plots.branch import overlay_branch

        branch = branch if isinstance(branch, Branch) else open_branch(branch)
        overlay_branch(top, branch, key, chosen.variable, chosen.slider or 0,
                       chosen.at == "maxima")
    variable = VARIABLES[chosen.variable]
    label = f"{variable.long_name}{chosen.selection}"
    top.set_ylabel(f"{label} [{variable.units}]" if variable.units != "1" else label)
    if failed.any():
        top.plot(x[failed], np.zeros(failed.sum()), "x", color="tab:red", ms=5,
                 transform=top.get_xaxis_transform(), clip_on=False, label="run failed")
    top.legend(loc="upper left", fontsize="small", framealpha=0.9)
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


def _profile_of(grid: xr.Dataset) -> str:
    """Speed profile of the sweep's base case."""
    return json.loads(grid.attrs["sweep_definition"])["base"]["speed"]["profile"]


def plot_separation_map(
    data: xr.Dataset | str | PathLike[str], path: str | PathLike[str] | None = None,
    ax: Axes | None = None,
) -> Figure:
    """Draw a separation map like the paper's Fig. 27.

    Separated points are filled markers over a shaded separation region (SR); points
    without separation are open markers, failed points crosses, and points not yet
    computed are left out.

    Parameters
    ----------
    data
        A two-axis grid sweep keeping ``separated`` (a dataset from
        :func:`~fivdisc.sweep.store.sweep_store.open_sweep`, or the store's path).
    path
        Image file to write (format from its suffix); None only returns the figure.
    ax
        Axes to draw into (the legend then goes into them); None: a new figure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from fivdisc.engine.conventions import axis_label
    from fivdisc.extras import require
    from fivdisc.sweep.store.sweep_store import open_sweep

    require("plot", "a separation map")
    from matplotlib.figure import Figure

    grid = data if isinstance(data, xr.Dataset) else open_sweep(data)
    if len(grid.dims) != 2 or "separated" not in grid or grid.attrs.get("sweep_mode") != "grid":
        raise SweepError(
            "a separation map needs a grid sweep over two axes keeping 'separated'; got "
            f"dimensions {list(grid.dims)} and variables {list(grid.data_vars)}"
        )
    x_key, y_key = json.loads(grid.attrs["sweep_axes"])
    grid = grid.transpose(x_key, y_key)
    profile = _profile_of(grid)
    xs, ys = grid[x_key].values, grid[y_key].values
    done = grid["done"].values.astype(bool)
    failed = done & (grid["error"].values != "")
    separated = done & ~failed & grid["separated"].values.astype(bool)
    clear = done & ~failed & ~separated
    X, Y = np.meshgrid(xs, ys, indexing="ij")

    if ax is None:
        fig = Figure(figsize=(6.0, 4.8), layout="constrained")
        ax = fig.add_subplot()
        legend = fig
    else:
        fig = ax.figure
        legend = ax
    if separated.any() and len(xs) > 1 and len(ys) > 1:
        ax.contourf(X, Y, separated.astype(float), levels=[0.5, 1.5], colors=["0.85"])
        ax.contour(X, Y, separated.astype(float), levels=[0.5], colors=["0.3"], linewidths=1.0)
    marker = float(np.clip(60.0 / max(len(xs), len(ys)), 2.0, 7.0))
    ax.plot(X[separated], Y[separated], "o", color="k", ms=marker, label="separation")
    ax.plot(X[clear], Y[clear], "o", mfc="none", color="0.4", ms=marker, label="no separation")
    if failed.any():
        ax.plot(X[failed], Y[failed], "x", color="tab:red", ms=marker, label="run failed")
    if separated.any():
        # under the markers, so that it hides none
        ax.text(
            X[separated].mean(),
            Y[separated].mean(),
            "SR",
            ha="center",
            va="center",
            fontsize=14,
            fontweight="bold",
            color="0.45",
            zorder=1,
        )
    for key, set_label in ((x_key, ax.set_xlabel), (y_key, ax.set_ylabel)):
        set_label(_LABELS.get((profile, key), axis_label(grid[key])))
    # Half a grid step around the points, so that markers on the edges show whole.
    for values, set_lim in ((xs, ax.set_xlim), (ys, ax.set_ylim)):
        pad = 0.5 * (values.max() - values.min()) / max(len(values) - 1, 1) or 0.5
        set_lim(values.min() - pad, values.max() + pad)
    name = grid.attrs.get("case_name", "")
    ax.set_title(f"{name + ': ' if name else ''}separation region (SR), {profile} disc",
                 fontsize="medium")
    if legend is fig:
        # Outside the axes, so that it hides no point.
        fig.legend(loc="outside upper center", ncol=3, fontsize="small", frameon=False)
    else:
        ax.legend(loc="upper left", fontsize="small", framealpha=0.9)
    if path is not None:
        write_atomic(path, lambda p: fig.savefig(p, dpi=_DPI))
    return fig
