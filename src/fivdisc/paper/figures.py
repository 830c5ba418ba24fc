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
import tempfile
from collections.abc import Callable
from dataclasses import asdict, dataclass
from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from fivdisc.analysis import linear_stability, sliding_equilibrium, stability_map
from fivdisc.analysis.boundary import stability_boundary
from fivdisc.case import Case
from fivdisc.model import build_model
from fivdisc.paper import measure as ms
from fivdisc.paper.cases import FIGURES, PaperCase
from fivdisc.result import select_slider
from fivdisc.simulate import initial_state, simulate

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["RECIPE", "Row", "Runs", "compute", "plot", "rows"]

RECIPE = 1
"""Version of what :func:`compute` stores; stored figures of another version are redone."""

# Result variables a figure may draw, and the event table.
_KEEP = ("phi", "phi_dot", "w", "normal_force", "friction_force", "phase", "disc_speed",
         "event_time", "event_kind", "event_from", "event_slider")
_RUN_ATTRS = ("status", "message", "end_time", "impact", "case", "wall_time")
# The variables of _KEEP that have a slider dimension in a result, and the event table.
_PER_SLIDER = ("phi", "phi_dot", "normal_force", "friction_force", "phase")
_EVENTS = ("phase", "event_time", "event_kind", "event_from", "event_slider")
_STFT_SEGMENT = 0.2  # [s]: 5 Hz resolution, fine enough to tell the disc modes apart
_FMAX = 1000.0  # [Hz], the Nyquist frequency of the 2 kHz output
_WINDOW = 5.0  # [s], windows of the per-stage frequency lists
_FREQ_TOL = 1.0  # [Hz], a fivdisc frequency "is" the paper's if this close


@dataclass(frozen=True)
class Row:
    """One comparison of a paper statement with fivdisc.

    Attributes
    ----------
    figure
        Figure number.
    quantity
        What is compared.
    paper
        What the paper says or shows.
    fivdisc
        What fivdisc gives with its model (docs/model.md: skew gyroscopic terms).
    printed
        What fivdisc gives with the printed paper's gyroscopic sign, where measured.
    verdict
        "agrees", "partly", "differs" or "" (a measurement without a paper value).
    """

    figure: int
    quantity: str
    paper: str
    fivdisc: str
    printed: str = ""
    verdict: str = ""


class Runs:
    """The simulations of one process, each (case, start) run once.

    Only the variables figures draw are kept (see ``_KEEP``), to bound memory.

    Parameters
    ----------
    sweep_dir
        Directory of the Zarr stores of Fig. 27's sweeps, which a later call resumes
        or reuses; None: a temporary directory, removed afterwards.
    sweep_workers
        Processes of the sweeps' pool (default: the number of CPUs).
    progress
        Show the sweeps' progress bars.
    """

    def __init__(self, sweep_dir: str | PathLike[str] | None = None,
                 sweep_workers: int | None = None, progress: bool = False) -> None:
        self._done: dict[tuple[Case, int | None], xr.Dataset] = {}
        self.sweep_dir = sweep_dir
        self.sweep_workers = sweep_workers
        self.progress = progress

    def get(self, case: Case, start_from: int | None = None) -> xr.Dataset:
        """The result dataset of `case`.

        Parameters
        ----------
        case
            The case.
        start_from
            Figure whose case's perturbed sliding equilibrium is the initial state;
            None: the case's own ``simulation.initial_state``.
        """
        key = (case, start_from)
        if key not in self._done:
            initial = None
            if start_from is not None:
                initial = initial_state(build_model(FIGURES[start_from].case))
            ds = simulate(case, initial=initial).dataset
            # A deep copy: the kept variables are views of the run's whole state buffer.
            # The paper's cases have one slider: its variables are kept as plain series.
            self._done[key] = select_slider(ds[list(_KEEP)], 0).copy(deep=True)
        return self._done[key]

    def printed(self, case: Case, start_from: int | None = None) -> xr.Dataset:
        """The run of `case` with the printed paper's gyroscopic sign."""
        return self.get(case.replace({"simulation.printed_gyroscopic_sign": True}), start_from)


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
    from fivdisc.conventions import global_attrs

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


# --- storing runs ----------------------------------------------------------------------------


def _with_slider(ds: xr.Dataset) -> xr.Dataset:
    """A run kept by :class:`Runs` (slider 0 selected) back in the result layout, with its
    ``slider`` dimension of one."""
    scalars = [c for c in ("slider", "angle", "face", "track_radius") if c in ds.coords]
    out = ds.drop_vars(scalars)
    for name in _PER_SLIDER:
        if name in out:
            out[name] = out[name].expand_dims("slider", axis=-1)
    return out.assign_coords({c: ("slider", [ds[c].item()], ds[c].attrs) for c in scalars})


def _pack(pc: PaperCase, runs: dict[str, xr.Dataset], variables: tuple[str, ...]
          ) -> xr.DataTree:
    """Runs as the groups of one tree, each in the result layout (see :func:`compute`)."""
    from fivdisc.conventions import global_attrs

    groups = {}
    for label, ds in runs.items():
        sub = _with_slider(ds[list(dict.fromkeys([*variables, *_EVENTS]))])
        name = f"{pc.stem}{'_' + label if label != 'main' else ''}"
        run = ("" if label == "main" else f" (run {label})")
        sub.attrs = {**global_attrs(f"fivdisc simulation of {name}: Fig. {pc.figure}{run}",
                                    "fivdisc.paper.compute"),
                     "case_name": name, **{key: ds.attrs[key] for key in _RUN_ATTRS}}
        groups[label] = sub
    return xr.DataTree.from_dict(groups)


def _unpack(data: xr.DataTree, label: str) -> xr.Dataset:
    """One run of :func:`_pack`'s tree, slider 0 selected as :class:`Runs` keeps it."""
    return select_slider(data[label].to_dataset(), 0)


def _labels(data: xr.DataTree) -> list[str]:
    return list(data.children)


# --- rows shared by several figures ------------------------------------------------------------


def _separation_text(ds: xr.Dataset) -> str:
    sep = ms.separation(ds)
    if not sep["count"]:
        return f"no separation in {float(ds['time'].values[-1]):g} s"
    return (f"separates {sep['count']} times from t = {sep['first']:.2f} s to "
            f"{sep['last']:.2f} s ({100 * sep['fraction']:.0f} % of the time)")


def _printed_text(ds: xr.Dataset) -> str:
    """Separation and divergence of a printed-sign run."""
    _, end = ms.run_end(ds)
    sep = ms.separation(ds)
    head = f"first separation at {sep['first']:.2f} s" if sep["count"] else "no separation"
    return f"{head}; {end}"


def _printed_row(pc: PaperCase, runs: Runs) -> Row:
    """What the printed gyroscopic sign does to the figure's runs."""
    parts_ok, parts_printed = [], []
    for label, case in pc.runs.items():
        lead = f"{label}: " if label else ""
        parts_ok.append(lead + _separation_text(runs.get(case, pc.start_from)))
        parts_printed.append(lead + _printed_text(runs.printed(case, pc.start_from)))
    return Row(pc.figure, "separation and boundedness, skew vs printed gyroscopic sign",
               "(equations as printed: +2 l M Omega dC/dt in the D equation)",
               "; ".join(parts_ok), "; ".join(parts_printed))


def _divergence(first: xr.Dataset, second: xr.Dataset, span: float = 1.0) -> tuple[float, float]:
    """How far two runs of the same case drift apart in the slider angle.

    Returns
    -------
    largest, when
        Largest ``|phi_1 - phi_2|`` over the first `span` s relative to the largest
        ``|phi_1|`` there, and the time [s] the difference first exceeds 1e-3 of that
        peak (nan if never).
    """
    keep = first["time"].values <= span
    diff = np.abs(first["phi"].values[keep] - second["phi"].values[keep])
    peak = np.max(np.abs(first["phi"].values[keep]))
    over = np.flatnonzero(diff > 1e-3 * peak)
    when = float(first["time"].values[over[0]]) if over.size else float("nan")
    return float(np.max(diff) / peak), when


def _omega_dot_row(pc: PaperCase, runs: Runs, label: str = "") -> Row:
    """Effect of the dOmega/dt terms (absent from the printed equations) on a run, next to
    the effect of a ten times tighter tolerance (the run's sensitivity)."""
    case = pc.runs[label]
    on = runs.get(case, pc.start_from)
    off = runs.get(case.replace({"simulation.omega_dot_terms": False}), pc.start_from)
    rtol = case.simulation.rtol
    tight = runs.get(case.replace({"simulation.rtol": rtol / 10.0}), pc.start_from)
    diff, when = _divergence(on, off)
    diff_tol, when_tol = _divergence(on, tight)
    counts = []
    for kind in ("stick", "separation"):
        n_on = int(np.sum(on["event_kind"].values == kind))
        n_off = int(np.sum(off["event_kind"].values == kind))
        counts.append(f"{kind} events {n_on} with, {n_off} without")
    lead = f"{label}: " if label else ""
    after = (f", above 1e-3 from t = {when:.2f} s" if np.isfinite(when) else "")
    after_tol = (f", above 1e-3 from t = {when_tol:.2f} s" if np.isfinite(when_tol) else "")
    return Row(pc.figure, "dOmega/dt terms of the disc equations, on vs off",
               "omitted in the printed Eqs. (33)-(41)",
               f"{lead}max |phi_on - phi_off| over the first 1 s = {diff:.1e} of max |phi|"
               f"{after} (rtol {rtol:g} vs {rtol / 10:g}: {diff_tol:.1e}{after_tol}); "
               "whole run: "
               f"{'; '.join(counts)}")


def _stability_text(case: Case) -> tuple[str, bool]:
    """Linear stability of a constant-speed case's sliding equilibrium, in words."""
    stab = linear_stability(case)
    word = "stable" if stab.stable else "unstable"
    return (f"{word}: largest growth rate {stab.max_growth_rate:.3g} 1/s "
            f"({stab.dominant[0]})"), stab.stable


def _stability_row(figure: int, case: Case, paper: str,
                   quantity: str = "sliding equilibrium") -> Row:
    """Linear stability of `case` with the skew and the printed gyroscopic sign."""
    text, stable = _stability_text(case)
    printed, _ = _stability_text(case.replace({"simulation.printed_gyroscopic_sign": True}))
    return Row(figure, quantity, paper, text, printed, _verdict(stable == (paper == "stable")))


def _verdict(ok: bool, partly: bool = False) -> str:
    return "agrees" if ok else ("partly" if partly else "differs")


def _analysis_window(ds: xr.Dataset, length: float = 10.0) -> tuple[float, float]:
    """The opening stationary stretch of a constant-speed run: from 1 s (after the
    start-up transient) for `length` s (0.1 Hz resolution), ending before the first
    separation."""
    sep = ms.separation(ds)
    end = min(1.0 + length, float(ds["time"].values[-1]))
    if sep["count"] and sep["first"] - 0.5 < end:
        end = sep["first"] - 0.5
    return 1.0, end


# Lyapunov exponents of a constant-speed run: three, over the analysis window.
_EXPONENTS = 3
_PAPER_LABEL = {8: "quasi-periodic", 13: "periodic"}


def _lyapunov_row(pc: PaperCase, ds: xr.Dataset, t0: float, t1: float) -> Row:
    """The spectral label of phi over [t0, t1] against the Lyapunov exponents of the
    same stretch (QR method with the saltation matrices at every switch)."""
    from fivdisc.analysis.lyapunov import lyapunov
    from fivdisc.analysis.regimes import cross_check

    spectral = ms.periodicity(ds, "phi", None, t0, t1).kind
    spec = lyapunov(pc.case, n=_EXPONENTS, transient=t0, duration=t1 - t0)
    regime = cross_check(spectral, spec)
    paper = _PAPER_LABEL.get(pc.figure, "")
    verdict = (_verdict(regime.lyapunov == paper, partly=regime.consistent) if paper else "")
    return Row(pc.figure, f"Lyapunov exponents ({_EXPONENTS}, {t0:g}-{t1:g} s) against the "
               "spectral label of phi", paper or "(not stated)",
               regime.summary + "; exponents " + ", ".join(f"{e:+.3g}" for e in spec.exponents)
               + " 1/s", verdict=verdict)


def _per_window(ds: xr.Dataset, var: str, probe: int | None = None,
                width: float = _WINDOW, until: float | None = None) -> list[tuple[float, float]]:
    """(window start [s], dominant frequency [Hz]) per window of `width` s, up to `until`."""
    end = float(ds["time"].values[-1]) if until is None else until
    starts = np.arange(0.0, end - width + 1e-9, width)
    return [(float(t0), ms.dominant(ds, var, probe, t0, t0 + width)) for t0 in starts]


def _window_text(values: list[tuple[float, float]], width: float = _WINDOW) -> str:
    return ", ".join(f"{t0:g}-{t0 + width:g} s: {f:.1f}" for t0, f in values) + " Hz"


# --- Fig. 3: stability map ---------------------------------------------------------------------


def _map_compute(pc: PaperCase, runs: Runs) -> tuple[xr.DataTree, list[Row]]:
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
                verdict=_verdict(all(above))))
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
        table.append(_stability_row(
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
                   verdict=_verdict(linear_stability(point).stable))
    top = max(crossings)
    return Row(figure, what, paper,
               f"r0^2 c_phi = {top:.4f} N m s/rad on the boundary: the point lies "
               f"{'above' if cphi > top else 'below'} it", verdict=_verdict(cphi > top))


def _map_plot(data: xr.DataTree) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.plots import plot_stability_map

    labels = _labels(data)
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


# --- Figs. 4-7: decay to the equilibrium, and the variable-speed transients --------------------


def _decay_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    ds = runs.get(pc.case)
    stab = linear_stability(pc.case)
    eq = sliding_equilibrium(pc.case)
    t = ds["time"].values
    dev = np.abs(ds["phi"].values - eq.phi[0])
    initial = float(dev[0])
    after = float(np.max(dev[(t >= 1.0) & (t <= 1.1)]))
    final = float(np.max(dev[t >= t[-1] - 0.5]))
    _, w_range = ms.envelope(ds, "w", 0, width=0.5)
    eigen = stab.to_dataframe()
    slowest = eigen[eigen["coordinate"] != "phi"].iloc[0]
    table = [
        _stability_row(pc.figure, pc.case, "stable"),
        Row(pc.figure, "slider: decay of |phi - phi_eq|", "decays fast to the equilibrium",
            f"{initial:.1e} rad at t = 0, {after:.1e} rad at 1 s, {final:.1e} rad in the last "
            "0.5 s", verdict=_verdict(after < 0.01 * initial)),
        Row(pc.figure, "disc at (r0, 0): decay of w",
            "decays fast to the equilibrium",
            f"peak-to-peak {w_range[0]:.2g} m in the first 0.5 s, {w_range[-1]:.2g} m in the "
            f"last: slow, the least damped disc mode ({slowest['coordinate']}, "
            f"{slowest['frequency_hz']:.1f} Hz) decays at {slowest['growth_rate']:.3g} 1/s "
            "(the disc has no structural damping)",
            verdict=_verdict(w_range[-1] < 0.01 * w_range[0], partly=True)),
        _printed_row(pc, runs),
    ]
    return _pack(pc, {"main": ds}, ("phi_dot", "w")), table


def _critical_speed(pc: PaperCase) -> tuple[float, float]:
    """Disc speed [rad/s] where the frozen-speed sliding equilibrium changes stability,
    and the time [s] the profile reaches it; nan if no change within the run."""
    speed = pc.case.speed
    t_end = pc.case.simulation.duration
    if speed.profile == "decelerating":
        omegas = np.linspace(speed.initial, speed.initial * (1 - t_end / speed.duration) + 0.1, 60)
    else:
        omegas = np.linspace(speed.initial, speed.initial + speed.rate * t_end, 60)
    base = pc.case.replace({"speed": {"profile": "constant", "value": float(omegas[0])},
                            "simulation.initial_state": "rest"})
    growth = np.array([linear_stability(base.replace({"speed.value": float(o)})).max_growth_rate
                       for o in omegas])
    change = np.flatnonzero(np.diff(np.sign(growth)) != 0)
    if change.size == 0:
        return float("nan"), float("nan")
    i = change[0]
    crit = float(omegas[i] + (omegas[i + 1] - omegas[i]) * growth[i] / (growth[i] - growth[i + 1]))
    if speed.profile == "decelerating":
        return crit, float((1.0 - crit / speed.initial) * speed.duration)
    return crit, float((crit - speed.initial) / speed.rate)


def _transient_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    ds = runs.get(pc.case, pc.start_from)
    centres, ranges = ms.envelope(ds, "phi_dot", width=0.1)
    # The first window holds the perturbation, which the slider's damping removes fast.
    i_min = 1 + int(np.argmin(ranges[1:]))
    t_min, r_min = centres[i_min], ranges[i_min]
    # The largest range after the minimum: at the very end the disc stops and the slider
    # sticks, so the last window is small again.
    i_max = i_min + int(np.argmax(ranges[i_min:]))
    growth = ranges[i_max] / r_min
    omega_min = float(ds["disc_speed"].sel(time=t_min, method="nearest"))
    crit, t_crit = _critical_speed(pc)
    side = "below" if pc.case.speed.profile == "decelerating" else "above"
    stick = ds["event_time"].values[ds["event_kind"].values == "stick"]
    table = [
        Row(pc.figure, "envelope of the slider's angular velocity",
            "decays at first, then grows",
            f"peak-to-peak over 0.1 s: {ranges[0]:.2g} rad/s at first, minimum {r_min:.2g} "
            f"rad/s at {t_min:.2f} s (Omega = {omega_min:.2f} rad/s), then x{growth:.3g} to "
            f"{ranges[i_max]:.2g} rad/s at {centres[i_max]:.2f} s",
            verdict=_verdict(ranges[0] > 3.0 * r_min and growth > 10.0)),
        Row(pc.figure, "frozen-speed linear stability along the profile",
            "explains the growth (negative friction slope / moving load)",
            f"sliding equilibrium unstable {side} Omega = {crit:.2f} rad/s, reached at "
            f"t = {t_crit:.1f} s" if np.isfinite(crit) else "no change of stability"),
    ]
    if pc.figure == 5:
        table.append(Row(pc.figure, "stick-slip in the final stage", "induced",
                         f"first stick at t = {stick[0]:.2f} s, {stick.size} sticks" if stick.size
                         else "no stick", verdict=_verdict(stick.size > 0)))
    else:
        table.append(Row(pc.figure, "separation", "not mentioned", _separation_text(ds)))
    table += [_omega_dot_row(pc, runs), _printed_row(pc, runs)]
    return _pack(pc, {"main": ds}, ("phi_dot", "w")), table


def _two_panel_plot(data: xr.Dataset) -> Figure:
    """(a) the slider's angular velocity, (b) the disc at (r0, 0)."""
    from matplotlib.figure import Figure

    from fivdisc.plots import plot_timeseries

    run = _unpack(data, "main")
    fig = Figure(figsize=(9, 6), layout="constrained")
    ax_a, ax_b = fig.subplots(2, 1, sharex=True)
    plot_timeseries(run, "phi_dot", ax=ax_a)
    plot_timeseries(run, "w", probe=0, ax=ax_b)
    ax_b.set_ylabel("w [m]")
    ax_a.set_title("(a) circumferential angular velocity of the slider", fontsize="medium")
    ax_b.set_title("(b) transverse displacement of the disc at r = r0, theta = 0",
                   fontsize="medium")
    _suptitle(fig, data)
    return fig


def _spectrogram(run: xr.Dataset, var: str, probe: int | None, ax: Axes) -> None:
    """Time-frequency plot of one variable, with a short colour-bar label."""
    from fivdisc.plots import plot_spectrogram

    plot_spectrogram(run, var, probe=probe, segment=_STFT_SEGMENT, fmax=_FMAX, ax=ax)
    # plot_spectrogram adds the colour bar last; its long name would overlap the panels.
    unit = "rad" if var == "phi" else "m"
    ax.figure.axes[-1].set_ylabel(f"STFT magnitude of {var} [{unit}]")


def _suptitle(fig: Figure, data: xr.DataTree) -> None:
    fig.suptitle(f"Fig. {data.attrs['figure']}: {data.attrs['figure_title']}", fontsize="medium")


# --- Figs. 8-16: slider and disc spectra, constant and decelerating ----------------------------


def _reference(case: Case) -> Case:
    """The constant-speed case a variable-speed case is compared with: the same at its
    initial speed (2 pi or 6 pi rad/s)."""
    speed = case.speed
    value = speed.value if speed.profile == "constant" else speed.initial
    return case.replace({"speed": {"profile": "constant", "value": value}})


def _constant_rows(pc: PaperCase, ds: xr.Dataset, var: str, probe: int | None) -> list[Row]:
    """Stationarity, periodicity and common lines of a constant-speed run."""
    t0, t1 = _analysis_window(ds)
    verdict = ms.periodicity(ds, var, probe, t0, t1)
    mine = ms.lines(ds, var, probe, t0, t1, n=20, rel=0.01)
    other_var, other_probe = ("w", 1) if var == "phi" else ("phi", None)
    other = ms.lines(ds, other_var, other_probe, t0, t1, n=20, rel=0.01)
    tol = 2.0 * mine.resolution
    common = ms.common_frequencies(mine, other, tol)
    sep = ms.separation(ds)
    until = sep["first"] if sep["count"] else None
    stages = _per_window(ds, var, probe, until=until)
    spread = np.ptp([f for _, f in stages]) if stages else np.nan
    name = "slider angle phi" if var == "phi" else "disc w at (r0, 1 rad)"
    window = f"{t0:g}-{t1:g} s"
    table = [Row(pc.figure, f"stationarity: strongest line of {name} per 5 s",
                 "unchanged throughout the process",
                 f"{_window_text(stages)} (spread {spread:.2f} Hz)",
                 verdict=_verdict(spread < _FREQ_TOL))]
    if pc.figure in (8, 9):
        has = [any(abs(c - f) < _FREQ_TOL for c in common) for f in (181.0, 290.5)]
        table += [
            Row(pc.figure, f"{name}, {window}", "quasi-periodic", verdict.summary,
                verdict=_verdict(verdict.kind == "quasi-periodic")),
            Row(pc.figure, f"lines common to phi and w (at least 1 % of the strongest), {window}",
                "f1 = 181 Hz and f2 = 290.5 Hz", ms.hz(common),
                verdict=_verdict(all(has), partly=any(has))),
        ]
    else:
        f0 = verdict.fundamental
        text = verdict.summary
        if np.isfinite(f0):
            multiples = ms.lines(ds, var, probe, t0, t1).frequencies / f0
            text += f"; strong lines at {', '.join(f'{m:.3f}' for m in multiples)} f0"
        table.append(Row(pc.figure, f"{name}, {window}",
                         "periodic: f0 = 206 Hz and its superharmonics n f0", text,
                         verdict=_verdict(verdict.kind == "periodic"
                                          and abs(f0 - 206.0) < _FREQ_TOL,
                                          partly=verdict.kind == "periodic")))
        if var == "w":
            f_phi = ms.periodicity(ds, "phi", None, t0, t1).fundamental
            peaks = ms.lines(ds, var, probe, t0, t1)
            ratios = peaks.frequencies / f_phi
            whole = np.abs(ratios - np.round(ratios)) < 0.01
            table.append(Row(pc.figure, "disc lines (at least 5 % of the strongest) as multiples "
                             "of the slider's f0",
                             "the same fundamental f0 (periodic at the same frequency)",
                             ", ".join(f"{r:.3f} f0 ({100 * a / peaks.amplitudes[0]:.0f} %)"
                                       for r, a in zip(ratios, peaks.amplitudes, strict=True))
                             + f", f0 = {f_phi:.2f} Hz; the others are free disc modes (no "
                             "structural damping)",
                             verdict=_verdict(whole.all(), partly=whole[0])))
    table.append(Row(pc.figure, "separation at constant speed", "none (section 3.2, Fig. 24)",
                     _separation_text(ds), verdict=_verdict(sep["count"] == 0)))
    return table


def _decelerating_rows(pc: PaperCase, ds: xr.Dataset, ref: xr.Dataset, var: str,
                       probe: int | None) -> list[Row]:
    """Time-variance, the early stage against constant speed, and the final stage."""
    name = "slider angle phi" if var == "phi" else "disc w at (r0, 1 rad)"
    early_dec = ms.dominant(ds, var, probe, 1.0, 6.0)
    early_ref = ms.dominant(ref, var, probe, 1.0, 6.0)
    end = float(ds["time"].values[-1])
    late = ms.dominant(ds, var, probe, end - _WINDOW, end)
    n_early = ms.line_count(ds, var, 1.0, 5.0, probe)
    n_late = ms.line_count(ds, var, end - 4.0, end, probe)
    _, r_dec = ms.ridge(ds, var, probe)
    _, r_ref = ms.ridge(ref, var, probe)
    return [
        Row(pc.figure, f"strongest line of {name} per 5 s", "time-variant",
            _window_text(_per_window(ds, var, probe))),
        _variance_row(pc, r_dec, r_ref, name),
        Row(pc.figure, "early stage (1-6 s), strongest line vs constant speed",
            "similar to constant speed",
            f"{early_dec:.1f} Hz vs {early_ref:.1f} Hz",
            verdict=_verdict(abs(early_dec - early_ref) < _FREQ_TOL)),
        Row(pc.figure, f"final stage ({end - _WINDOW:g}-{end:g} s), strongest line",
            "lower-frequency components arise", f"{late:.1f} Hz (early: {early_dec:.1f} Hz)",
            verdict=_verdict(late < 0.95 * early_dec)),
        Row(pc.figure, "lines of at least 5 % of the strongest, first 1-5 s vs last 4 s",
            "fuzzy and dense in the final stage", f"{n_early} vs {n_late}",
            verdict=_verdict(n_late > n_early)),
    ]


def _variance_row(pc: PaperCase, r_dec: np.ndarray, r_ref: np.ndarray, name: str) -> Row:
    """How often the strongest line moves, decelerating vs constant speed."""
    dec, ref = ms.ridge_changes(r_dec), ms.ridge_changes(r_ref)
    return Row(pc.figure, f"time-variance: share of 0.5 s STFT slices where the strongest line "
               f"of {name} moves by more than 2 Hz, decelerating vs constant speed",
               "more time-variant than at constant speed",
               f"{100 * dec:.0f} % vs {100 * ref:.0f} %", verdict=_verdict(dec > ref))


def _spectra_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    ds = runs.get(pc.case)
    slider = pc.figure in (8, 10, 13, 15)
    var, probe = ("phi", None) if slider else ("w", 1)
    if pc.case.speed.profile == "constant":
        table = []
        if slider:
            table.append(_stability_row(pc.figure, pc.case, "unstable"))
            if pc.figure == 8:
                stab = linear_stability(pc.case)
                eigen = stab.to_dataframe()
                freq = dict(zip(eigen["coordinate"], eigen["frequency_hz"], strict=True))
                table.append(Row(pc.figure, "linear eigenfrequencies C01 and D02",
                                 "f1 = 181 Hz, f2 = 290.5 Hz",
                                 f"{freq['C01']:.2f} Hz, {freq['D02']:.2f} Hz",
                                 verdict=_verdict(abs(freq["C01"] - 181.0) < _FREQ_TOL
                                                  and abs(freq["D02"] - 290.5) < _FREQ_TOL)))
        table += _constant_rows(pc, ds, var, probe)
        if pc.figure in (8, 13):
            table.append(_lyapunov_row(pc, ds, *_analysis_window(ds)))
    else:
        table = _decelerating_rows(pc, ds, runs.get(_reference(pc.case)), var, probe)
        if pc.figure == 15:
            table += _segment_rows(pc, ds)
        table += [Row(pc.figure, "separation", "not mentioned", _separation_text(ds)),
                  _omega_dot_row(pc, runs)]
    table.append(_printed_row(pc, runs))
    data = _pack(pc, {"main": ds}, ("phi", "phi_dot") if slider else ("w",))
    data.attrs["profile"] = pc.case.speed.profile
    data.attrs["analysis_window"] = list(_analysis_window(ds))
    return data, table


def _segment_rows(pc: PaperCase, ds: xr.Dataset) -> list[Row]:
    """The six segments of Fig. 15: the strongest line of phi at their ends and middle."""
    times, freqs = ms.ridge(ds, "phi")
    leave = ms.plateau_end(times, freqs)
    table = [Row(pc.figure, "end of the opening periodic regime",
                 "first segment 0-10 s, second 10-15 s",
                 f"the strongest line leaves {np.median(freqs[: freqs.size // 4]):.0f} Hz at "
                 f"t = {leave:.1f} s and then glides down as the disc slows",
                 verdict=_verdict(10.0 <= leave <= 15.0))]
    previous = None
    for t0, t1 in pc.windows:
        inside = (times >= t0) & (times <= t1)
        f = freqs[inside]
        stick = float(np.mean(ds["phase"].values[(ds["time"].values >= t0)
                                                 & (ds["time"].values <= t1)] == 1))
        median = float(np.median(f))
        distinct = previous is None or abs(median - previous) > 0.03 * previous
        moves = abs(f[-1] - f[0]) > 0.03 * f[0]
        table.append(Row(pc.figure, f"segment {t0:g}-{t1:g} s", "a distinct frequency composition",
                         f"strongest line {f[0]:.0f} -> {f[-1]:.0f} Hz (median {median:.0f} Hz, "
                         f"0.5 s STFT); sticking {100 * stick:.0f} % of the time",
                         verdict=_verdict(distinct, partly=moves)))
        previous = median
    return table


def _spectra_plot(data: xr.Dataset) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.plots import plot_spectrum, plot_timeseries

    run = _unpack(data, "main")
    figure = int(data.attrs["figure"])
    slider = figure in (8, 10, 13, 15)
    constant = data.attrs["profile"] == "constant"
    if slider:
        fig = Figure(figsize=(10, 7), layout="constrained")
        ax_a, ax_b = fig.subplots(2, 1)
        plot_timeseries(run, "phi_dot", ax=ax_a)
        _spectrogram(run, "phi", None, ax_b)
        ax_a.set_title("(a) circumferential angular velocity of the slider", fontsize="medium")
        ax_b.set_title("(b) time-frequency plot of the circumferential angle", fontsize="medium")
    else:
        fig = Figure(figsize=(10, 10 if constant else 7), layout="constrained")
        axes = fig.subplots(3 if constant else 2, 1)
        plot_timeseries(run, "w", probe=1, ax=axes[0])
        axes[0].set_ylabel("w [m]")
        _spectrogram(run, "w", 1, axes[1])
        axes[0].set_title("(a) transverse displacement of the disc at r = r0, theta = 1 rad",
                          fontsize="medium")
        axes[1].set_title("(b) time-frequency plot", fontsize="medium")
        if constant:
            t0, t1 = (float(t) for t in np.atleast_1d(data.attrs["analysis_window"]))
            plot_spectrum(run, "w", probe=1, window=(t0, t1), fmax=_FMAX, ax=axes[2])
            # plot_spectrum's title ends with the periodicity verdict
            verdict = axes[2].get_title().split("\n")[-1]
            axes[2].set_title(f"(b') amplitude spectrum, {t0:g}-{t1:g} s\n{verdict}",
                              fontsize="small")
    _suptitle(fig, data)
    return fig


# --- Fig. 12: early and late windows; Fig. 17: phase portraits ---------------------------------


def _motion_text(ds: xr.Dataset, t0: float, t1: float) -> tuple[str, float, bool]:
    """The slider's motion in a window, its fundamental (or strongest) frequency [Hz], and
    whether it sticks."""
    inside = (ds["time"].values >= t0) & (ds["time"].values <= t1)
    stick = float(np.mean(ds["phase"].values[inside] == 1))
    kind = ms.periodicity(ds, "phi", None, t0, t1)
    freq = kind.fundamental if kind.kind == "periodic" else ms.dominant(ds, "phi", None, t0, t1)
    motion = "stick-slip" if stick > 0 else "pure slip"
    return (f"{motion}, sticking {100 * stick:.0f} % of the time; phi {kind.summary}", freq,
            stick > 0)


def _window(ds: xr.Dataset, t0: float, t1: float) -> xr.Dataset:
    """The samples and events of a run within ``[t0, t1]`` [s]."""
    times = ds["event_time"].values
    return ds.sel(time=slice(t0, t1)).isel(event=(times >= t0) & (times <= t1))


def _windows_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    ds = runs.get(pc.case)
    table, freqs, sticks = [], [], []
    for t0, t1 in pc.windows:
        text, freq, sticks_here = _motion_text(ds, t0, t1)
        freqs.append(freq)
        sticks.append(sticks_here)
        table.append(Row(pc.figure, f"{t0:g}-{t1:g} s", "(time histories)", text))
    if pc.figure == 12:
        a, b = freqs
        table.append(Row(pc.figure, "frequency of the slider's motion, early vs late span",
                         "varies during the process", f"{a:.1f} Hz vs {b:.1f} Hz",
                         verdict=_verdict(abs(a - b) > 0.03 * a)))
    else:
        # Lines closer than the 10 Hz resolution of a 0.1 s window are not told apart.
        distinct = len({round(f / 10.0) for f in freqs if np.isfinite(f)})
        table.append(Row(pc.figure, "stick-slip and its period in the six spans",
                         "stick-slip with different periods in the six spans",
                         f"stick-slip in {sum(sticks)} of 6 spans; fundamental (or strongest) "
                         f"frequency {ms.hz(freqs)}: {distinct} distinct at 10 Hz resolution",
                         verdict=_verdict(all(sticks) and distinct == 6,
                                          partly=any(sticks) and distinct > 1)))
    parts = [_window(ds, t0, t1) for t0, t1 in pc.windows]
    data = _pack(pc, {f"w{i}": p for i, p in enumerate(parts)},
                 ("phi", "phi_dot", "friction_force", "disc_speed"))
    return data, table


def _windows_plot(data: xr.Dataset) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.plots import plot_friction, plot_phase_portrait, plot_timeseries

    labels = _labels(data)
    letters = "abcdefghijkl"
    if int(data.attrs["figure"]) == 12:
        fig = Figure(figsize=(10, 6.5), layout="constrained")
        axes = fig.subplots(2, len(labels))
        for i, label in enumerate(labels):
            run = _unpack(data, label)
            plot_timeseries(run, "phi_dot", ax=axes[0, i])
            plot_timeseries(run, "friction_force", ax=axes[1, i])
            axes[1, i].set_ylabel("friction force [N]")
            axes[0, i].set_title(f"({letters[i]}) slider angular velocity", fontsize="medium")
            axes[1, i].set_title(f"({letters[i + 2]}) friction force", fontsize="medium")
    else:
        fig = Figure(figsize=(10, 16), layout="constrained")
        axes = fig.subplots(len(labels), 2)
        for i, label in enumerate(labels):
            run = _unpack(data, label)
            t0, t1 = float(run["time"].values[0]), float(run["time"].values[-1])
            plot_phase_portrait(run, ax=axes[i, 0])
            plot_friction(run, ax=axes[i, 1])
            axes[i, 1].set_ylabel("friction force [N]")
            axes[i, 0].set_title(f"({letters[2 * i]}) {t0:g} < t < {t1:g} s", fontsize="medium")
            axes[i, 1].set_title(f"({letters[2 * i + 1]}) {t0:g} < t < {t1:g} s",
                                 fontsize="medium")
    _suptitle(fig, data)
    return fig


# --- Figs. 18, 19, 24: normal force; 20-23, 25, 26: responses ----------------------------------


def _normal_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    table = []
    packed = {}
    for label, case in pc.runs.items():
        ds = runs.get(case)
        bad = runs.printed(case)
        packed[label], packed[f"{label}_printed"] = ds, bad
        sep = ms.separation(ds)
        sep_bad = ms.separation(bad)
        printed = _printed_text(bad)
        lead = f"{label}: "
        if pc.figure == 18:
            table.append(Row(pc.figure, lead + "separation", "happens",
                             _separation_text(ds), printed, _verdict(sep["count"] > 0)))
        elif pc.figure == 19:
            end = float(ds["time"].values[-1])
            late = 2.0 * end / 3.0
            if label == "a":
                spread = sep["count"] > 0 and sep["first"] < 5.0 and sep["last"] > end - 5.0
                table.append(Row(pc.figure, lead + "separation", "throughout the whole process",
                                 _separation_text(ds), printed, _verdict(spread)))
            else:
                quiet = sep["count"] > 0 and sep["last"] < late
                table.append(Row(pc.figure, lead + "separation",
                                 f"happens, but not in the late stage (after {late:.0f} s)",
                                 _separation_text(ds), printed,
                                 _verdict(quiet, partly=sep["count"] == 0)))
        else:
            ref_case = _reference(case)
            ref = runs.get(ref_case)
            omega = (case.speed.initial + case.speed.rate * sep["first"]
                     if sep["count"] else float("nan"))
            omega_bad = (case.speed.initial + case.speed.rate * sep_bad["first"]
                         if sep_bad["count"] else float("nan"))
            table.append(Row(pc.figure, lead + "separation", "happens as the disc speeds up",
                             f"{_separation_text(ds)}; first at Omega = {omega:.2f} rad/s",
                             f"{printed}; first at Omega = {omega_bad:.2f} rad/s",
                             _verdict(sep["count"] > 0)))
            ref_sep = ms.separation(ref)
            table.append(Row(pc.figure, lead + "separation at constant 2 pi rad/s (Figs. 8, 13)",
                             "none", _separation_text(ref), _printed_text(runs.printed(ref_case)),
                             _verdict(ref_sep["count"] == 0)))
        if pc.figure != 18:
            table.append(_omega_dot_row(pc, runs, label))
    return _pack(pc, packed, ("normal_force", "w")), table


def _normal_plot(data: xr.Dataset) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.plots import plot_normal_force

    panels = [label for label in _labels(data) if not label.endswith("_printed")]
    fig = Figure(figsize=(12, 3.2 * len(panels) * 2), layout="constrained")
    axes = fig.subplots(2 * len(panels), 2)
    for i, label in enumerate(panels):
        for j, key in enumerate((label, f"{label}_printed")):
            run = _unpack(data, key)
            sign = "printed gyroscopic sign" if j else "fivdisc (skew gyroscopic terms)"
            ax = axes[2 * i, j]
            # One shaded band per separation (plot_normal_force) is too slow for thousands.
            time = run["time"].values
            ax.plot(time, run["normal_force"].values, lw=0.5)
            ax.fill_between(time, 0, 1, where=run["phase"].values == 2, color="C1", alpha=0.3,
                            lw=0, transform=ax.get_xaxis_transform(), label="separation")
            ax.set_xlabel("time [s]")
            ax.set_ylabel("normal contact force [N]")
            ax.set_title(f"({label}) {sign}", fontsize="medium")
            sep = ms.separation(run)
            zoom = axes[2 * i + 1, j]
            if sep["count"]:
                t0 = sep["first"] - 0.02
                plot_normal_force(run, window=(max(t0, 0.0), t0 + 0.1), ax=zoom)
                zoom.set_title(f"({label}) zoom at the first separation", fontsize="small")
            else:
                zoom.set_axis_off()
                zoom.text(0.5, 0.5, "no separation", ha="center", va="center",
                          transform=zoom.transAxes)
    _suptitle(fig, data)
    return fig


def _counterpart(pc: PaperCase) -> PaperCase:
    """The constant-speed figure a decelerating one is compared with (22 <-> 20, 23 <-> 21)."""
    return FIGURES[{22: 20, 23: 21}[pc.figure]]


def _responses_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    ds = runs.get(pc.case)
    sep = ms.separation(ds)
    table = [Row(pc.figure, "separation", "happens", _separation_text(ds),
                 _printed_text(runs.printed(pc.case)), _verdict(sep["count"] > 0))]
    end = float(ds["time"].values[-1])
    profile = pc.case.speed.profile
    if profile == "constant":
        for var, probe in (("phi", None), ("w", 1)):
            table.append(Row(pc.figure, f"strongest line of {var} per 5 s", "(time-frequency plot)",
                             _window_text(_per_window(ds, var, probe))))
        if pc.figure in (20, 21):
            table.append(_lyapunov_row(pc, ds, 1.0, min(11.0, end)))
    elif profile == "decelerating":
        ref = runs.get(_counterpart(pc).case)
        _, r_dec = ms.ridge(ds, "phi")
        _, r_ref = ms.ridge(ref, "phi")
        table.append(_variance_row(pc, r_dec, r_ref, "slider angle phi"))
        early = ms.dominant(ds, "phi", None, 1.0, 6.0)
        late = ms.dominant(ds, "phi", None, end - _WINDOW, end)
        n_early = ms.line_count(ds, "phi", 1.0, 5.0)
        n_late = ms.line_count(ds, "phi", end - 4.0, end)
        lower = late < 0.95 * early and n_late > n_early
        expected = pc.figure == 23
        table += [
            Row(pc.figure, "strongest line of phi per 5 s", "(time-frequency plot)",
                _window_text(_per_window(ds, "phi"))),
            Row(pc.figure, "final stage: lower and denser lines (strongest line; lines of "
                "at least 5 %, first 1-5 s vs last 4 s)",
                "yes" if expected else "not seen",
                f"{early:.1f} -> {late:.1f} Hz; {n_early} vs {n_late} lines",
                verdict=_verdict(lower == expected)),
            Row(pc.figure, "separation in the late stage",
                "none" if expected else "separation throughout",
                f"last separation starts at {sep['last']:.2f} s" if sep["count"]
                else "no separation"),
            _omega_dot_row(pc, runs),
        ]
    else:
        if sep["count"]:
            t_sep = sep["first"]
            before = ms.dominant(ds, "phi", None, max(0.0, t_sep - 2.0), t_sep)
            after = ms.dominant(ds, "phi", None, t_sep, min(end, t_sep + 2.0))
            w_before = ms.dominant(ds, "w", 1, max(0.0, t_sep - 2.0), t_sep)
            w_after = ms.dominant(ds, "w", 1, t_sep, min(end, t_sep + 2.0))
            shift = abs(after - before) > _FREQ_TOL or abs(w_after - w_before) > _FREQ_TOL
            table.append(Row(pc.figure, "strongest lines 2 s before vs after the first separation",
                             "separation shifts the spectra",
                             f"phi {before:.1f} -> {after:.1f} Hz, w {w_before:.1f} -> "
                             f"{w_after:.1f} Hz", verdict=_verdict(shift)))
        table.append(_omega_dot_row(pc, runs))
    return _pack(pc, {"main": ds}, ("phi", "phi_dot", "w")), table


def _responses_plot(data: xr.Dataset) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.plots import plot_timeseries

    run = _unpack(data, "main")
    fig = Figure(figsize=(12, 7), layout="constrained")
    axes = fig.subplots(2, 2)
    plot_timeseries(run, "phi_dot", ax=axes[0, 0])
    _spectrogram(run, "phi", None, axes[0, 1])
    plot_timeseries(run, "w", probe=1, ax=axes[1, 0])
    axes[1, 0].set_ylabel("w [m]")
    _spectrogram(run, "w", 1, axes[1, 1])
    for ax, text in zip(axes.ravel(), ("(a) slider angular velocity", "(b) slider angle: STFT",
                                       "(c) disc at (r0, 1 rad)", "(d) disc: STFT"), strict=True):
        ax.set_title(text, fontsize="medium")
    _suptitle(fig, data)
    return fig


# --- Fig. 27: separation region ---------------------------------------------------------------


def separation_grid(pc: PaperCase, directory: str | PathLike[str], printed: bool,
                    workers: int | None = None, progress: bool = False) -> xr.Dataset:
    """Run (or resume) the separation sweep of Fig. 27, stored as Zarr in `directory`.

    Parameters
    ----------
    pc
        Fig. 27's parameters.
    directory
        Where the sweep's store goes, named after the sweep's digest so that a changed
        grid or case gets a store of its own; a complete store is reused.
    printed
        Use the printed paper's gyroscopic sign.
    workers
        Processes of the sweep's pool (default: the number of CPUs).
    progress
        Show the sweep's progress bar.

    Returns
    -------
    xarray.Dataset
        The sweep (:func:`fivdisc.sweep.open_sweep`) without its checksums:
        ``separated``, ``first_separation_time`` [s], ``error`` and ``done`` on
        (``speed.initial`` [rad/s], ``speed.duration`` [s]).
    """
    from fivdisc.sweep import open_sweep, run_sweep, separation_sweep

    base = pc.case.replace({"simulation.printed_gyroscopic_sign": printed})
    (_, xs), (_, ys) = pc.axes
    sweep = separation_sweep("decelerating", x=list(xs), y=list(ys), base=base)
    name = "printed" if printed else "skew"
    store = Path(directory) / f"fig27_{name}_{sweep.digest[:12]}.zarr"
    run_sweep(sweep, store, workers=workers, progress=progress)
    grid = open_sweep(store).drop_vars("checksum")
    # netCDF has no numpy StringDType: the messages as Python strings.
    grid["error"] = grid["error"].astype(object)
    grid.attrs["case_name"] = f"{pc.stem} ({name} gyroscopic sign)"
    return grid


def _map_text(grid: xr.Dataset) -> tuple[str, bool]:
    """Where a separation grid separates, and whether more speed and longer stops only add."""
    grid = grid.transpose("speed.initial", "speed.duration")
    sep = grid["separated"].values.astype(bool)
    xs, ys = grid["speed.initial"].values, grid["speed.duration"].values
    if not sep.any():
        return "no separation anywhere in the grid", False
    # Monotone: separation at (Omega_0, t_max) implies it at higher Omega_0 and longer t_max.
    up_x = np.all(~sep[:-1] | sep[1:])
    up_y = np.all(~sep[:, :-1] | sep[:, 1:])
    lowest = [f"{ys[j]:g} s: {xs[np.argmax(sep[:, j])]:g}" for j in range(ys.size)
              if sep[:, j].any()]
    text = (f"{sep.mean() * 100:.0f} % of the grid separates; lowest Omega_0 [rad/s] that "
            f"separates per t_max: {', '.join(lowest)}; region closed towards higher Omega_0: "
            f"{'yes' if up_x else 'no'}, towards longer t_max: {'yes' if up_y else 'no'}")
    return text, bool(up_x and up_y)


def _sweep_compute(pc: PaperCase, runs: Runs) -> tuple[xr.DataTree, list[Row]]:
    grids = {}
    with tempfile.TemporaryDirectory() as tmp:
        for printed in (False, True):
            grids["printed" if printed else "skew"] = separation_grid(
                pc, runs.sweep_dir or tmp, printed, runs.sweep_workers, runs.progress)
    text, ok = _map_text(grids["skew"])
    text_bad, _ = _map_text(grids["printed"])
    failed = sum(int(np.sum(g["error"].values != "")) for g in grids.values())
    table = [Row(pc.figure, "separation region over (Omega_0, t_max)",
                 "more likely at high Omega_0 and long t_max", text, text_bad,
                 _verdict(ok, partly=bool(grids["skew"]["separated"].values.any())))]
    if failed:
        table.append(Row(pc.figure, "failed sweep points", "", str(failed)))
    return xr.DataTree.from_dict(grids), table


def _sweep_plot(data: xr.DataTree) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.sweep import plot_separation_map

    fig = Figure(figsize=(11, 4.8), layout="constrained")
    for ax, key, title in zip(fig.subplots(1, 2), ("skew", "printed"),
                              ("fivdisc (skew gyroscopic terms)", "printed gyroscopic sign"),
                              strict=True):
        plot_separation_map(data[key].to_dataset(), ax=ax)
        ax.set_title(title, fontsize="medium")
    _suptitle(fig, data)
    return fig


# --- Fig. 28: impact --------------------------------------------------------------------------


def _impact_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    packed = {}
    amplitude = {}
    table = []
    for label, case in pc.runs.items():
        ds = runs.get(case)
        bad = runs.printed(case)
        packed[label], packed[f"{label}_printed"] = ds, bad
        sep = ms.separation(ds)
        after = ds["time"].values >= (sep["first"] if sep["count"] else 0.0)
        w = ds["w"].values[after, 0]
        amplitude[label] = (float(np.max(np.abs(w))), float(np.sqrt(np.mean(w**2))))
        what = "with impact" if case.simulation.impact else "without impact"
        table.append(Row(pc.figure, f"{label} ({what}): separation", "happens",
                         _separation_text(ds), _printed_text(bad), _verdict(sep["count"] > 0)))
    (max_a, rms_a), (max_b, rms_b) = amplitude["a"], amplitude["b"]
    table.append(Row(pc.figure, "w at (r0, 0) after the first separation: max |w|, RMS, "
                     "with vs without impact", "much weaker with impact",
                     f"max {max_a:.2e} vs {max_b:.2e} m (x{max_b / max_a:.2f}); RMS {rms_a:.2e} "
                     f"vs {rms_b:.2e} m (x{rms_b / rms_a:.2f})",
                     verdict=_verdict(max_b > 1.5 * max_a, partly=max_b > max_a)))
    return _pack(pc, packed, ("w",)), table


def _impact_plot(data: xr.Dataset) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.plots import plot_timeseries

    fig = Figure(figsize=(11, 7), layout="constrained")
    axes = fig.subplots(2, 2)
    for i, label in enumerate(("a", "b")):
        run = _unpack(data, label)
        plot_timeseries(run, "w", probe=0, ax=axes[0, i])
        axes[0, i].set_ylabel("w at (r0, 0) [m]")
        axes[0, i].set_title(f"({label}) {'with' if i == 0 else 'without'} impact, fivdisc",
                             fontsize="medium")
        bad = _unpack(data, f"{label}_printed")
        ax = axes[1, i]
        # Drawn until the displacement leaves the model's range (it grows without bound).
        w = bad["w"].values[:, 0]
        out = np.flatnonzero(~(np.abs(w) <= ms.DIVERGED))
        end = out[0] + 1 if out.size else w.size
        ax.plot(bad["time"].values[:end], w[:end], lw=0.8)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("w at (r0, 0) [m]")
        ax.set_title(f"({label}) {'with' if i == 0 else 'without'} impact, printed "
                     f"gyroscopic sign: {ms.run_end(bad)[1]}", fontsize="small")
    _suptitle(fig, data)
    return fig


_Compute = Callable[[PaperCase, Runs], tuple[xr.Dataset, list[Row]]]
_Plot = Callable[[xr.Dataset], "Figure"]

_KINDS: dict[int, tuple[_Compute, _Plot]] = {
    3: (_map_compute, _map_plot),
    4: (_decay_compute, _two_panel_plot),
    5: (_transient_compute, _two_panel_plot),
    6: (_decay_compute, _two_panel_plot),
    7: (_transient_compute, _two_panel_plot),
    **{n: (_spectra_compute, _spectra_plot) for n in (8, 9, 10, 11, 13, 14, 15, 16)},
    12: (_windows_compute, _windows_plot),
    17: (_windows_compute, _windows_plot),
    **{n: (_normal_compute, _normal_plot) for n in (18, 19, 24)},
    **{n: (_responses_compute, _responses_plot) for n in (20, 21, 22, 23, 25, 26)},
    27: (_sweep_compute, _sweep_plot),
    28: (_impact_compute, _impact_plot),
}

