"""Fig. 3 of the paper: the stability map."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from fivdisc.analysis import linear_stability, stability_map
from fivdisc.analysis.boundary import stability_boundary
from fivdisc.case import Case
from fivdisc.paper.cases import FIGURES, PaperCase
from fivdisc.paper.rows import stability_row, verdict_of
from fivdisc.paper.runs import Row, Runs, labels_of

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def map_compute(pc: PaperCase, runs: Runs) -> tuple[xr.DataTree, list[Row]]:
    (xkey, xs), (ykey, ys), (ckey, cs) = pc.axes
    maps = {label: stability_map(case, x=(xkey, xs), y=(ykey, ys), curves=(ckey, cs))
            for label, case in pc.runs.items()}
    table = []
    for label, case in pc.runs.items():
        for alpha in cs:
            one = maps[label].sel({ckey: alpha})
            stable = one["stable"].values.astype(bool)
            bound = one["boundary"].values
            cols = np.flatnonzero(np.isfinite(bound))
            if cols.size == 0:
                # The values of alpha are this module's choice (see FIG3.choices), so a
                # value without a stable region is a measurement, not a disagreement.
                where = ("stable everywhere in the grid" if stable.all() else
                         "no boundary in the grid (stable at "
                         f"{100 * stable.mean():.0f} % of its points)")
                table.append(Row(pc.figure, f"{label}: Omega_c = {case.speed.value:g} rad/s, "
                                 f"alpha = {alpha:g}: boundary", "a curve, 'stable' above it",
                                 where))
                continue
            above = [bool(stable[ys > bound[i], i].all()) for i in cols]
            table.append(Row(
                pc.figure,
                f"{label}: Omega_c = {case.speed.value:g} rad/s, alpha = {alpha:g}: boundary",
                "a curve, 'stable' above it",
                f"boundary for c_z = {xs[cols[0]]:.2f}-{xs[cols[-1]]:.2f} N s/m, "
                f"r0^2 c_phi from {np.nanmax(bound):.2f} down to {np.nanmin(bound):.2f} "
                f"N m s/rad; stable above it in {sum(above)} of {cols.size} columns",
                verdict=verdict_of(all(above))))
    groups: dict[str, xr.Dataset] = {}
    for label, case in pc.runs.items():
        for i, alpha in enumerate(cs):
            exact = stability_boundary(case.replace({ckey: float(alpha)}),
                                       (xkey, (xs[0], xs[-1])), (ykey, (ys[0], ys[-1])))
            exact.attrs["curve_value"] = float(alpha)
            groups[f"{label}/boundary{i}"] = exact
            table.append(_exact_boundary_row(pc.figure, case, alpha, exact))
    for fig in (4, 6):
        point = FIGURES[fig].case
        table.append(stability_row(
            pc.figure, point, "stable",
            f"point of Fig. {fig} (c_z = {point.slider.normal_damping:g}, r0^2 c_phi = "
            f"{point.slider.rotational_damping:g}, alpha = {point.friction.decay:g}, "
            f"Omega_c = {point.speed.value:g})"))
        label = next(lb for lb, c in pc.runs.items() if c.speed.value == point.speed.value)
        i = list(cs).index(point.friction.decay)
        table.append(_point_against_boundary(pc.figure, fig, point,
                                             groups[f"{label}/boundary{i}"]))
    for label, one in maps.items():
        one.attrs["case_name"] = f"{pc.stem}{label}"
    return xr.DataTree.from_dict({**maps, **groups}), table


def _exact_boundary_row(figure: int, case: Case, alpha: float, exact: xr.Dataset) -> Row:
    """The traced boundary of one curve of Fig. 3, in words."""
    xkey, ykey = exact.attrs["x_key"], exact.attrs["y_key"]
    what = (f"Omega_c = {case.speed.value:g} rad/s, alpha = {alpha:g}: exact boundary "
            "(Hopf curves)")
    if exact.sizes["point"] == 0:
        return Row(figure, what, "a curve, 'stable' above it", "no boundary in the box")
    x, y = exact[xkey].values, exact[ykey].values
    modes = ", ".join(dict.fromkeys(exact["mode"].values))
    return Row(figure, what, "a curve, 'stable' above it",
               f"{exact.sizes['curve']} curve(s), r0^2 c_phi = {y[np.argmin(x)]:.3f} at c_z = "
               f"{x.min():.3f} to {y[np.argmax(x)]:.3f} at c_z = {x.max():.3f}; critical "
               f"mode {modes} at {np.median(exact['frequency'].values):.2f} Hz")


def _point_against_boundary(figure: int, fig: int, point: Case, exact: xr.Dataset) -> Row:
    """Where a stable point of the paper lies against the traced boundary: the boundary's
    r0^2 c_phi at the point's c_z, which the paper's 'stable above' puts below it."""
    xkey, ykey = exact.attrs["x_key"], exact.attrs["y_key"]
    cz, cphi = point.slider.normal_damping, point.slider.rotational_damping
    x, y = exact[xkey].values, exact[ykey].values
    crossings = [y[i] + (y[i + 1] - y[i]) * (cz - x[i]) / (x[i + 1] - x[i])
                 for i in range(x.size - 1)
                 if exact["branch"].values[i] == exact["branch"].values[i + 1]
                 and (x[i] - cz) * (x[i + 1] - cz) <= 0 and x[i] != x[i + 1]]
    paper = f"({cz:g}, {cphi:g}) of Fig. {fig} above the curve (stable)"
    what = f"exact boundary at the c_z of Fig. {fig} (alpha = {point.friction.decay:g})"
    if not crossings:
        return Row(figure, what, paper, "no boundary at this c_z in the box",
                   verdict=verdict_of(linear_stability(point).stable))
    top = max(crossings)
    return Row(figure, what, paper,
               f"r0^2 c_phi = {top:.4f} N m s/rad on the boundary: the point lies "
               f"{'above' if cphi > top else 'below'} it", verdict=verdict_of(cphi > top))


def map_plot(data: xr.DataTree) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.plots.stability import plot_stability_map

    labels = labels_of(data)
    fig = Figure(figsize=(12, 5.5), layout="constrained")
    axes = fig.subplots(1, len(labels))
    for ax, label in zip(axes, labels, strict=True):
        panel = data[label].to_dataset()
        plot_stability_map(panel, ax=ax,
                           boundary=[child.to_dataset(inherit=False)
                                     for child in data[label].children.values()])
        speed = Case.from_toml(panel.attrs["case"]).speed.value
        for fig_no in (4, 6):
            case = FIGURES[fig_no].case
            if np.isclose(case.speed.value, speed):
                ax.plot(case.slider.normal_damping, case.slider.rotational_damping, "k*",
                        ms=10, label=rf"Fig. {fig_no} ($\alpha$ = {case.friction.decay:g} s/m)")
        ax.legend(loc="upper right", fontsize="small")
        absent = [line for line in ax.get_title().split("\n") if line.startswith("no boundary")]
        ax.set_title("\n".join([rf"({label}) $\Omega_c$ = {speed:g} rad/s", *absent]),
                     fontsize="medium")
    fig.suptitle("Fig. 3: sliding equilibrium stable in each shaded region; dashed: the "
                 "exact boundaries",
                 fontsize="medium")
    return fig


