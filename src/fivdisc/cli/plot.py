"""``fivdisc plot RESULT.nc [--run LABEL] --kind KIND [--var NAME] [--probe I] [--slider J]
[--window T0:T1] -o FIG.png``: any netCDF file fivdisc writes, drawn."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import click

from fivdisc.errors import FivdiscError
from fivdisc.plots.kinds import KINDS

if TYPE_CHECKING:
    import numpy as np

_USES_VAR = ("timeseries", "spectrogram", "spectrum")
# Variables each kind of plot reads, besides --var.
_NEEDS = {
    "phase": ("phi", "phi_dot"),
    "friction": ("disc_speed", "phi_dot", "friction_force"),
    "normal-force": ("normal_force",),
}


def parse_window(text: str | None, time: np.ndarray) -> tuple[float, float] | None:
    """``"T0:T1"`` [s] as a pair within the sample ``time`` [s]; an empty side means that end.

    Raises
    ------
    FivdiscError
        If the text is not two numbers around a colon, or the window is empty or
        outside the data.
    """
    if text is None:
        return None
    lo, hi = float(time[0]), float(time[-1])
    parts = text.split(":")
    try:
        if len(parts) != 2:
            raise ValueError(text)
        t0 = float(parts[0]) if parts[0].strip() else lo
        t1 = float(parts[1]) if parts[1].strip() else hi
    except ValueError:
        raise FivdiscError(f"--window {text!r} is malformed: must be T0:T1 in seconds, e.g. "
                           "0.1:0.2 (either side may be left empty)") from None
    # Half a sample of slack, so that an end typed as the printed duration is accepted.
    slack = 0.5 * (hi - lo) / (time.size - 1)
    if not (lo - slack <= t0 < t1 <= hi + slack):
        raise FivdiscError(f"--window {text!r} is invalid: must satisfy {lo:g} <= T0 < T1 <= "
                           f"{hi:g} (the data's time span in s)")
    return max(t0, lo), min(t1, hi)


def _check(ds, kind: str, var: str | None, probe: int | None) -> str | None:
    """The variable to plot, after checking --var and --probe against the data."""
    if kind not in _USES_VAR:
        if var is not None or probe is not None:
            option = "--var" if var is not None else "--probe"
            raise FivdiscError(f"{option} is not used by --kind {kind}: it plots "
                               f"{', '.join(_NEEDS[kind])}")
        missing = [name for name in _NEEDS[kind] if name not in ds]
        if missing:
            raise FivdiscError(f"--kind {kind} needs {', '.join(missing)}, which the file "
                               "lacks: is it a fivdisc result?")
        return None
    name = "phi" if var is None else var
    allowed = sorted(str(v) for v, da in ds.data_vars.items() if "time" in da.dims)
    if name not in allowed:
        raise FivdiscError(f"--var {name!r} is not a time series of the file: must be one of "
                           f"{', '.join(allowed)}")
    others = [d for d in ds[name].dims if d != "time"]
    if probe is not None:
        if not others:
            raise FivdiscError(f"--probe {probe} is invalid: --var {name} has no probe "
                               "dimension; leave --probe out")
        size = ds.sizes[others[0]]
        if not 0 <= probe < size:
            raise FivdiscError(f"--probe {probe} is out of range for --var {name}: must be in "
                               f"[0, {size - 1}] ({others[0]})")
    return name


@click.command()
@click.argument("result", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--run", default=None, metavar="LABEL",
              help="Which run of a file of fivdisc reproduce that holds several (a, b, "
              "a_printed, ...).")
@click.option("--kind", type=click.Choice(KINDS), default="timeseries", show_default=True,
              help="What to plot (simulation results).")
@click.option("--var", default=None,
              help="Variable for timeseries, spectrogram and spectrum [default: phi].")
@click.option("--probe", type=int, default=None,
              help="Index along the variable's second dimension (w: probe) [default: 0].")
@click.option("--slider", type=int, default=0, show_default=True,
              help="Which slider's variables (phi, normal_force, ...) and events to plot.")
@click.option("--window", "window_text", metavar="T0:T1", default=None,
              help="Time window in s; either side may be empty [default: all, except a "
              "timeseries with many oscillations: its last 30, as its title says].")
@click.option("--fmax", type=float, default=None,
              help="Highest frequency shown by spectrogram and spectrum, up to the Nyquist "
              "frequency (half the output rate) [Hz] [default: spectrogram: the band "
              "holding 99.9 % of the variable's power; spectrum: Nyquist].")
@click.option("--segment", type=float, default=None,
              help="STFT segment length of spectrogram [s] [default: from the window's "
              "length and the frequencies shown].")
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="Figure file; the format follows the extension [default: RESULT-KIND.png].")
@click.option("--growth-scale", type=click.Choice(("auto", "linear", "symlog")),
              default=None, help="Eigenvalue branches (fivdisc stability --x): the "
              "growth-rate axis [default: auto, symmetric log where a small rate would "
              "be a flat line beside the largest].")
@click.option("--equilibrium", is_flag=True,
              help="A branch of periodic orbits: draw the sliding equilibrium's branch "
              "too (stable solid, unstable dashed) where its measure has a value.")
@click.option("--dpi", type=click.IntRange(min=10), default=150, show_default=True,
              help="Resolution of raster formats.")
def plot(result: Path, run: str | None, kind: str, var: str | None, probe: int | None,
         slider: int, window_text: str | None, fmax: float | None, segment: float | None,
         output: Path | None, growth_scale: str | None, equilibrium: bool, dpi: int) -> None:
    """Draw RESULT, a netCDF file that fivdisc wrote, to a figure file.

    A simulation result (``fivdisc simulate``, or a run of ``fivdisc reproduce``) is drawn
    as --kind says; a stability map (``fivdisc stability -o map.nc``) or a separation map
    (a run of Fig. 3 or 27 of ``fivdisc reproduce``) as a map; a branch of periodic orbits
    (``fivdisc continue -o``) against its key, --var naming the measure (period, phi_dot,
    normal_force_min, ...) and --slider the slider.
    """
    from fivdisc.extras import require

    require("plot", "fivdisc plot")
    import xarray as xr

    from fivdisc import plots
    from fivdisc.engine.result import open_result, run_groups
    from fivdisc.files import (
        check_netcdf,
        check_output,
        figure_suffixes,
        read_dataset,
        require_fivdisc_netcdf,
    )
    from fivdisc.plots.result import check_fmax

    if not result.exists():
        raise FileNotFoundError(2, "No such file", str(result))
    from fivdisc.continuation.branch import CONTENT

    given = click.get_current_context().get_parameter_source
    default = click.core.ParameterSource.DEFAULT
    kind_given = None if given("kind") == default else kind
    slider_given = None if given("slider") == default else slider
    stored_attrs = read_dataset(result, "plot").attrs
    if stored_attrs.get("content") == CONTENT and "curve_kind" in stored_attrs:
        from fivdisc.continuation.codim2 import open_curve

        out = check_output(output or result.with_name(f"{result.stem}.png"), "-o",
                           figure_suffixes(), inputs=[result])
        _save(plots.plot_bifurcation_curve(open_curve(result)), out, dpi)
        return
    if stored_attrs.get("content") == CONTENT:
        out = check_output(output or result.with_name(f"{result.stem}-{var or 'period'}.png"),
                           "-o", figure_suffixes(), inputs=[result])
        fig = _branch(result, var, slider, (("--run", run), ("--probe", probe),
                                            ("--window", window_text), ("--fmax", fmax),
                                            ("--segment", segment), ("--kind", kind_given),
                                            ("--growth-scale", growth_scale)),
                      slider_given=slider_given is not None, equilibrium=equilibrium)
        _save(fig, out, dpi)
        return
    require_fivdisc_netcdf(result, "fivdisc plot")
    if equilibrium:
        raise FivdiscError(f"--equilibrium is not used for {result}: only for a branch of "
                           "periodic orbits (fivdisc continue -o)")
    out = check_output(output or result.with_name(f"{result.stem}-{kind}.png"), "-o",
                       figure_suffixes(), inputs=[result])
    groups = _groups(result, run_groups)
    if run is not None and run not in groups:
        raise FivdiscError(f"--run {run!r} is invalid: {result} holds "
                           + (f"the runs {', '.join(groups)}" if groups else "one run; "
                              "leave --run out"))
    if run is None and len(groups) > 1:
        raise FivdiscError(f"{result} holds the runs {', '.join(groups)}: choose one with "
                           "--run LABEL")
    run = run if run is not None else (groups[0] if groups else None)
    with xr.open_dataset(result, group=run) as stored:
        what = stored.attrs.get("fivdisc_kind", "simulation")
    if what == "bistable_region":
        out = check_output(output or result.with_name(f"{result.stem}.png"), "-o",
                           figure_suffixes(), inputs=[result])
        check_netcdf(result)
        with xr.open_dataset(result, group=run) as stored:
            fig = plots.plot_bistable_region(stored.load())
        _save(fig, out, dpi)
        return
    if what in ("stability_map", "sweep", "eigen_branches", "stability_boundary"):
        unused = [name for name, value in (("--kind", kind_given), ("--var", var),
                                           ("--probe", probe), ("--slider", slider_given),
                                           ("--window", window_text), ("--fmax", fmax),
                                           ("--segment", segment)) if value is not None]
        if growth_scale is not None and what != "eigen_branches":
            unused.append("--growth-scale")
        if unused:
            drawn = {"stability_map": "a stability map", "sweep": "a sweep's map",
                     "eigen_branches": "eigenvalue branches",
                     "stability_boundary": "a stability boundary"}[what]
            choices = (" (--kind chooses among the figures of a simulation result)"
                       if unused[0] == "--kind" else "")
            raise FivdiscError(f"{unused[0]} is not used for {result}: it is {drawn}, drawn "
                               f"whole{choices}")
        check_netcdf(result)
        with xr.open_dataset(result, group=run) as stored:
            fig = _map(stored.load(), result, growth_scale or "auto")
    else:
        if growth_scale is not None:
            raise FivdiscError(f"--growth-scale is not used for {result}: only for "
                               "eigenvalue branches (fivdisc stability --x -o FILE.nc)")
        ds = open_result(result, run).dataset
        count = ds.sizes.get("slider", 1)
        if not 0 <= slider < count:
            raise FivdiscError(f"--slider {slider} is invalid: the run has {count} slider"
                               f"{'s' if count > 1 else ''}, numbered from 0")
        from fivdisc.engine.result import select_slider

        one = select_slider(ds, slider)
        if fmax is not None and kind not in ("spectrogram", "spectrum"):
            raise FivdiscError(f"--fmax is not used by --kind {kind}: only by spectrogram and "
                               "spectrum")
        if one.sizes["time"] < 2:  # drawn as a marker; a spectrum needs more
            if kind in ("spectrogram", "spectrum"):
                raise FivdiscError(
                    f"--kind {kind} needs at least 2 samples: {result} holds one (a run "
                    "shorter than its output interval, or one that failed at its start), "
                    "which has no frequencies; draw it with --kind timeseries, or simulate "
                    "longer or with a higher simulation.output_rate")
            if window_text is not None:
                raise FivdiscError(f"--window is not used for {result}: it holds one sample, "
                                   "drawn whole")
        else:
            check_fmax(fmax, 0.5 * (one.sizes["time"] - 1)
                             / float(one["time"].values[-1] - one["time"].values[0]), "--fmax")
        if segment is not None and kind != "spectrogram":
            raise FivdiscError(f"--segment is not used by --kind {kind}: only by spectrogram")
        name = _check(one, kind, var, probe)
        window = parse_window(window_text, one["time"].values)
        fig = plots.plot_kind(ds, kind, var=name, probe=probe, slider=slider, window=window,
                              fmax=fmax, segment=segment)
    _save(fig, out, dpi)


def _save(fig, out: Path, dpi: int) -> None:
    import matplotlib.pyplot as plt

    from fivdisc.files import write_atomic
    from fivdisc.limits import check_raster

    try:
        check_raster(fig, dpi)
        write_atomic(out, lambda path: fig.savefig(path, dpi=dpi))
    finally:
        plt.close(fig)
    click.echo(f"wrote {out}")


def _branch(path: Path, var: str | None, slider: int, unused, slider_given: bool,
            equilibrium: bool = False):
    """The figure of a branch (fivdisc continue -o): --var is the measure."""
    from fivdisc.continuation.branch import open_branch
    from fivdisc.plots.branch import BRANCH_MEASURES, plot_branch

    given = [name for name, value in unused if value is not None]
    if given:
        raise FivdiscError(f"{given[0]} is not used for {path}: it is a branch of periodic "
                           "orbits, drawn against its key (--var picks the measure)")
    measure = var or "period"
    if measure not in BRANCH_MEASURES:
        raise FivdiscError(f"--var {measure!r} is invalid for a branch: must be one of "
                           f"{', '.join(BRANCH_MEASURES)}")
    if measure == "period" and slider_given:
        raise FivdiscError("--slider is not used for --var period: the period is the "
                           "orbit's, not a slider's (give a measure such as phi_dot)")
    return plot_branch(open_branch(path), measure, slider, equilibrium=equilibrium)


def _groups(path: Path, run_groups) -> list[str]:
    try:
        return run_groups(path)
    except (OSError, ValueError) as exc:
        raise FivdiscError(f"cannot read {path} as a netCDF file of fivdisc: {exc}") from None


def _map(ds, path: Path, growth_scale: str = "auto"):
    """The figure of a stability map, branches, a boundary or a separation map."""
    kind = ds.attrs.get("fivdisc_kind")
    if kind in ("stability_map", "eigen_branches", "stability_boundary"):
        from fivdisc import plots

        if kind == "eigen_branches":
            return plots.plot_eigen_branches(ds, growth_scale=growth_scale)
        draw = {"stability_map": plots.plot_stability_map,
                "stability_boundary": plots.plot_stability_boundary}[kind]
        return draw(ds)
    if "separated" not in ds:
        raise FivdiscError(f"{path} is a sweep without 'separated': read it with "
                           "xarray.open_dataset")
    from fivdisc.plots.sweep import plot_separation_map

    return plot_separation_map(ds)
