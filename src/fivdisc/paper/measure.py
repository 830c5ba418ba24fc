"""Numbers read off simulated responses, for comparison with the paper's statements.

Every function takes a result :class:`xarray.Dataset` (or a part of one with the
variables it needs) and returns plain numbers; :mod:`fivdisc.paper.figures` turns
them into the report's rows.
"""

from __future__ import annotations

import itertools

import numpy as np
import xarray as xr

from fivdisc.analysis import (
    Periodicity,
    classify,
    find_peaks,
    separation_intervals,
    spectrum,
    stft,
)
from fivdisc.analysis.spectra import Peaks

__all__ = [
    "DIVERGED",
    "common_frequencies",
    "dominant",
    "envelope",
    "hz",
    "line_count",
    "lines",
    "periodicity",
    "plateau_end",
    "ridge",
    "ridge_changes",
    "run_end",
    "separation",
]

# Below this the slow drift of the slider's mean angle, not an oscillation, dominates.
FMIN = 5.0  # [Hz]
# A run whose disc displacement exceeds this has left the model's range (a plate 2 mm
# thick deflecting by more than 10 cm): it diverged.
DIVERGED = 0.1  # [m]


def hz(values: float | list[float] | np.ndarray, digits: int = 1) -> str:
    """Frequencies as text, e.g. ``"180.9, 290.4 Hz"`` ("none" for no value)."""
    arr = np.atleast_1d(np.asarray(values, dtype=float))
    arr = arr[np.isfinite(arr)]
    if arr.size == 0:
        return "none"
    return ", ".join(f"{v:.{digits}f}" for v in arr) + " Hz"


def lines(ds: xr.Dataset, var: str, probe: int | None = None, t0: float | None = None,
          t1: float | None = None, n: int = 10, rel: float = 0.05) -> Peaks:
    """The strongest spectral lines of one variable in a time window, above :data:`FMIN`.

    Parameters
    ----------
    ds
        Result dataset.
    var
        Variable, e.g. ``"phi"`` [rad] or ``"w"`` [m].
    probe
        Probe index for ``w``.
    t0, t1
        Window [s].
    n
        Largest number of lines.
    rel
        Lines weaker than this fraction of the strongest are left out.
    """
    return find_peaks(spectrum(ds, var, probe, t0, t1), n=n, min_rel_height=rel, fmin=FMIN)


def dominant(ds: xr.Dataset, var: str, probe: int | None = None, t0: float | None = None,
             t1: float | None = None) -> float:
    """Frequency of the strongest line above :data:`FMIN` [Hz]; nan if there is none."""
    peaks = lines(ds, var, probe, t0, t1, n=1)
    return float(peaks.frequencies[0]) if len(peaks) else float("nan")


def periodicity(ds: xr.Dataset, var: str, probe: int | None = None, t0: float | None = None,
                t1: float | None = None) -> Periodicity:
    """Periodic, quasi-periodic or irregular, from the ten strongest lines of a window."""
    return classify(lines(ds, var, probe, t0, t1))


def common_frequencies(first: Peaks, second: Peaks, tol: float) -> list[float]:
    """Lines of `first` that `second` has too, within `tol` [Hz], ascending."""
    return sorted(
        float(f) for f in first.frequencies
        if second.frequencies.size and np.min(np.abs(second.frequencies - f)) <= tol
    )


def line_count(ds: xr.Dataset, var: str, t0: float, t1: float, probe: int | None = None,
               rel: float = 0.05) -> int:
    """Spectral lines of at least `rel` of the strongest in ``[t0, t1]``: a density measure."""
    return len(lines(ds, var, probe, t0, t1, n=1000, rel=rel))


def ridge(ds: xr.Dataset, var: str, probe: int | None = None,
          segment: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Strongest STFT frequency above :data:`FMIN` per segment.

    Returns
    -------
    times, frequencies
        Segment centres [s] and their strongest frequency [Hz] (resolution
        1 / `segment`).
    """
    mag = stft(ds, var, probe, segment=segment, overlap=0.5)
    freq = mag["frequency"].values
    band = freq >= FMIN
    return mag["time"].values, freq[band][np.argmax(mag.values[:, band], axis=1)]


def ridge_changes(freqs: np.ndarray, tol: float = 2.0) -> float:
    """Share of consecutive ridge values that differ by more than `tol` [Hz]: 0 for a
    stationary response, near 1 for one whose frequency glides all the time."""
    return float(np.mean(np.abs(np.diff(freqs)) > tol)) if freqs.size > 1 else 0.0


def plateau_end(times: np.ndarray, freqs: np.ndarray, rel: float = 0.03) -> float:
    """First time [s] the ridge leaves its opening value by more than `rel` for good.

    The opening value is the median of the ridge over its first quarter; nan if the
    ridge never leaves it.
    """
    ref = np.median(freqs[: max(1, freqs.size // 4)])
    away = np.abs(freqs - ref) > rel * ref
    if not away[-1]:
        return float("nan")
    back = np.flatnonzero(~away)
    return float(times[back[-1] + 1]) if back.size else float(times[0])


def envelope(ds: xr.Dataset, var: str, probe: int | None = None,
             width: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Peak-to-peak range of a variable in consecutive windows.

    Returns
    -------
    centres, ranges
        Window centres [s] and the variable's range in each [its units].
    """
    da = ds[var] if probe is None else ds[var].isel(probe=probe)
    time = ds["time"].values
    edges = np.arange(time[0], time[-1] + 1e-12, width)
    index = np.searchsorted(time, edges)
    values = da.values
    ranges = np.array([np.ptp(values[i:j]) if j > i else np.nan
                       for i, j in itertools.pairwise(index)])
    return 0.5 * (edges[:-1] + edges[1:]), ranges


def separation(ds: xr.Dataset) -> dict[str, float | int]:
    """Separation of a run: how often, first and last start, share of the time.

    Returns
    -------
    dict
        ``count``, ``first`` [s], ``last`` [s] (starts of the first and last
        separation; nan if none), ``fraction`` of the record spent separated.
    """
    intervals = separation_intervals(ds)
    time = ds["time"].values
    span = float(time[-1] - time[0]) if time.size > 1 else 0.0
    return {
        "count": len(intervals),
        "first": intervals[0][0] if intervals else float("nan"),
        "last": intervals[-1][0] if intervals else float("nan"),
        "fraction": sum(b - a for a, b in intervals) / span if span > 0 else 0.0,
    }


def run_end(ds: xr.Dataset) -> tuple[bool, str]:
    """Whether a run diverged, and how it ended, in words.

    A run diverges when the integrator fails or the disc's displacement exceeds
    :data:`DIVERGED`.
    """
    w = np.abs(ds["w"].values).max(axis=-1)
    big = np.flatnonzero(~(w <= DIVERGED))
    status = str(ds.attrs["status"])
    end = float(ds.attrs["end_time"])
    if big.size:
        when = float(ds["time"].values[big[0]])
        text = f"diverges: |w| > {DIVERGED:g} m from t = {when:.2f} s"
        if status not in ("success", "stopped"):
            text += f", integration fails at {end:.2f} s ({status.replace('_', ' ')})"
        return True, text
    if status not in ("success", "stopped"):
        return True, f"integration fails at t = {end:.2f} s ({status.replace('_', ' ')})"
    return False, f"bounded to {end:g} s (max |w| = {np.max(w):.2g} m)"
