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

import functools
import os
import sys
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, ParamSpec, TypeVar

import numpy as np
import xarray as xr

from fivdisc import _plot_kinds
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
from fivdisc.conventions import axis_label
from fivdisc.selection import select_slider

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "KINDS",
    "content_band",
    "default_segment",
    "plot_eigen_branches",
    "plot_friction",
    "plot_kind",
    "plot_normal_force",
    "plot_phase_portrait",
    "plot_spectrogram",
    "plot_spectrum",
    "plot_stability_boundary",
    "plot_stability_map",
    "plot_timeseries",
]

Window = tuple[float | None, float | None] | None
P = ParamSpec("P")
R = TypeVar("R")

# Defined apart, for the command line to list them without importing this module.
#: The kinds of figure of a simulation result (``fivdisc plot --kind``).
KINDS = _plot_kinds.KINDS
# Default spectrogram segments: at least this many per record, and frequency bins at
# most this fraction of the frequency range shown.
_SEGMENTS_PER_RECORD = 100
_BINS_PER_RANGE = 50
# A time series drawn without a window shows its last this many oscillations.
_READABLE_CYCLES = 30
# Average width of a character of the default font, in units of its size (for wrapping).
_CHAR_WIDTH = 0.6


def _drawing(function: Callable[P, R]) -> Callable[P, R]:
    """A function that draws: it checks for matplotlib (the plot extra) before any work."""

    @functools.wraps(function)
    def checked(*args: P.args, **kwargs: P.kwargs) -> R:
        from fivdisc.extras import require

        require("plot", "fivdisc.plots")
        return function(*args, **kwargs)

    return checked


def _axes(ax: Axes | None) -> tuple[Figure, Axes]:
    if ax is not None:
        return ax.figure, ax
    import matplotlib

    headless = sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
    )
    if headless and not os.environ.get("MPLBACKEND") and "matplotlib.pyplot" not in sys.modules:
        # An interactive backend chosen by the user's config would fail without a display;
        # one chosen for this process (MPLBACKEND, e.g. Jupyter's inline backend) stays.
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, new_ax = plt.subplots(layout="constrained")
    return fig, new_ax


def _label(da: xr.DataArray, fallback: str, prefix: str = "") -> str:
    name = da.attrs.get("long_name", fallback)
    units = da.attrs.get("units", "")
    return f"{name} [{prefix}{units}]" if units and units != "1" else name


# SI prefixes for axis values, so that ticks read 0.1 [mm] rather than 0.0001 [m].
_PREFIXES = {-9: "n", -6: "µ", -3: "m", 0: "", 3: "k", 6: "M"}
_SCALED_UNITS = ("m", "m/s", "rad", "rad/s", "N", "J")


def _engineering(da: xr.DataArray) -> tuple[float, str]:
    """(factor, prefix) that bring the largest |value| of `da` into [1, 1000) with an SI
    prefix of its unit; (1, "") for units not scaled (or rad/s, N beyond their ranges)."""
    units = da.attrs.get("units", "")
    values = np.abs(np.asarray(da.values, dtype=float))
    top = float(np.nanmax(values)) if values.size and np.isfinite(values).any() else 0.0
    if units not in _SCALED_UNITS or not top > 0:
        return 1.0, ""
    power = int(np.clip(3 * np.floor(np.log10(top) / 3), min(_PREFIXES), max(_PREFIXES)))
    if units == "rad" and power > 0:  # kilo-radians read worse than radians
        power = 0
    return 10.0 ** -power, _PREFIXES[power]


def _lone(data: xr.DataArray | xr.Dataset) -> dict[str, str]:
    """Line options that show a record of one sample (a line through one point draws
    nothing): a marker."""
    return {"marker": "o"} if data.sizes.get("time") == 1 else {}


def _bounds(window: Window) -> tuple[float | None, float | None]:
    if window is None:
        return None, None
    try:
        t0, t1 = window
    except (TypeError, ValueError):
        raise AnalysisError(f"window = {window!r} is invalid: must be a pair (t0, t1) [s] "
                            "or None") from None
    return t0, t1


def _where(da: xr.DataArray | xr.Dataset) -> str:
    """Which slider, probe or modal coordinate a series was taken at, for titles."""
    parts = []
    if "slider" in da.coords and da["slider"].ndim == 0:
        parts.append(f"slider {int(da['slider'])}")
    if "probe" in da.coords and da["probe"].ndim == 0:
        probe = f"probe {int(da['probe'])}"
        if "probe_r" in da.coords and "probe_theta" in da.coords:
            probe += f" (r = {float(da['probe_r']):g} m, θ = {float(da['probe_theta']):g} rad)"
        parts.append(probe)
    if "coordinate" in da.coords and da["coordinate"].ndim == 0:
        parts.append(f"coordinate {da['coordinate'].item()}")
    return ", ".join(parts)


def _title(ax: Axes, ds: xr.Dataset, what: str, where: str = "", detail: str = "") -> None:
    """Title: the case's name and what is drawn; the run and where; a detail."""
    name = str(ds.attrs.get("case_name", ""))
    title = str(ds.attrs.get("title", ""))
    run = title.split(": ", 1)[1] if ": " in title else ""
    lines = [f"{name}: {what}" if name else what, "; ".join(p for p in (run, where) if p),
             detail]
    ax.set_title(_fit(ax, "\n".join(line for line in lines if line), "medium"),
                 fontsize="medium")


def _fit(ax: Axes, text: str, size: str) -> str:
    """`text` wrapped to the width of `ax` (at font `size`), never inside $math$."""
    from matplotlib.font_manager import FontProperties

    points = FontProperties(size=size).get_size_in_points()
    width = ax.get_position().width * ax.figure.get_figwidth() * 72.0  # [pt]
    chars = max(20, int(width / (_CHAR_WIDTH * points)))
    # Spaces inside $...$ are kept from the line breaks.
    parts = text.split("$")
    parts[1::2] = [part.replace(" ", "\0") for part in parts[1::2]]
    wrapped = "\n".join(_fill_phrases(line, chars)
                         for line in "$".join(parts).split("\n"))
    return wrapped.replace("\0", " ")


def _fill_phrases(line: str, chars: int) -> str:
    """`line` broken only after ", " or "; " outside parentheses (never inside a phrase
    such as "slider circumferential angle"), at most about `chars` characters a line; a
    phrase longer than a line and a half is itself broken between words."""
    import textwrap

    phrases, start, depth = [], 0, 0
    for i, char in enumerate(line):
        depth += {"(": 1, ")": -1}.get(char, 0)
        if char in ",;" and depth == 0 and line[i + 1:i + 2] == " ":
            phrases.append(line[start:i + 1])
            start = i + 2
    phrases.append(line[start:])
    out: list[str] = []
    for phrase in phrases:
        if len(phrase) > 1.5 * chars:
            pieces = textwrap.wrap(phrase, chars, break_on_hyphens=False)
        else:
            pieces = [phrase]
        for piece in pieces:
            if out and len(out[-1]) + 1 + len(piece) <= chars:
                out[-1] += " " + piece
            else:
                out.append(piece)
    return "\n".join(out)


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


@_drawing
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
    da = series(ds, var, probe, *_bounds(window))
    fig, ax = _axes(ax)
    if "flag_values" in da.attrs:
        ax.step(da["time"].values, da.values, where="post", **_lone(da))
        values = np.atleast_1d(da.attrs["flag_values"]).tolist()
        meanings = str(da.attrs.get("flag_meanings", "")).split()
        ax.set_yticks(values, meanings if len(meanings) == len(values) else None)
        ax.set_ylabel(_label(da, var))
    else:
        factor, prefix = _engineering(da)
        ax.plot(da["time"].values, da.values * factor, lw=0.8, **_lone(da))
        ax.set_ylabel(_label(da, var, prefix))
    ax.set_xlabel(_label(da["time"], "time"))
    _title(ax, ds, str(da.attrs.get("long_name", var)), _where(da))
    return fig


@_drawing
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
    t0, t1 = _bounds(window)
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
    fig, ax = _axes(ax)
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
    ax.set_xlabel(_label(mag["time"], "time"))
    ax.set_ylabel(_label(mag["frequency"], "frequency"))
    long_name = ds[var].attrs.get("long_name", var)
    _title(ax, ds, f"spectrogram of {long_name}", _where(mag),
           f"0-{fmax:g} Hz, {segment:g} s segments ({1 / segment:.3g} Hz bins)")
    return fig


@_drawing
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
    t0, t1 = _bounds(window)
    spec = spectrum(ds, var, probe, t0, t1, window=taper)
    peaks = find_peaks(spec, n=n_peaks, min_rel_height=min_rel_height, fmax=fmax)
    verdict = classify(peaks)
    fig, ax = _axes(ax)
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
    _title(ax, ds, f"spectrum of {spec.long_name}", _where(series(ds, var, probe)),
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


@_drawing
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
    ds = phase_portrait(data, *_bounds(window), slider=slider)
    return _trajectory(ds, "phi", "phi_dot", "phase portrait of the slider", ax)


@_drawing
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
    ds = friction_trajectory(data, *_bounds(window), slider=slider)
    return _trajectory(ds, "relative_velocity", "friction_force",
                       "friction force against sliding speed", ax)


def _trajectory(ds: xr.Dataset, x: str, y: str, what: str, ax: Axes | None) -> Figure:
    """One variable of ``ds`` against another, labelled with names and units."""
    fig, ax = _axes(ax)
    (fx, px), (fy, py) = _engineering(ds[x]), _engineering(ds[y])
    ax.plot(ds[x].values * fx, ds[y].values * fy, lw=0.8, **_lone(ds))
    ax.set_xlabel(_label(ds[x], x, px))
    ax.set_ylabel(_label(ds[y], y, py))
    time = ds["time"].values
    _title(ax, ds, what, _where(ds), f"{time[0]:g} s to {time[-1]:g} s")
    return fig


@_drawing
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
    ds = time_window(select_slider(as_dataset(data), slider), *_bounds(window))
    force = ds["normal_force"]
    fig, ax = _axes(ax)
    ax.plot(ds["time"].values, force.values, lw=0.8, **_lone(ds))
    for i, (start, end) in enumerate(separation_intervals(ds)):
        ax.axvspan(start, end, color="C1", alpha=0.3, lw=0,
                   label="separation" if i == 0 else None)
    if ax.get_legend_handles_labels()[1]:
        ax.legend(loc="upper right", fontsize="small")
    ax.set_xlabel(_label(ds["time"], "time"))
    ax.set_ylabel(_label(force, "normal_force"))
    _title(ax, ds, str(force.attrs.get("long_name", "normal force")), _where(ds))
    return fig


@_drawing
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
            axes.set_title(axes.get_title() + "\n" + _fit(axes, note, "medium"),
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


@_drawing
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
    fig, ax = _axes(ax)
    xkey, ykey = ds.attrs["x_key"], ds.attrs["y_key"]
    ckey = ds.attrs.get("curve_key", "")
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
    _title(ax, ds, what, detail="no boundary in the grid: " + ", ".join(absent) if absent
           else "")
    return fig


@_drawing
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
    fig, ax = _axes(ax)
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
    _title(ax, ds, "exact stability boundary")
    return fig


@_drawing
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

    _axes(None)  # chooses a headless backend where needed
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
    _title(top, ds, "eigenvalue branches (thick: unstable)",
           detail="dotted: mode coupling; dots: Hopf points" if len(ds["coupling"]) or marks
           else "")
    return fig
