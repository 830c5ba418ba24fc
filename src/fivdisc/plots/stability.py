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

__all__ = ["GROWTH_SCALES", "growth_axis", "plot_eigen_branches", "plot_hopf_curves",
           "plot_stability_boundary",
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
    the legend and on the axes. Where the exact boundary is given, it is drawn instead,
    over the shading: the grid's contour, a few cells' linear interpolation of the
    growth rate, would only show beside it where the two disagree. Axes are labelled
    with the keys' descriptions, symbols and units.

    Parameters
    ----------
    ds : xarray.Dataset
        The map's dataset.
    ax : matplotlib Axes, optional
        Where to draw.
    boundary : xarray.Dataset or sequence of them, optional
        Exact boundary curves of :func:`fivdisc.analysis.boundary.stability_boundary`
        over the same keys (one per curve value, with `curve_key`), drawn on top (solid,
        black or the value's colour) in place of the grid's contours.
    """
    xkey, ykey = ds.attrs["x_key"], ds.attrs["y_key"]
    ckey = ds.attrs.get("curve_key", "")
    if ckey:
        check_curves(ds.sizes[ckey], ckey)
    fig, ax = new_axes(ax)
    absent: list[str] = []
    x, y = ds[xkey].values, ds[ykey].values
    panels = [(None, ds)] if not ckey else [(v, ds.sel({ckey: v})) for v in ds[ckey].values]
    exact = [boundary] if isinstance(boundary, xr.Dataset) else list(boundary or [])
    # One exact boundary per panel replaces its grid contour; any other number is laid
    # over every panel.
    per_panel = len(exact) == len(panels)
    from matplotlib import rcParams

    cycle = rcParams["axes.prop_cycle"].by_key()["color"]
    for k, (value, one) in enumerate(panels):
        stable = one["stable"].transpose(ykey, xkey).values.astype(float)
        growth = one["max_growth_rate"].transpose(ykey, xkey).values
        stable[np.isnan(growth)] = np.nan
        if value is None:
            text, color = "", "k"
            # The sign of the interpolated growth rate, so that the shading's edge is the
            # grid's contour, not a staircase of its cells.
            big = float(np.nanmax(np.abs(growth), initial=0.0)) or 1.0
            ax.contourf(x, y, growth, levels=[-2 * big, 0.0, 2 * big],
                        colors=["#c6e5c3", "#f4c7c3"])
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
                big = float(np.nanmax(np.abs(growth), initial=0.0)) or 1.0
                ax.contourf(x, y, growth, levels=[-2 * big, 0.0], colors=[color], alpha=0.15)
        if per_panel:
            _draw_exact(ax, exact[k], xkey, ykey, color, text)
        elif np.isfinite(one["boundary"].values).any():
            ax.contour(x, y, growth, levels=[0.0], colors=[color], linewidths=1.5)
            ax.plot([], [], color=color, lw=1.5,
                    label=f"{text}: boundary, stable shaded" if text else "grid boundary")
        if not np.isfinite(one["boundary"].values).any() and not (
                per_panel and exact[k].sizes.get("point", 0)):
            ok = stable[np.isfinite(stable)]
            state = ("stable throughout" if ok.size and ok.all() else "unstable throughout"
                     if not ok.any() else f"stable at {ok.mean():.0%}, no sign change")
            absent.append(f"{text} ({state})" if text else state)
            if text:
                ax.plot([], [], color=color, lw=8, alpha=0.3, label=f"{text}: {state}")
    if not per_panel:
        for k, one in enumerate(exact):
            _draw_exact(ax, one, xkey, ykey, "k", "", label=k == 0)
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


def _draw_exact(ax: Axes, one: xr.Dataset, xkey: str, ykey: str, color: str, text: str,
                label: bool = True) -> None:
    """The curves of an exact boundary, solid and over the map's shading and contours,
    with a legend entry (``text``: the curve value's) when `label`."""
    for b in np.unique(one["branch"].values):
        sel = one["branch"].values == b
        ax.plot(one[xkey].values[sel], one[ykey].values[sel], color=color, lw=1.5,
                zorder=3)
    if label and one.sizes.get("point", 0):
        ax.plot([], [], color=color, lw=1.5,
                label=f"{text}: exact boundary, stable shaded" if text
                else "exact boundary")


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


#: Scales of the growth-rate axis of :func:`plot_eigen_branches`.
GROWTH_SCALES = ("auto", "linear", "symlog")
# "auto" takes a symmetric-log axis where the largest |growth rate| exceeds this many
# times the typical branch's largest (the median over the branches).
_SYMLOG_RATIO = 30.0


def growth_axis(growth: np.ndarray, scale: str = "auto") -> tuple[str, float]:
    """The growth-rate axis of an eigenvalue-branch figure: ``("linear", 0)`` or
    ``("symlog", linthresh)``.

    ``"auto"`` takes the symmetric-log axis where the largest |growth rate| is more than
    30 times the median over the branches of each one's largest (a 4 1/s instability
    beside 417 1/s is a flat line on a linear axis); its linear part reaches to the
    power of ten below that median, where most branches lie.

    Parameters
    ----------
    growth : ndarray
        ``(values, branches)`` growth rates [1/s] (NaN: no equilibrium).
    scale : str
        One of :data:`GROWTH_SCALES`.
    """
    from fivdisc.analysis.spectra import AnalysisError

    if scale not in GROWTH_SCALES:
        raise AnalysisError(f"growth_scale = {scale!r} is invalid: must be one of "
                            f"{', '.join(GROWTH_SCALES)}")
    peaks = np.nanmax(np.abs(growth), axis=0, initial=0.0) if growth.size else np.zeros(1)
    peaks = peaks[np.isfinite(peaks)]
    typical = float(np.median(peaks)) if peaks.size else 0.0
    top = float(peaks.max(initial=0.0))
    if scale == "linear" or (scale == "auto" and not top > _SYMLOG_RATIO * typical):
        return "linear", 0.0
    floor = typical if typical > 0 else (top if top > 0 else 1.0)
    return "symlog", float(10.0 ** np.floor(np.log10(floor)))


@drawing
def plot_eigen_branches(ds: xr.Dataset, hopf: Sequence | None = None,
                        growth_scale: str = "auto") -> Figure:
    """Frequency and growth rate of every eigenvalue branch against the key
    (:func:`fivdisc.analysis.eigenbranches.eigen_branches`).

    One colour per branch (positive frequencies only: one of each complex pair),
    labelled with its mode in the key beside the axes; where a branch is unstable it is
    drawn thick. Mode couplings are marked with a dotted line, existence limits with a
    solid grey one, and Hopf points (:func:`fivdisc.analysis.hopf.hopf_points`) with
    dots in the colour of the mode that crosses there.

    Parameters
    ----------
    ds : xarray.Dataset
        The branches.
    hopf : sequence of HopfPoint, optional
        Hopf points to mark; by default those stored in `ds` (``hopf``,
        ``hopf_frequency``: ``fivdisc stability --x`` writes them), if any.
    growth_scale : str
        The growth-rate axis: ``"linear"``, ``"symlog"`` (symmetric log, linear near
        zero) or ``"auto"``, symlog where the rates span more than the linear axis
        shows (:func:`growth_axis`).
    """
    import matplotlib.pyplot as plt

    new_axes(None)  # chooses a headless backend where needed
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, layout="constrained",
                                      figsize=(8.0, 6.5))
    key = ds.attrs["x_key"]
    x = ds[key].values
    freq, growth = ds["frequency"].values, ds["growth_rate"].values
    scale, linthresh = growth_axis(growth, growth_scale)
    colors: dict[str, str] = {}  # mode -> its branch's colour
    for b in range(freq.shape[1]):
        if not np.nanmax(freq[:, b], initial=-1.0) > 0.0:
            continue
        (line,) = top.plot(x, freq[:, b], lw=1.0, label=str(ds["mode"].values[b]))
        colors[str(ds["mode"].values[b])] = line.get_color()
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
        marks = [(hp.value, hp.frequency, hp.mode) for hp in hopf]
    elif "hopf" in ds:
        modes = (ds["hopf_mode"].values if "hopf_mode" in ds
                 else np.full(ds.sizes["hopf"], ""))
        marks = list(zip(ds["hopf"].values, ds["hopf_frequency"].values, modes,
                         strict=True))
    else:
        marks = []
    for value, frequency, mode in marks:
        # Filled with its branch's colour: the key names the mode that crosses there.
        face = colors.get(str(mode), "k")
        top.plot(value, frequency, "o", mfc=face, mec="k", ms=6)
        bottom.plot(value, 0.0, "o", mfc=face, mec="k", ms=6)
    bottom.axhline(0.0, color="k", lw=0.5)
    top.set_ylabel("frequency [Hz]")
    if scale == "symlog":
        bottom.set_yscale("symlog", linthresh=linthresh)
        bottom.axhspan(-linthresh, linthresh, color="0.92", zorder=0, lw=0)
        bottom.set_ylabel(f"growth rate [1/s]\n(symmetric log, linear within ±{linthresh:g})")
    else:
        bottom.set_ylabel("growth rate [1/s]")
    bottom.set_xlabel(axis_label(ds[key]))
    # Beside the axes, where it hides no branch.
    fig.legend(*top.get_legend_handles_labels(), loc="outside right upper",
               fontsize="small", title="mode", title_fontsize="small")
    set_title(top, ds, "eigenvalue branches (thick: unstable)",
           detail="dotted: mode coupling; dots: Hopf points, in their mode's colour"
           if len(ds["coupling"]) or marks else "")
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
        # Each segment's style, drawn as runs of one style: dashes restart on every line,
        # so a dashed curve of many short segments, one line each, looked solid.
        styles = [("--" if sub[k] and sub[k + 1] else "-",
                   2.6 if outer[k] and outer[k + 1] else 1.2) for k in range(sel.size - 1)]
        start = 0
        for k in range(1, len(styles) + 1):
            if k == len(styles) or styles[k] != styles[start]:
                ls, lw = styles[start]
                ax.plot(x[sel[start: k + 1]], y[sel[start: k + 1]], color=color, ls=ls,
                        lw=lw)
                start = k
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
