"""Figures in two keys of the orbits' bifurcations: one bifurcation curve
(:func:`fivdisc.continuation.codim2.bifurcation_curve`) and the bistable region
(:func:`fivdisc.continuation.region.bistable_region`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from fivdisc.analysis.kinds import BifurcationKind as Kind
from fivdisc.plots.branch import key_label
from fivdisc.plots.text import drawing, new_axes, set_title

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from fivdisc.continuation.codim2 import BifurcationCurve

__all__ = ["plot_bifurcation_curve", "plot_bistable_region"]

# Region code: colour and legend entry.
_SHADES = {-1: ("#dddddd", "undetermined (the vibration's end not followed there)"),
           0: ("#c6e5c3", "sliding stable, no vibration"),
           1: ("#f7d08a", "bistable: sliding stable, a large kick starts a stable vibration"),
           2: ("#f4c7c3", "sliding unstable")}


@drawing
def plot_bifurcation_curve(curve: BifurcationCurve, ax: Axes | None = None) -> Figure:
    """A bifurcation followed in two keys: the second key against the first, a marker
    per point, filled where the orbit is stable.

    Parameters
    ----------
    curve : BifurcationCurve
        From :func:`fivdisc.continuation.codim2.bifurcation_curve` or
        :func:`~fivdisc.continuation.codim2.open_curve`.
    ax : matplotlib Axes, optional
        Where to draw.
    """
    fig, ax = new_axes(ax)
    x, y = curve.parameter, curve.second_parameter
    ax.plot(x, y, "-", color="C0", lw=1.5, label=f"{curve.kind} curve")
    stable = curve.stable.astype(bool)
    ax.plot(x[stable], y[stable], "o", color="C0", ms=4, label="orbit stable")
    ax.plot(x[~stable], y[~stable], "o", mfc="w", color="C0", ms=4, label="orbit unstable")
    ax.set_xlabel(key_label(curve.key))
    ax.set_ylabel(key_label(curve.key2))
    ax.legend(loc="best", fontsize="small")
    set_title(ax, curve.dataset, f"{curve.kind} of periodic orbits in two keys",
              detail=f"largest |condition| {np.abs(curve.condition).max():.1e}")
    return fig


@drawing
def plot_bistable_region(ds: xr.Dataset, ax: Axes | None = None) -> Figure:
    """The bistable region of :func:`fivdisc.continuation.region.bistable_region`.

    The grid shaded by region (sliding unstable; bistable, where sliding is stable and
    a large enough kick starts a stable vibration; sliding stable only; undetermined);
    the Hopf curves where they bound the stable sliding (dashed where subcritical, solid
    where supercritical), the curve where the stable vibration ends (thick, named by its
    kind: fold of cycles or grazing) and, if followed, where the threshold orbits from
    the Hopf point end (thin); the Bautin points (GH).

    Parameters
    ----------
    ds : xarray.Dataset
        The region's dataset (or its file's, ``fivdisc bistable -o``).
    ax : matplotlib Axes, optional
        Where to draw.
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap

    fig, ax = new_axes(ax, figsize=(7.5, 5.0))
    xkey, ykey = ds.attrs["x_key"], ds.attrs["y_key"]
    xs, ys = ds[xkey].values, ds[ykey].values
    codes = sorted(_SHADES)
    cmap = ListedColormap([_SHADES[c][0] for c in codes])
    norm = BoundaryNorm(np.arange(codes[0] - 0.5, codes[-1] + 1.0), cmap.N)
    ax.pcolormesh(xs, ys, ds["region"].values, cmap=cmap, norm=norm, shading="nearest")
    present = set(np.unique(ds["region"].values).tolist())
    for c in codes:
        if c in present:
            ax.plot([], [], color=_SHADES[c][0], lw=8, label=_SHADES[c][1])
    hx, hy = ds["hopf_x"].values, ds["hopf_y"].values
    outer = ds["hopf_on_boundary"].values.astype(bool)
    sub = ds["hopf_l1"].values > 0.0
    curve = ds["hopf_curve"].values
    # Segments between consecutive points of one curve on the boundary, dashed where both
    # ends are subcritical; consecutive segments of one style drawn as one line (a dash
    # pattern restarts at every line: drawn one by one, short ones would look solid).
    lines: list[tuple[str, list[int]]] = []
    for k in range(hx.size - 1):
        if curve[k] != curve[k + 1] or not (outer[k] and outer[k + 1]):
            continue
        style = "--" if sub[k] and sub[k + 1] else "-"
        if lines and lines[-1][0] == style and lines[-1][1][-1] == k:
            lines[-1][1].append(k + 1)
        else:
            lines.append((style, [k, k + 1]))
    drawn = set()
    for style, run in lines:
        label = "Hopf, subcritical" if style == "--" else "Hopf, supercritical"
        ax.plot(hx[run], hy[run], style, color="C3", lw=2.0,
                label=None if label in drawn else label)
        drawn.add(label)
    names = {Kind.FOLD: "fold of cycles", Kind.GRAZING: "grazing",
             Kind.STICK_SPLIT: "stick split"}
    for c in range(ds.sizes["curve"]):
        sel = ds["curve"].values == c
        role = str(ds["curve_role"].values[c])
        kind = names.get(str(ds["curve_kind"].values[c]), str(ds["curve_kind"].values[c]))
        main = role == "vibration end"
        ax.plot(ds["curve_x"].values[sel], ds["curve_y"].values[sel], "-" if main else ":",
                color="k" if main else "C0", lw=2.4 if main else 1.5, marker=".",
                label=(f"stable vibration ends ({kind})" if main
                       else f"threshold orbits end ({kind})"))
    # The Bautin points, where the Hopf curve turns from super- to subcritical (each once:
    # hopf_curves finds one from every curve through it); double Hopf points are left to
    # plot_hopf_curves (identical pads give one per seed line, which would hide the rest).
    sel = np.flatnonzero(ds["special_kind"].values == "bautin")
    points = {(round(float(ds["special_x"].values[i]), 6),
               round(float(ds["special_y"].values[i]), 9)) for i in sel}
    for k, (x, y) in enumerate(sorted(points)):
        ax.plot(x, y, "*", ms=12, color="k", mfc="gold",
                label="GH: Bautin point (l1 = 0)" if k == 0 else None)
        ax.annotate("GH", (x, y), xytext=(5, 5), textcoords="offset points",
                    fontsize="small")
    ax.set_xlim(*ds.attrs["x_range"])
    ax.set_ylim(*ds.attrs["y_range"])
    ax.set_xlabel(key_label(xkey))
    ax.set_ylabel(key_label(ykey))
    ax.legend(loc="best", fontsize="x-small", framealpha=0.85)
    set_title(ax, ds, "where stable sliding and a stable vibration coexist",
              detail="bistable: the eigenvalues say stable, a large kick says otherwise")
    return fig
