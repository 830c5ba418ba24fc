"""Matplotlib figures of simulation results (the paper's Figs. 4-26).

Every function draws into ``ax`` (a new figure when None) and returns the Figure
without showing it. ``window`` is a time window ``(t0, t1)`` [s]; either end may be
None for the start or end of the record. Axis labels are the variables' ``long_name``
and ``units`` attributes. Matplotlib is imported only when a figure is drawn.
"""

from __future__ import annotations

import os
import sys
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
from fivdisc.result import select_slider

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "plot_friction",
    "plot_normal_force",
    "plot_phase_portrait",
    "plot_spectrogram",
    "plot_spectrum",
    "plot_timeseries",
]

Window = tuple[float | None, float | None] | None


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


def _label(da: xr.DataArray, fallback: str) -> str:
    name = da.attrs.get("long_name", fallback)
    units = da.attrs.get("units", "")
    return f"{name} [{units}]" if units and units != "1" else name


def _bounds(window: Window) -> tuple[float | None, float | None]:
    if window is None:
        return None, None
    try:
        t0, t1 = window
    except (TypeError, ValueError):
        raise AnalysisError(f"window = {window!r} is invalid: must be a pair (t0, t1) [s] "
                            "or None") from None
    return t0, t1


def _where(da: xr.DataArray) -> str:
    """Title naming the probe or modal coordinate a 1-D series was taken at."""
    if "probe" in da.coords and da["probe"].ndim == 0:
        parts = [f"probe {int(da['probe'])}"]
        if "probe_r" in da.coords and "probe_theta" in da.coords:
            parts.append(f"r = {float(da['probe_r']):g} m, θ = {float(da['probe_theta']):g} rad")
        return ": ".join(parts)
    if "coordinate" in da.coords and da["coordinate"].ndim == 0:
        return f"coordinate {da['coordinate'].item()}"
    return ""


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
    da = series(data, var, probe, *_bounds(window))
    fig, ax = _axes(ax)
    if "flag_values" in da.attrs:
        ax.step(da["time"].values, da.values, where="post")
        values = np.atleast_1d(da.attrs["flag_values"]).tolist()
        meanings = str(da.attrs.get("flag_meanings", "")).split()
        ax.set_yticks(values, meanings if len(meanings) == len(values) else None)
    else:
        ax.plot(da["time"].values, da.values, lw=0.8)
    ax.set_xlabel(_label(da["time"], "time"))
    ax.set_ylabel(_label(da, var))
    ax.set_title(_where(da))
    return fig


def plot_spectrogram(data: xr.Dataset | object, var: str = "phi", probe: int | None = None,
                     window: Window = None, segment: float = 0.05, overlap: float = 0.75,
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
    segment, overlap, taper
        Segment length [s], overlap fraction and scipy window of
        :func:`fivdisc.analysis.spectra.stft`.
    fmax : float, optional
        Highest frequency shown [Hz]; default the Nyquist frequency.
    dynamic_range : float
        Magnitudes more than this below the maximum share the lowest colour [dB], > 0.
    ax : matplotlib Axes, optional
        Where to draw.
    """
    from matplotlib.colors import LogNorm

    if not dynamic_range > 0:
        raise AnalysisError(f"dynamic_range = {dynamic_range!r} [dB] is invalid: must be > 0")
    t0, t1 = _bounds(window)
    mag = stft(data, var, probe, window=taper, segment=segment, overlap=overlap, t0=t0, t1=t1)
    if fmax is not None:
        if not fmax > 0:
            raise AnalysisError(f"fmax = {fmax!r} [Hz] is invalid: must be > 0")
        mag = mag.sel(frequency=slice(None, fmax))
    top = float(mag.max())
    fig, ax = _axes(ax)
    if top > 0:
        norm = LogNorm(vmin=top * 10 ** (-dynamic_range / 20), vmax=top, clip=True)
    else:
        norm = None
    mesh = ax.pcolormesh(mag["time"].values, mag["frequency"].values, mag.values.T,
                         shading="nearest", norm=norm, rasterized=True)
    fig.colorbar(mesh, ax=ax, label=_label(mag, "STFT magnitude"))
    ax.set_xlabel(_label(mag["time"], "time"))
    ax.set_ylabel(_label(mag["frequency"], "frequency"))
    ax.set_title(_where(mag))
    return fig


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
        Highest frequency shown and searched for peaks [Hz]; default the Nyquist frequency.
    ax : matplotlib Axes, optional
        Where to draw.
    """
    t0, t1 = _bounds(window)
    spec = spectrum(data, var, probe, t0, t1, window=taper)
    peaks = find_peaks(spec, n=n_peaks, min_rel_height=min_rel_height, fmax=fmax)
    verdict = classify(peaks)
    fig, ax = _axes(ax)
    shown = spec.amplitude > 0
    if fmax is not None:
        shown &= spec.frequencies <= fmax
    ax.semilogy(spec.frequencies[shown], spec.amplitude[shown], lw=0.8)
    ax.plot(peaks.frequencies, peaks.amplitudes, "v", color="C3", label="refined peaks")
    for f, a in zip(peaks.frequencies, peaks.amplitudes, strict=True):
        ax.annotate(f"{f:.1f}", (f, a), textcoords="offset points", xytext=(0, 6),
                    ha="center", fontsize="x-small")
    if len(peaks):
        top = float(peaks.amplitudes.max())
        ax.set_ylim(top * 1e-4, top * 3)
    units = f" [{spec.units}]" if spec.units and spec.units != "1" else ""
    ax.set_ylabel(f"amplitude of {spec.long_name}{units}")
    ax.set_xlabel("frequency [Hz]")
    ax.set_title(f"{spec.name}\n{verdict.summary}", fontsize="small")
    if len(peaks):
        ax.legend(loc="upper right", fontsize="small")
    return fig


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
    return _trajectory(phase_portrait(data, *_bounds(window), slider=slider), "phi", "phi_dot",
                       ax)


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
    return _trajectory(ds, "relative_velocity", "friction_force", ax)


def _trajectory(ds: xr.Dataset, x: str, y: str, ax: Axes | None) -> Figure:
    """One variable of ``ds`` against another, labelled with names and units."""
    fig, ax = _axes(ax)
    ax.plot(ds[x].values, ds[y].values, lw=0.8)
    ax.set_xlabel(_label(ds[x], x))
    ax.set_ylabel(_label(ds[y], y))
    return fig


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
    ax.plot(ds["time"].values, force.values, lw=0.8)
    for i, (start, end) in enumerate(separation_intervals(ds)):
        ax.axvspan(start, end, color="C1", alpha=0.3, lw=0,
                   label="separation" if i == 0 else None)
    if ax.get_legend_handles_labels()[1]:
        ax.legend(loc="upper right", fontsize="small")
    ax.set_xlabel(_label(ds["time"], "time"))
    ax.set_ylabel(_label(force, "normal_force"))
    return fig


def plot_stability_map(ds: xr.Dataset, ax: Axes | None = None) -> Figure:
    """Stability map of :func:`fivdisc.analysis.stability.stability_map` (paper Fig. 3).

    With one curve the map is shaded by the sign of the largest growth rate; with several,
    only their boundary curves are drawn ('stable' lies above each curve).

    Parameters
    ----------
    ds : xarray.Dataset
        The map's dataset.
    ax : matplotlib Axes, optional
        Where to draw.
    """
    fig, ax = _axes(ax)
    x, y = ds["x"].values, ds["y"].values
    if ds.sizes["curve"] == 1:
        ax.contourf(x, y, ds["stable"].values[0], levels=[-0.5, 0.5, 1.5],
                    colors=["#f4c7c3", "#c6e5c3"])
        ax.plot([], [], color="#c6e5c3", lw=8, label="stable")
        ax.plot([], [], color="#f4c7c3", lw=8, label="unstable")
    for i, value in enumerate(ds["curve"].values):
        label = f"{ds.attrs['curve_key']} = {value:g}" if ds.attrs["curve_key"] else "boundary"
        ax.plot(x, ds["boundary"].values[i], lw=1.5, label=label)
    from fivdisc.case import unit_of

    for key, set_label in ((ds.attrs["x_key"], ax.set_xlabel), (ds.attrs["y_key"], ax.set_ylabel)):
        unit = unit_of(key)
        set_label(f"{key} [{unit}]" if unit else key)
    ax.set_xlim(x[0], x[-1])
    ax.set_ylim(y[0], y[-1])
    ax.legend(loc="best", fontsize="small")
    return fig
