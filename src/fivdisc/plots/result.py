"""Matplotlib figures of simulation results (the paper's Figs. 4-26) and stability maps.

Every function draws into ``ax`` (a new figure when None) and returns the Figure
without showing it. ``window`` is a time window ``(t0, t1)`` [s]; either end may be
None for the start or end of the record. Axis labels are the variables' ``long_name``
and ``units`` attributes; titles name the case (its ``case_name``, see
:meth:`fivdisc.Result.named`) and what is drawn. :func:`plot_kind` draws what
``fivdisc plot --kind KIND`` draws. Matplotlib (the ``plot`` extra) is imported only when
a figure is drawn.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from fivdisc.analysis.spectra import (
    AnalysisError,
    as_dataset,
    classify,
    find_peaks,
    series,
    spectrum,
    stft,
    time_window,
)
from fivdisc.analysis.trajectories import (
    friction_trajectory,
    phase_portrait,
    separation_intervals,
)
from fivdisc.engine.selection import select_slider
from fivdisc.plots.kinds import KINDS

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
from fivdisc.plots.text import (
    Window,
    disc_speed_axis,
    drawing,
    engineering_scale,
    fit_text,
    label_of,
    lone_coords,
    new_axes,
    set_title,
    set_two_line_title,
    where_text,
    window_bounds,
)

__all__ = [
    "check_fmax",
    "content_band",
    "default_segment",
    "plot_friction",
    "plot_kind",
    "plot_normal_force",
    "plot_phase_portrait",
    "plot_spectrogram",
    "plot_spectrum",
    "plot_timeseries",
]


# Default spectrogram segments: at least this many per record, and frequency bins at
# most this fraction of the frequency range shown.
_SEGMENTS_PER_RECORD = 100


_BINS_PER_RANGE = 50


# A spectrogram's figure [in]: wider than the default, for its colour bar beside it.
_WIDE = (8.0, 4.8)

# A time series drawn without a window shows its last this many oscillations.
_READABLE_CYCLES = 30


def _nyquist(ds: xr.Dataset) -> float:
    """Half the sampling rate of a result [Hz]; AnalysisError for a record of one sample."""
    time = ds["time"].values
    if time.size < 2:
        raise AnalysisError(f"the result holds {time.size} sample(s): frequencies need at "
                            "least 2 (a run shorter than its output interval?)")
    return 0.5 * (time.size - 1) / (time[-1] - time[0])


def check_fmax(fmax: float | None, nyquist: float, name: str = "fmax") -> None:
    """Refuse a highest frequency that is not positive or lies above the Nyquist frequency.

    Parameters
    ----------
    fmax
        The frequency [Hz], or None (no limit).
    nyquist
        Half the sampling rate of the data [Hz].
    name
        The parameter or option, for the message.

    Raises
    ------
    AnalysisError
        One line naming `name`, its value and the allowed range.
    """
    if fmax is None:
        return
    if not 0 < fmax <= nyquist * (1 + 1e-9):
        raise AnalysisError(f"{name} = {fmax:g} [Hz] is invalid: must be in (0, {nyquist:g}] "
                            "Hz, up to the Nyquist frequency (half the output rate)")


def content_band(da: xr.DataArray, nyquist: float, share: float = 0.999) -> float:
    """Default highest frequency of a spectrogram [Hz]: the frequency below which `share`
    of the series' power lies (its mean removed), with a fifth more room, rounded up to
    1, 2 or 5 times a power of ten; never above `nyquist`.

    Parameters
    ----------
    da
        The series (a time dimension only).
    nyquist
        Half the sampling rate [Hz].
    share
        Fraction of the power the band holds, in (0, 1].
    """
    values = np.asarray(da.values, dtype=float)
    values = values[np.isfinite(values)]
    if values.size < 4:
        return nyquist
    power = np.abs(np.fft.rfft(values - values.mean())) ** 2
    if not power.sum() > 0:
        return nyquist
    freqs = np.linspace(0.0, nyquist, power.size)
    edge = 1.2 * float(freqs[np.searchsorted(np.cumsum(power) / power.sum(), share)])
    if not edge > 0:
        return nyquist
    decade = 10.0 ** np.floor(np.log10(edge))
    step = next(s for s in (1.0, 2.0, 5.0, 10.0) if s * decade >= edge)
    return float(min(step * decade, nyquist))


def default_segment(duration: float, fmax: float) -> float:
    """Default STFT segment of a spectrogram [s], from the record and the frequencies shown.

    Long enough that the frequency bins (1 / segment) are at most 1/50 of the range shown,
    and short enough for at least 100 segments per record, whichever is longer; never
    more than a quarter of the record. Two significant digits.

    Parameters
    ----------
    duration
        Length of the record [s].
    fmax
        Highest frequency shown [Hz].
    """
    segment = min(max(_BINS_PER_RANGE / fmax, duration / _SEGMENTS_PER_RECORD), duration / 4)
    return float(f"{segment:.2g}")


@drawing
def plot_timeseries(data: xr.Dataset | object, var: str, probe: int | None = None,
                    window: Window = None, ax: Axes | None = None) -> Figure:
    """Time history of one variable (paper Figs. 8a, 9a, 12).

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    var : str
        Variable with a time dimension, e.g. ``"phi_dot"`` [rad/s] or ``"w"`` [m].
    probe : int, optional
        Index along the variable's second dimension (``w``: probe; default 0).
    window : (float, float), optional
        Time window [s].
    ax : matplotlib Axes, optional
        Where to draw.
    """
    ds = as_dataset(data)
    da = series(ds, var, probe, *window_bounds(window))
    fig, ax = new_axes(ax)
    if "flag_values" in da.attrs:
        ax.step(da["time"].values, da.values, where="post", **lone_coords(da))
        values = np.atleast_1d(da.attrs["flag_values"]).tolist()
        meanings = str(da.attrs.get("flag_meanings", "")).split()
        ax.set_yticks(values, meanings if len(meanings) == len(values) else None)
        ax.set_ylabel(label_of(da, var))
    else:
        factor, prefix = engineering_scale(da)
        ax.plot(da["time"].values, da.values * factor, lw=0.8, **lone_coords(da))
        ax.set_ylabel(label_of(da, var, prefix))
    ax.set_xlabel(label_of(da["time"], "time"))
    disc_speed_axis(ax, ds)
    set_title(ax, ds, str(da.attrs.get("long_name", var)), where_text(da))
    return fig


@drawing
def plot_spectrogram(data: xr.Dataset | object, var: str = "phi", probe: int | None = None,
                     window: Window = None, segment: float | None = None, overlap: float = 0.75,
                     taper: str | tuple = "hann", fmax: float | None = None,
                     dynamic_range: float = 60.0, ax: Axes | None = None) -> Figure:
    """Time-frequency plot: STFT magnitude on a log colour scale (paper Figs. 8b, 9b).

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    var : str
        Variable, e.g. ``"phi"`` [rad] or ``"w"`` [m].
    probe : int, optional
        Index along the variable's second dimension.
    window : (float, float), optional
        Time window [s].
    segment : float, optional
        STFT segment length [s]; default :func:`default_segment` of the window's length
        and the frequencies shown.
    overlap, taper
        Overlap fraction and scipy window of :func:`fivdisc.analysis.spectra.stft`.
    fmax : float, optional
        Highest frequency shown [Hz], up to the Nyquist frequency; default
        :func:`content_band`, the band that holds the variable's content.
    dynamic_range : float
        Magnitudes more than this below the maximum share the lowest colour [dB], > 0.
    ax : matplotlib Axes, optional
        Where to draw.
    """
    if not dynamic_range > 0:
        raise AnalysisError(f"dynamic_range = {dynamic_range!r} [dB] is invalid: must be > 0")
    ds = as_dataset(data)
    t0, t1 = window_bounds(window)
    nyquist = _nyquist(ds)
    check_fmax(fmax, nyquist)
    if fmax is None:
        fmax = content_band(series(ds, var, probe, t0, t1), nyquist)
    if segment is None:
        span = time_window(ds[["time"]], t0, t1)["time"].values
        segment = default_segment(float(span[-1] - span[0]), fmax or nyquist)
    mag = stft(ds, var, probe, window=taper, segment=segment, overlap=overlap, t0=t0, t1=t1)
    if fmax is not None:
        mag = mag.sel(frequency=slice(None, fmax))
    top = float(mag.max())
    fig, ax = new_axes(ax, figsize=_WIDE)
    from matplotlib.colors import LogNorm

    if top > 0:
        norm = LogNorm(vmin=top * 10 ** (-dynamic_range / 20), vmax=top, clip=True)
    else:
        norm = None
    mesh = ax.pcolormesh(mag["time"].values, mag["frequency"].values, mag.values.T,
                         shading="nearest", norm=norm, rasterized=True)
    units = mag.attrs.get("units", "")
    fig.colorbar(mesh, ax=ax, label=f"magnitude [{units}]" if units and units != "1"
                 else "magnitude")
    ax.set_xlabel(label_of(mag["time"], "time"))
    ax.set_ylabel(label_of(mag["frequency"], "frequency"))
    ax.set_xlim(*_span(ds, t0, t1))
    disc_speed_axis(ax, ds)
    long_name = ds[var].attrs.get("long_name", var)
    set_two_line_title(ax, ds, f"spectrogram of {long_name}", where_text(mag),
                       f"0-{fmax:g} Hz, {segment:g} s segments ({1 / segment:.3g} Hz bins)")
    return fig


def _span(ds: xr.Dataset, t0: float | None, t1: float | None) -> tuple[float, float]:
    """The time window's ends [s] within the record."""
    time = ds["time"].values
    return (float(time[0]) if t0 is None else max(float(t0), float(time[0])),
            float(time[-1]) if t1 is None else min(float(t1), float(time[-1])))


@drawing
def plot_spectrum(data: xr.Dataset | object, var: str = "phi", probe: int | None = None,
                  window: Window = None, taper: str | tuple = "hann", n_peaks: int = 10,
                  min_rel_height: float = 0.05, fmax: float | None = None,
                  ax: Axes | None = None) -> Figure:
    """Amplitude spectrum with its refined peaks marked and the periodicity in the title.

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    var : str
        Variable, e.g. ``"phi"`` [rad] or ``"w"`` [m].
    probe : int, optional
        Index along the variable's second dimension.
    window : (float, float), optional
        Time window [s]; pick a stationary stretch.
    taper : str or tuple
        scipy window of :func:`fivdisc.analysis.spectra.spectrum`.
    n_peaks, min_rel_height
        Passed to :func:`fivdisc.analysis.spectra.find_peaks`.
    fmax : float, optional
        Highest frequency shown and searched for peaks [Hz], up to the Nyquist frequency
        (the default).
    ax : matplotlib Axes, optional
        Where to draw.
    """
    ds = as_dataset(data)
    check_fmax(fmax, _nyquist(ds))
    t0, t1 = window_bounds(window)
    spec = spectrum(ds, var, probe, t0, t1, window=taper)
    peaks = find_peaks(spec, n=n_peaks, min_rel_height=min_rel_height, fmax=fmax)
    verdict = classify(peaks)
    fig, ax = new_axes(ax)
    shown = spec.amplitude > 0
    if fmax is not None:
        shown &= spec.frequencies <= fmax
    ax.semilogy(spec.frequencies[shown], spec.amplitude[shown], lw=0.8)
    ax.plot(peaks.frequencies, peaks.amplitudes, "v", color="C3", label="refined peaks [Hz]")
    if len(peaks):
        top = float(peaks.amplitudes.max())
        ax.set_ylim(top * 1e-4, top * 5)
    ax.set_xlim(0.0, float(spec.frequencies[shown][-1]) if shown.any() else fmax)
    _label_peaks(ax, peaks.frequencies, peaks.amplitudes)
    units = f" [{spec.units}]" if spec.units and spec.units != "1" else ""
    ax.set_ylabel(f"amplitude{units}")
    ax.set_xlabel("frequency [Hz]")
    set_title(ax, ds, f"spectrum of {spec.long_name}", where_text(series(ds, var, probe)),
           verdict.summary)
    if len(peaks):
        ax.legend(loc="upper right", fontsize="small")
    return fig


def _label_peaks(ax: Axes, frequencies: np.ndarray, amplitudes: np.ndarray) -> None:
    """Write each peak's frequency above it, strongest first, leaving out a label that
    would overlap one already written or leave the axes."""
    # Without a renderer argument the extents come from the figure's own renderer, which
    # also exists for figures made without pyplot (their canvas has no get_renderer).
    inside = ax.get_window_extent()
    written = []
    for f, a in zip(frequencies, amplitudes, strict=True):
        label = ax.annotate(f"{f:.1f}", (f, a), textcoords="offset points", xytext=(0, 5),
                            ha="center", fontsize="x-small")
        box = label.get_window_extent()
        if any(box.overlaps(other) for other in written) or not (
                inside.x0 <= box.x0 and box.x1 <= inside.x1 and box.y1 <= inside.y1):
            label.remove()
        else:
            written.append(box)


@drawing
def plot_phase_portrait(data: xr.Dataset | object, window: Window = None,
                        ax: Axes | None = None, slider: int = 0) -> Figure:
    """Slider angular velocity against angle (paper Fig. 17a, c, e, ...).

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    window : (float, float), optional
        Time window [s]; a short one (about 0.1 s) shows the limit cycle.
    ax : matplotlib Axes, optional
        Where to draw.
    slider : int
        Which slider (from 0).
    """
    ds = phase_portrait(data, *window_bounds(window), slider=slider)
    return _trajectory(ds, "phi", "phi_dot", "phase portrait of the slider", ax)


@drawing
def plot_friction(data: xr.Dataset | object, window: Window = None,
                  ax: Axes | None = None, slider: int = 0) -> Figure:
    """Friction force against relative angular velocity (paper Fig. 17b, d, f, ...).

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    window : (float, float), optional
        Time window [s].
    ax : matplotlib Axes, optional
        Where to draw.
    slider : int
        Which slider (from 0).
    """
    ds = friction_trajectory(data, *window_bounds(window), slider=slider)
    return _trajectory(ds, "relative_velocity", "friction_force",
                       "friction force against sliding speed", ax)


def _trajectory(ds: xr.Dataset, x: str, y: str, what: str, ax: Axes | None) -> Figure:
    """One variable of ``ds`` against another, labelled with names and units."""
    fig, ax = new_axes(ax)
    (fx, px), (fy, py) = engineering_scale(ds[x]), engineering_scale(ds[y])
    ax.plot(ds[x].values * fx, ds[y].values * fy, lw=0.8, **lone_coords(ds))
    ax.set_xlabel(label_of(ds[x], x, px))
    ax.set_ylabel(label_of(ds[y], y, py))
    time = ds["time"].values
    set_title(ax, ds, what, where_text(ds), f"{time[0]:g} s to {time[-1]:g} s")
    return fig


@drawing
def plot_normal_force(data: xr.Dataset | object, window: Window = None,
                      ax: Axes | None = None, slider: int = 0) -> Figure:
    """Normal contact force with separation intervals shaded (paper Figs. 18, 19, 24).

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    window : (float, float), optional
        Time window [s].
    ax : matplotlib Axes, optional
        Where to draw.
    slider : int
        Which slider (from 0).
    """
    ds = time_window(select_slider(as_dataset(data), slider), *window_bounds(window))
    force = ds["normal_force"]
    fig, ax = new_axes(ax)
    ax.plot(ds["time"].values, force.values, lw=0.8, **lone_coords(ds))
    for i, (start, end) in enumerate(separation_intervals(ds)):
        ax.axvspan(start, end, color="C1", alpha=0.3, lw=0,
                   label="separation" if i == 0 else None)
    if ax.get_legend_handles_labels()[1]:
        ax.legend(loc="upper right", fontsize="small")
    ax.set_xlabel(label_of(ds["time"], "time"))
    ax.set_ylabel(label_of(force, "normal_force"))
    set_title(ax, ds, str(force.attrs.get("long_name", "normal force")), where_text(ds))
    return fig


@drawing
def plot_kind(data: xr.Dataset | object, kind: str = "timeseries", var: str | None = None,
              probe: int | None = None, slider: int = 0, window: Window = None,
              fmax: float | None = None, segment: float | None = None,
              ax: Axes | None = None) -> Figure:
    """The figure ``fivdisc plot --kind KIND`` draws (and :meth:`fivdisc.Result.plot`).

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    kind : str
        One of :data:`KINDS`: ``timeseries``, ``spectrogram`` and ``spectrum`` of `var`;
        ``phase`` (portrait), ``friction`` (against sliding speed) and ``normal-force``
        of the slider.
    var : str, optional
        Variable of timeseries, spectrogram and spectrum [default: ``"phi"``].
    probe : int, optional
        Index along the variable's second dimension (``w``: probe).
    slider : int
        Which slider (from 0).
    window : (float, float), optional
        Time window [s].
    fmax : float, optional
        Highest frequency of spectrogram and spectrum [Hz].
    segment : float, optional
        STFT segment of spectrogram [s] (default: :func:`default_segment`).
    ax : matplotlib Axes, optional
        Where to draw.

    Raises
    ------
    AnalysisError
        An unknown kind, or an option the kind does not use.
    """
    if kind not in KINDS:
        raise AnalysisError(f"kind = {kind!r} is invalid: must be one of {', '.join(KINDS)}")
    spectral = ("spectrogram", "spectrum")
    unused = [name for name, value, users in (
        ("var", var, ("timeseries", *spectral)), ("probe", probe, ("timeseries", *spectral)),
        ("fmax", fmax, spectral), ("segment", segment, ("spectrogram",)))
        if value is not None and kind not in users]
    if unused:
        raise AnalysisError(f"{unused[0]} is not used by kind = {kind!r}: leave it out")
    full = as_dataset(data)
    ds = select_slider(full, slider)
    name = "phi" if var is None else var
    if name in full and "slider" not in full[name].dims and "slider" in full.dims:
        ds = full  # a disc variable (w, q, disc_speed): no slider to name
    if kind == "timeseries":
        note = ""
        if window is None:
            window, note = _readable_window(series(ds, name, probe))
        fig = plot_timeseries(ds, name, probe, window, ax=ax)
        if note:
            axes = fig.axes[0] if ax is None else ax
            axes.set_title(axes.get_title() + "\n" + fit_text(axes, note, "medium"),
                           fontsize="medium")
        return fig
    if kind == "spectrogram":
        return plot_spectrogram(ds, name, probe, window, segment=segment, fmax=fmax, ax=ax)
    if kind == "spectrum":
        return plot_spectrum(ds, name, probe, window, fmax=fmax, ax=ax)
    if kind == "phase":
        return plot_phase_portrait(ds, window, ax=ax)
    if kind == "friction":
        return plot_friction(ds, window, ax=ax)
    return plot_normal_force(ds, window, ax=ax)


def _readable_window(da: xr.DataArray) -> tuple[Window, str]:
    """The last stretch of a series that shows about ``_READABLE_CYCLES`` of its
    oscillations (counted by crossings of its mean), and a note saying so for the title;
    (None, "") when the whole record is readable."""
    values = np.asarray(da.values, dtype=float)
    time = da["time"].values
    if values.size < 3 or time[-1] <= time[0]:
        return None, ""
    above = values > np.nanmean(values)
    cycles = 0.5 * np.count_nonzero(above[1:] != above[:-1])
    if cycles <= _READABLE_CYCLES:
        return None, ""
    span = float(time[-1] - time[0])
    length = float(f"{span * _READABLE_CYCLES / cycles:.1g}")
    t0 = float(time[-1]) - length
    return (t0, None), (f"the last {length:g} s of {span:g} s shown (about "
                        f"{_READABLE_CYCLES} oscillations; --window for others)")
