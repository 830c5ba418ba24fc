"""Figures of a branch of periodic orbits (:func:`fivdisc.continue_orbit`): a measure of
the orbits against the continued key, stable solid and unstable dashed, bifurcations
marked and labelled; and the same laid over a brute-force bifurcation diagram."""

from __future__ import annotations

import itertools
from typing import TYPE_CHECKING

import numpy as np

from fivdisc.analysis.cycle import MEASURES
from fivdisc.analysis.kinds import BifurcationKind as Kind
from fivdisc.case import describe_key
from fivdisc.continuation.branch import Branch
from fivdisc.errors import FivdiscError

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["BRANCH_MEASURES", "NARROW", "draw_branch", "draw_equilibrium", "equilibrium_curve",
           "key_label", "narrow_unstable", "plot_branch"]

#: What :func:`plot_branch` can draw: the period, or a measure per slider, as its
#: largest (``_max``) or smallest (``_min``) value over a period, or both (no suffix).
BRANCH_MEASURES = ("period", *MEASURES, *(f"{m}_{e}" for m in MEASURES for e in ("max", "min")))
#: Largest fraction of a branch figure's width and height that :func:`narrow_unstable`
#: calls too short to show dashed.
NARROW = 0.02
# Short labels of the bifurcations on a figure.
_MARKS = {Kind.FOLD: ("LP", "s"), Kind.PERIOD_DOUBLING: ("PD", "D"), Kind.TORUS: ("NS", "o"),
          Kind.BRANCH_POINT: ("BP", "^"), Kind.SIGNATURE_CHANGE: ("DIB", "v"),
          Kind.GRAZING: ("GR", "v"), Kind.STICK_SPLIT: ("SPLIT", "v"),
          Kind.SYMMETRY_BREAKING: ("SB", "P"),
          Kind.SWITCHING_ORDER: ("SO", "v"), Kind.DISCONTINUITY: ("JUMP", "X"),
          Kind.DISCONTINUITY_END: ("END", "X"), Kind.CASCADE_END: ("END", "X"),
          Kind.END: ("LOST", "x"), Kind.GAP: ("GAP", "x")}


def _columns(branch: Branch, measure: str, slider: int) -> list[tuple[str, np.ndarray, str]]:
    """(name, values, unit) of the curves a measure draws."""
    ds = branch.dataset
    if measure not in BRANCH_MEASURES:
        raise FivdiscError(f"measure = {measure!r} is invalid: must be one of "
                           f"{', '.join(BRANCH_MEASURES)}")
    if measure == "period":
        return [("period", ds["period"].values * 1e3, "ms")]
    count = ds.sizes["slider"]
    if not 0 <= slider < count:
        raise FivdiscError(f"slider = {slider} is invalid: the branch has {count} slider"
                           f"{'s' if count > 1 else ''}, numbered from 0")
    names = [measure] if measure.endswith(("_max", "_min")) else [f"{measure}_max",
                                                                   f"{measure}_min"]
    return [(n, ds[n].values[:, slider], ds[n].attrs.get("units", "")) for n in names]


def _spans(x: np.ndarray, curves: list[tuple[str, np.ndarray, str]]) -> tuple[float, float]:
    """The figure's extent in the key and in the measure (1 where a branch has none)."""
    return (float(np.ptp(x)) or 1.0,
            max(float(np.nanmax(y) - np.nanmin(y)) for _, y, _ in curves) or 1.0)


def _narrow_stretches(branch: Branch, curves: list[tuple[str, np.ndarray, str]]
                      ) -> list[tuple[int, int, float, float]]:
    """(first point, end point, start and end of the key) of each unstable stretch of
    :func:`narrow_unstable`."""
    x = branch.parameter
    stable = np.asarray(branch.stable, bool)
    span_x, span_y = _spans(x, curves)
    ends = {b["point"]: b["parameter"] for b in branch.bifurcations()}
    cuts = np.flatnonzero(np.diff(stable.astype(int))) + 1
    found = []
    for a, b in itertools.pairwise(np.r_[0, cuts, x.size]):
        if stable[a]:
            continue
        # The stretch as drawn: from the last stable point before it to the first after.
        drawn = slice(max(a - 1, 0), min(b + 1, x.size))
        wide = np.ptp(x[drawn]) / span_x
        high = max(float(np.ptp(y[drawn])) for _, y, _ in curves) / span_y
        if max(wide, high) < NARROW:
            found.append((int(a), int(b), float(ends.get(a - 1, x[a])),
                          float(ends.get(b - 1, x[b - 1]))))
    return found


def narrow_unstable(branch: Branch, measure: str = "period",
                    slider: int = 0) -> list[tuple[float, float]]:
    """Unstable stretches of a branch too short to show dashed on its figure, each as the
    range of the key it spans (from the located bifurcations that bound it where there
    are, else its first and last points), in the order of the branch.

    A stretch counts when it spans less than :data:`NARROW` of the figure's width and of
    its height (the measure's span): one dash and gap of the unstable line style, at the
    default line width on a figure 7 in wide, take about 1.7 % of the axes."""
    curves = _columns(branch, measure, slider)
    return [(lo, hi) for _, _, lo, hi in _narrow_stretches(branch, curves)]


def draw_branch(ax: Axes, branch: Branch, measure: str = "period", slider: int = 0,
                color: str = "C0", labels: bool = True) -> None:
    """Draw a measure of a branch on existing axes: stable stretches solid, unstable
    dashed, bifurcations marked (LP fold, PD period doubling, NS torus, BP branch point,
    DIB a change of the event signature, GR a grazing) and, with ``labels``, named. The
    points of an unstable stretch too short to show dashed (:func:`narrow_unstable`) are
    marked."""
    x = branch.parameter
    stable = branch.stable
    curves = _columns(branch, measure, slider)
    cuts = np.flatnonzero(np.diff(stable.astype(int))) + 1
    bounds = np.r_[0, cuts, x.size]
    narrow = _narrow_stretches(branch, curves)
    for _name, y, _ in curves:
        # Split where the stability changes; each piece shares its end point with the next.
        for a, b in itertools.pairwise(bounds):
            piece = slice(a, min(b + 1, x.size))
            ax.plot(x[piece], y[piece], color=color, lw=1.4,
                    linestyle="-" if stable[a] else "--")
        for a, b, _, _ in narrow:
            ax.plot(x[a:b], y[a:b], color=color, ls="none", marker="o", ms=2.5)
    # Labels placed so far, in axes fractions of the data's span: one that would land on
    # an earlier one (bifurcations a few thousandths of the span apart) is stacked above.
    span_x, span_y = _spans(x, curves)
    placed: list[tuple[float, float]] = []
    for b in branch.bifurcations():
        label, marker = _MARKS[Kind(b["kind"])]
        i = b["point"]
        j = min(i + 1, x.size - 1)
        for _, y, _ in curves:
            # The value at the bifurcation, between the points that bracket it.
            if x[j] != x[i]:
                frac = np.clip((b["parameter"] - x[i]) / (x[j] - x[i]), 0.0, 1.0)
            else:
                frac = 0.0
            yb = y[i] + frac * (y[j] - y[i])
            ax.plot([b["parameter"]], [yb], marker=marker, color="C3", ms=6, mfc="none",
                    mew=1.3, linestyle="none")
            if labels:
                here = (b["parameter"] / span_x, yb / span_y)
                near = sum(abs(here[0] - u) < 0.03 and abs(here[1] - v) < 0.03
                           for u, v in placed)
                placed.append(here)
                ax.annotate(label, (b["parameter"], yb), textcoords="offset points",
                            xytext=(4, 4 + 9 * near), fontsize=8, color="C3")


def key_label(key: str) -> str:
    """Axis label of a case key: its words, symbol and unit (``disc speed $\\Omega_c$
    [rad/s]``), as the stability figures label their axes."""
    import types

    from fivdisc.engine.conventions import axis_label, key_attrs

    return axis_label(types.SimpleNamespace(attrs=key_attrs(key), name=key))


# Points on which the sliding equilibrium's branch is drawn, and how far beyond the
# branch's range (a fraction of it).
_EQUILIBRIUM_POINTS = 201
_EQUILIBRIUM_MARGIN = 0.05


def equilibrium_curve(branch: Branch, measure: str, slider: int = 0):
    """The sliding equilibrium along a branch's key, over the branch's range (and its
    Hopf point's value): ``(values, measure's value, stable)``, from
    :func:`~fivdisc.analysis.eigenbranches.eigen_branches` (NaN where there is no
    equilibrium). At the equilibrium every measure's largest and smallest values are
    its value; ``phi_dot`` is 0.

    Raises
    ------
    FivdiscError
        The measure is the period (an equilibrium has none), or there is no sliding
        equilibrium at either end of the range.
    """
    from fivdisc.analysis.eigenbranches import eigen_branches
    from fivdisc.errors import CaseError

    if measure == "period":
        raise FivdiscError("the sliding equilibrium has no period: draw its branch with a "
                           "measure such as phi_dot or normal_force")
    base = measure.removesuffix("_max").removesuffix("_min")
    p = branch.parameter
    hopf = branch.hopf()
    ends = [float(p.min()), float(p.max())] + ([hopf["value"]] if hopf else [])
    # A little beyond both ends, so that a Hopf point at one shows the equilibrium's
    # change of stability.
    margin = _EQUILIBRIUM_MARGIN * (max(ends) - min(ends)) or 1e-3 * abs(ends[0] or 1.0)
    lo, hi = min(ends) - margin, max(ends) + margin
    values = np.linspace(lo, hi, _EQUILIBRIUM_POINTS)
    ds = None
    for order in (values, values[::-1]):
        try:
            ds = eigen_branches(branch.case, branch.key, order)
            break
        except CaseError:
            continue
    if ds is None:
        raise FivdiscError(f"no sliding equilibrium at {branch.key} = {lo:.6g} or {hi:.6g}: "
                           "there is no equilibrium branch to draw")
    ds = ds.sortby(branch.key)
    x = ds[branch.key].values
    if base == "phi_dot":
        y = np.where(np.isfinite(ds["phi"].values[:, slider]), 0.0, np.nan)
    else:
        y = ds[base].values[:, slider]
    return x, y, ds["max_growth_rate"].values < 0.0


def draw_equilibrium(ax: Axes, branch: Branch, measure: str, slider: int = 0,
                     color: str = "0.35") -> None:
    """Draw the sliding equilibrium's branch (:func:`equilibrium_curve`) on existing
    axes: stable solid, unstable dashed, its Hopf point (a branch from one) marked."""
    x, y, stable = equilibrium_curve(branch, measure, slider)
    cuts = np.flatnonzero(np.diff(stable.astype(int))) + 1
    for a, b in itertools.pairwise(np.r_[0, cuts, x.size]):
        piece = slice(a, min(b + 1, x.size))
        ax.plot(x[piece], y[piece], color=color, lw=1.2, linestyle="-" if stable[a] else "--")
    hopf = branch.hopf()
    if hopf:
        ax.plot([hopf["value"]], [np.interp(hopf["value"], x, y)], marker="o", color=color,
                ms=6, linestyle="none")
        ax.annotate("H", (hopf["value"], float(np.interp(hopf["value"], x, y))),
                    textcoords="offset points", xytext=(4, -12), fontsize=8, color=color)


def plot_branch(branch: Branch, measure: str = "period", slider: int = 0,
                ax: Axes | None = None, equilibrium: bool = False) -> Figure:
    """A branch of periodic orbits against its key.

    Parameters
    ----------
    branch : Branch
        From :func:`~fivdisc.continuation.walk.continue_orbit` or
        :func:`~fivdisc.continuation.branch.open_branch`.
    measure : str
        One of :data:`BRANCH_MEASURES`: ``"period"`` [ms], or a measure per slider
        (``"phi_dot"``: its largest and smallest value over a period; ``"phi_dot_max"``
        only the largest).
    slider : int
        Which slider's measure.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default: a new figure).
    equilibrium : bool
        Draw the sliding equilibrium's branch too (:func:`draw_equilibrium`: stable
        solid, unstable dashed, in grey), where the orbits of a Hopf point leave it; not
        with the period.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from fivdisc.extras import require

    require("plot", "a branch figure")
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    if ax is None:
        fig = Figure(figsize=(7.0, 4.5), layout="constrained")
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    curves = _columns(branch, measure, slider)
    if equilibrium:
        draw_equilibrium(ax, branch, measure, slider)
    draw_branch(ax, branch, measure, slider)
    ds = branch.dataset
    ax.set_xlabel(key_label(branch.key))
    unit = curves[0][2]
    if measure == "period":
        what = "period"
    else:
        base = measure.removesuffix("_max").removesuffix("_min")
        what = MEASURES[base][0] + ("" if ds.sizes["slider"] == 1 else f", slider {slider}")
        what += {"_max": ", largest", "_min": ", smallest"}.get(measure[-4:], ", range")
    ax.set_ylabel(f"{what} [{unit}]" if unit and unit != "1" else what)
    ax.set_title(f"periodic orbits continued in {describe_key(branch.key).long_name}"
                 + (" with the sliding equilibrium" if equilibrium else ""), fontsize=10)
    what = "periodic orbits, " if equilibrium else ""
    handles = [Line2D([], [], color="C0", ls="-", label=f"{what}stable"),
               Line2D([], [], color="C0", ls="--", label=f"{what}unstable")]
    if equilibrium:
        handles += [Line2D([], [], color="0.35", ls="-", label="sliding equilibrium, stable"),
                    Line2D([], [], color="0.35", ls="--",
                           label="sliding equilibrium, unstable")]
    narrow = narrow_unstable(branch, measure, slider)
    if narrow:
        spans = ", ".join(f"{min(lo, hi):.6g} to {max(lo, hi):.6g}" for lo, hi in narrow)
        handles.append(Line2D([], [], color="C0", ls="none", marker="o", ms=2.5,
                              label=f"unstable, too short to see dashed: {spans}"))
    ax.legend(handles=handles, loc="best", fontsize=8, frameon=False)
    ax.grid(alpha=0.3)
    return fig


def overlay_branch(ax: Axes, branch: Branch, key: str, variable: str, slider: int,
                   maxima: bool) -> None:
    """Lay a branch over a brute-force bifurcation diagram of ``variable`` of ``slider``
    over ``key``: the largest value over a period for a diagram of maxima, else the
    largest and smallest (the span the section's values lie in).

    Raises
    ------
    FivdiscError
        The branch is in another key, or the variable is not one of its measures.
    """
    if branch.key != key:
        raise FivdiscError(f"the branch is continued in {branch.key}, the sweep in {key}: "
                           "they cannot share an axis")
    if variable not in ("phi", "phi_dot", "normal_force"):
        raise FivdiscError(f"a branch keeps phi, phi_dot and normal_force per slider, not the "
                           f"section's variable {variable!r}")
    draw_branch(ax, branch, f"{variable}_max" if maxima else variable, slider, color="C1")
    # Entries of the key the diagram draws.
    ax.plot([], [], color="C1", ls="-", label="periodic orbits, stable")
    ax.plot([], [], color="C1", ls="--", label="periodic orbits, unstable")
