"""``fivdisc plot RESULT.nc --kind KIND [--var NAME] [--probe I] [--slider J] [--window T0:T1]
-o FIG.png``."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from fivdisc.errors import FivdiscError

KINDS = ("timeseries", "spectrogram", "spectrum", "phase", "friction", "normal-force")
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
@click.option("--kind", type=click.Choice(KINDS), default="timeseries", show_default=True,
              help="What to plot.")
@click.option("--var", default=None,
              help="Variable for timeseries, spectrogram and spectrum [default: phi].")
@click.option("--probe", type=int, default=None,
              help="Index along the variable's second dimension (w: probe) [default: 0].")
@click.option("--slider", type=int, default=0, show_default=True,
              help="Which slider's variables (phi, normal_force, ...) and events to plot.")
@click.option("--window", "window_text", metavar="T0:T1", default=None,
              help="Time window in s; either side may be empty [default: all].")
@click.option("--fmax", type=float, default=None,
              help="Highest frequency shown by spectrogram and spectrum [Hz].")
@click.option("--segment", type=float, default=None,
              help="STFT segment length of spectrogram [s] [default: 0.05].")
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="Figure file; the format follows the extension [default: RESULT-KIND.png].")
@click.option("--dpi", type=click.IntRange(min=10), default=150, show_default=True,
              help="Resolution of raster formats.")
def plot(result: Path, kind: str, var: str | None, probe: int | None, slider: int,
         window_text: str | None, fmax: float | None, segment: float | None,
         output: Path | None, dpi: int) -> None:
    """Plot a simulation RESULT (netCDF written by ``fivdisc simulate``) to a file."""
    import xarray as xr

    from fivdisc import plots
    from fivdisc.files import check_output, figure_suffixes, write_atomic
    from fivdisc.limits import check_raster
    from fivdisc.result import select_slider

    out = check_output(output or result.with_name(f"{result.stem}-{kind}.png"), "-o",
                       figure_suffixes(), inputs=[result])
    try:
        with xr.open_dataset(result) as stored:
            ds = stored.load()
    except FileNotFoundError:
        # The command group reports a missing file itself.
        raise
    except (OSError, ValueError) as exc:
        raise FivdiscError(f"cannot read {result} as a netCDF result: {exc}") from None
    if "time" not in ds.coords or ds.sizes["time"] < 2:
        raise FivdiscError(f"{result} has no time coordinate: is it a fivdisc result?")
    count = ds.sizes.get("slider", 1)
    if not 0 <= slider < count:
        raise FivdiscError(f"--slider {slider} is invalid: the run has {count} slider"
                           f"{'s' if count > 1 else ''}, numbered from 0")
    ds = select_slider(ds, slider)
    if fmax is not None and kind not in ("spectrogram", "spectrum"):
        raise FivdiscError(f"--fmax is not used by --kind {kind}: only by spectrogram and "
                           "spectrum")
    if fmax is not None and not fmax > 0:
        raise FivdiscError(f"--fmax {fmax:g} is invalid: must be > 0 [Hz]")
    if segment is not None and kind != "spectrogram":
        raise FivdiscError(f"--segment is not used by --kind {kind}: only by spectrogram")
    name = _check(ds, kind, var, probe)
    window = parse_window(window_text, ds["time"].values)

    if kind == "timeseries":
        fig = plots.plot_timeseries(ds, name, probe, window)
    elif kind == "spectrogram":
        fig = plots.plot_spectrogram(ds, name, probe, window, fmax=fmax,
                                     segment=0.05 if segment is None else segment)
    elif kind == "spectrum":
        fig = plots.plot_spectrum(ds, name, probe, window, fmax=fmax)
    elif kind == "phase":
        fig = plots.plot_phase_portrait(ds, window)
    elif kind == "friction":
        fig = plots.plot_friction(ds, window)
    else:
        fig = plots.plot_normal_force(ds, window)

    import matplotlib.pyplot as plt

    try:
        check_raster(fig, dpi)
        write_atomic(out, lambda path: fig.savefig(path, dpi=dpi))
    finally:
        plt.close(fig)
    click.echo(f"wrote {out}")
