"""Figures of the sliding equilibrium's stability: maps over two keys (paper Fig. 3),
the exact boundary, every Hopf curve with its codimension-two points, and eigenvalue
branches along one key."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from fivdisc.engine.conventions import axis_label
from fivdisc.errors import AnalysisError

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
from fivdisc.plots.text import drawing, new_axes, set_title

__all__ = ["plot_eigen_branches", "plot_hopf_curves", "plot_stability_boundary",
           "plot_stability_map"]


#: Most curves (values of a third key) one stability map figure draws: one colour each,
#: from matplotlib's cycle of ten, and a legend entry each.
MAX_CURVES = 10


def check_curves(count: int, key: str, option: str = "curves") -> None:
    """Refuse a figure of more than :data:`MAX_CURVES` curves, which it could not tell
    apart (their colours repeat) nor name (the legend overflows the axes).

    Raises
    ------
    AnalysisError
        Naming `option`, the count and what is allowed.
    """
    if count > MAX_CURVES:
        raise AnalysisError(
            f"{option} = {key} with {count} values is invalid for a figure: must have at "
            f"most {MAX_CURVES} (one colour and legend entry each; more repeat the colours "
            "and overflow the legend); write the map to a .nc file for more"
        )


@drawing
def plot_stability_map(ds: xr.Dataset, ax: Axes | None = None,
                       boundary: xr.Dataset | Sequence[xr.Dataset] | None = None) -> Figure:
    """Stability map of :func:`fivdisc.analysis.stability.stability_map` (paper Fig. 3).

    The field is always drawn: with one map the grid is shaded stable against unstable;
    with several (a ``curve_key``), each value of the third key shades the region where
    it is stable, in its colour. The grid's boundary (where the growth rate changes
    sign, either way) is drawn as a contour; a value, or a map, without one says so in
    the legend and on the axes. Axes are labelled with the keys' descriptions, symbols
    and units.

    Parameters
    ----------
    ds : xarray.Dataset
        The map's dataset.
    ax : matplotlib Axes, optional
        Where to draw.
    boundary : xarray.Dataset or sequence of them, optional
        Exact boundary curves of :func:`fivdisc.analysis.boundary.stability_boundary`
        over the same keys (one per curve value, with `curve_key`), drawn on top
        (black, dashed).
    """
    xkey, ykey = ds.attrs["x_key"], ds.attrs["y_key"]
    ckey = ds.attrs.get("curve_key", "")
    if ckey:
        check_curves(ds.sizes[ckey], ckey)
    fig, ax = new_axes(ax)
    absent: list[str] = []
    x, y = ds[xkey].values, ds[ykey].values
    panels = [(None, ds)] if not ckey else [(v, ds.sel({ckey: v})) for v in ds[ckey].values]
    from matplotlib import rcParams

    cycle = rcParams["axes.prop_cycle"].by_key()["color"]
    for value, one in panels:
        stable = one["stable"].transpose(ykey, xkey).values.astype(float)
        growth = one["max_growth_rate"].transpose(ykey, xkey).values
        stable[np.isnan(growth)] = np.nan
        if value is None:
            text, color = "", "k"
            ax.contourf(x, y, stable, levels=[-0.5, 0.5, 1.5], colors=["#f4c7c3", "#c6e5c3"])
            ax.plot([], [], color="#c6e5c3", lw=8, label="stable")
            ax.plot([], [], color="#f4c7c3", lw=8, label="unstable")
        else:
            coord = ds[ckey]
            symbol = coord.attrs.get("symbol", "")
            units = coord.attrs.get("units", "")
            unit = f" {units}" if units and units != "1" else ""
            text = f"${symbol}$ = {value:g}{unit}" if symbol else f"{ckey} = {value:g}{unit}"
            color = cycle[list(ds[ckey].values).index(value) % len(cycle)]
            if np.nanmax(stable, initial=0.0) > 0.5:
                ax.contourf(x, y, stable, levels=[0.5, 1.5], colors=[color], alpha=0.15)
        if np.isfinite(one["boundary"].values).any():
            ax.contour(x, y, growth, levels=[0.0], colors=[color], linewidths=1.5)
            ax.plot([], [], color=color, lw=1.5,
                    label=f"{text}: boundary, stable shaded" if text else "grid boundary")
        else:
            ok = stable[np.isfinite(stable)]
            state = ("stable throughout" if ok.size and ok.all() else "unstable throughout"
                     if not ok.any() else f"stable at {ok.mean():.0%}, no sign change")
            absent.append(f"{text} ({state})" if text else state)
            if text:
                ax.plot([], [], color=color, lw=8, alpha=0.3, label=f"{text}: {state}")
    exact = [boundary] if isinstance(boundary, xr.Dataset) else list(boundary or [])
    for k, one in enumerate(exact):
        for b in np.unique(one["branch"].values):
            sel = one["branch"].values == b
            ax.plot(one[xkey].values[sel], one[ykey].values[sel], color="k", lw=1.0,
                    ls="--", label="exact boundary" if k == b == 0 else None)
    ax.set_xlabel(axis_label(ds[xkey]))
    ax.set_ylabel(axis_label(ds[ykey]))
    ax.set_xlim(x[0], x[-1])
    ax.set_ylim(y[0], y[-1])
    if absent and len(absent) == len(panels):
        ax.text(0.5, 0.5, "no stability boundary in the grid", transform=ax.transAxes,
                ha="center", va="center", fontsize="large", alpha=0.6)
    if ax.get_legend_handles_labels()[1]:
        ax.legend(loc="best", fontsize="small")
    what = ("stable regions shaded, one colour per curve" if ckey
            else "stability of the sliding equilibrium")
    set_title(ax, ds, what, detail="no boundary in the grid: " + ", ".join(absent) if absent
           else "")
    return fig


@drawing
def plot_stability_boundary(ds: xr.Dataset, ax: Axes | None = None) -> Figure:
    """The curves of :func:`fivdisc.analysis.boundary.stability_boundary` in their box,
    each labelled with its critical mode and frequency.

    Parameters
    ----------
    ds : xarray.Dataset
        The boundary's dataset.
    ax : matplotlib Axes, optional
        Where to draw.
    """
    fig, ax = new_axes(ax)
    xkey, ykey = ds.attrs["x_key"], ds.attrs["y_key"]
    for b in np.unique(ds["branch"].values):
        sel = ds["branch"].values == b
        modes = ", ".join(dict.fromkeys(ds["mode"].values[sel]))
        ax.plot(ds[xkey].values[sel], ds[ykey].values[sel], lw=1.5,
                label=f"{modes}, {np.median(ds['frequency'].values[sel]):.1f} Hz")
    ax.set_xlim(*ds.attrs["x_range"])
    ax.set_ylim(*ds.attrs["y_range"])
    ax.set_xlabel(axis_label(ds[xkey]))
    ax.set_ylabel(axis_label(ds[ykey]))
    if ds.sizes["point"]:
        ax.legend(loc="best", fontsize="small")
    else:
        ax.text(0.5, 0.5, "no stability boundary in the box", transform=ax.transAxes,
                ha="center", va="center", fontsize="large", alpha=0.6)
    set_title(ax, ds, "exact stability boundary")
    return fig


@drawing
def plot_eigen_branches(ds: xr.Dataset, hopf: Sequence | None = None) -> Figure:
    """Frequency and growth rate of every eigenvalue branch against the key
    (:func:`fivdisc.analysis.eigenbranches.eigen_branches`).

    One colour per branch (positive frequencies only: one of each complex pair); where a
    branch is unstable it is drawn thick. Mode couplings are marked with a dotted line,
    existence limits with a solid grey one, and Hopf points
    (:func:`fivdisc.analysis.hopf.hopf_points`) with dots.

    Parameters
    ----------
    ds : xarray.Dataset
        The branches.
    hopf : sequence of HopfPoint, optional
        Hopf points to mark; by default those stored in `ds` (``hopf``,
        ``hopf_frequency``: ``fivdisc stability --x`` writes them), if any.
    """
    import matplotlib.pyplot as plt

    new_axes(None)  # chooses a headless backend where needed
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, layout="constrained",
                                      figsize=(7.0, 6.5))
    key = ds.attrs["x_key"]
    x = ds[key].values
    freq, growth = ds["frequency"].values, ds["growth_rate"].values
    for b in range(freq.shape[1]):
        if not np.nanmax(freq[:, b], initial=-1.0) > 0.0:
            continue
        (line,) = top.plot(x, freq[:, b], lw=1.0, label=str(ds["mode"].values[b]))
        bottom.plot(x, growth[:, b], lw=1.0, color=line.get_color())
        bad = np.where(growth[:, b] > 0.0, growth[:, b], np.nan)
        top.plot(x, np.where(growth[:, b] > 0.0, freq[:, b], np.nan), lw=3.5,
                 color=line.get_color(), alpha=0.6)
        bottom.plot(x, bad, lw=3.5, color=line.get_color(), alpha=0.6)
    for ax in (top, bottom):
        for value in ds["coupling"].values:
            ax.axvline(value, color="0.4", ls=":", lw=1.0)
        for value in ds["existence_limit"].values:
            ax.axvline(value, color="0.5", lw=2.0)
    if hopf is not None:
        marks = [(hp.value, hp.frequency) for hp in hopf]
    else:
        marks = list(zip(ds["hopf"].values, ds["hopf_frequency"].values, strict=True)
                     ) if "hopf" in ds else []
    for value, frequency in marks:
        top.plot(value, frequency, "ko", ms=5)
        bottom.plot(value, 0.0, "ko", ms=5)
    bottom.axhline(0.0, color="k", lw=0.5)
    top.set_ylabel("frequency [Hz]")
    bottom.set_ylabel("growth rate [1/s]")
    bottom.set_xlabel(axis_label(ds[key]))
    top.legend(loc="best", fontsize="small", ncols=2)
    set_title(top, ds, "eigenvalue branches (thick: unstable)",
           detail="dotted: mode coupling; dots: Hopf points" if len(ds["coupling"]) or marks
           else "")
    return fig


# Markers of the codimension-two points of plot_hopf_curves: marker, label, abbreviation.
_CODIM2 = {"bautin": ("*", "Bautin (l1 = 0)", "GH"), "double_hopf": ("s", "double Hopf", "HH"),
           "zero_hopf": ("^", "zero-Hopf", "ZH"),
           "existence": ("X", "equilibrium ceases to exist", "E")}


@drawing
def plot_hopf_curves(ds: xr.Dataset, ax: Axes | None = None,
                     grid: xr.Dataset | None = None) -> Figure:
    """Every Hopf curve of :func:`fivdisc.analysis.codimension.hopf_curves` with its
    codimension-two points.

    One colour per mode, labelled with its frequencies; solid where the Hopf
    point is supercritical (``l1 < 0``), dashed where subcritical (``l1 > 0``: sliding
    is stable on one side but a large enough disturbance starts a vibration), thick
    where the curve is the outer stability boundary. Bautin (GH), double Hopf (HH),
    zero-Hopf (ZH) points and the ends of the equilibrium's existence (E) are marked
    and named; the limit of existence is drawn in grey.

    Parameters
    ----------
    ds : xarray.Dataset
        The curves' dataset.
    ax : matplotlib Axes, optional
        Where to draw.
    grid : xarray.Dataset, optional
        A :func:`fivdisc.analysis.stability.stability_map` over the same keys: its
        stable and unstable regions are shaded underneath.
    """
    fig, ax = new_axes(ax)
    xkey, ykey = ds.attrs["x_key"], ds.attrs["y_key"]
    if grid is not None:
        stable = grid["stable"].transpose(ykey, xkey).values.astype(float)
        stable[np.isnan(grid["max_growth_rate"].transpose(ykey, xkey).values)] = np.nan
        ax.contourf(grid[xkey].values, grid[ykey].values, stable, levels=[-0.5, 0.5, 1.5],
                    colors=["#f4c7c3", "#c6e5c3"])
        ax.plot([], [], color="#c6e5c3", lw=8, label="sliding stable")
        ax.plot([], [], color="#f4c7c3", lw=8, label="sliding unstable")
    x, y = ds[xkey].values, ds[ykey].values
    from matplotlib import rcParams

    cycle = rcParams["axes.prop_cycle"].by_key()["color"]
    # One colour and one legend entry per mode (identical sliders give several curves of
    # nearly one frequency).
    modes = list(dict.fromkeys(str(m) for m in ds["curve_mode"].values))
    for k, mode in enumerate(modes):
        sel = np.isin(ds["hopf_curve"].values,
                      np.flatnonzero(ds["curve_mode"].values == mode))
        freq = ds["frequency"].values[sel]
        span = (f"{np.median(freq):.5g} Hz" if np.ptp(freq) < 5e-4 * freq.max()
                else f"{freq.min():.4g}-{freq.max():.4g} Hz")
        ax.plot([], [], lw=1.5, color=cycle[k % len(cycle)], label=f"{mode}, {span}")
    for c in range(ds.sizes["curve_index"]):
        sel = np.flatnonzero(ds["hopf_curve"].values == c)
        color = cycle[modes.index(str(ds["curve_mode"].values[c])) % len(cycle)]
        sub = ds["l1"].values[sel] > 0.0
        outer = ds["on_boundary"].values[sel].astype(bool)
        for k in range(sel.size - 1):
            i, j = sel[k], sel[k + 1]
            ax.plot(x[[i, j]], y[[i, j]], color=color, ls="--" if sub[k] and sub[k + 1]
                    else "-", lw=2.6 if outer[k] and outer[k + 1] else 1.2)
    if ds.sizes["curve_index"]:
        ax.plot([], [], color="0.3", lw=1.2, label="supercritical (l1 < 0)")
        ax.plot([], [], color="0.3", lw=1.2, ls="--", label="subcritical (l1 > 0)")
        ax.plot([], [], color="0.3", lw=2.6, label="on the stability boundary")
    ex = ds["existence_branch"].values
    for b in np.unique(ex):
        sel = ex == b
        ax.plot(ds["existence_x"].values[sel], ds["existence_y"].values[sel], color="0.5",
                lw=2.0, label="limit of existence" if b == ex.min() else None)
    kinds = ds["codim2_kind"].values
    for kind, (marker, name, short) in _CODIM2.items():
        sel = np.flatnonzero(kinds == kind)
        if not sel.size:
            continue
        ax.plot(ds["codim2_x"].values[sel], ds["codim2_y"].values[sel], marker, ms=10,
                color="k", mfc="gold" if kind == "bautin" else "w", label=f"{short}: {name}")
        for i in sel:
            ax.annotate(short, (ds["codim2_x"].values[i], ds["codim2_y"].values[i]),
                        xytext=(6, 6), textcoords="offset points", fontsize="small")
    ax.set_xlim(*ds.attrs["x_range"])
    ax.set_ylim(*ds.attrs["y_range"])
    ax.set_xlabel(axis_label(ds[xkey]))
    ax.set_ylabel(axis_label(ds[ykey]))
    if not ds.sizes["curve_index"]:
        ax.text(0.5, 0.5, "no Hopf curve in the box", transform=ax.transAxes,
                ha="center", va="center", fontsize="large", alpha=0.6)
    ax.legend(loc="best", fontsize="small")
    set_title(ax, ds, "Hopf curves of the sliding equilibrium",
              detail="dashed: subcritical, where sliding is stable but not safe")
    return fig
