"""Phase portraits, friction trajectories and separation (paper Figs. 17-19, 24, 27).

Functions take a result :class:`xarray.Dataset` or a :class:`fivdisc.engine.result.Result`
and a time window ``[t0, t1]`` [s] (default: the whole record).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from fivdisc.analysis.spectra import as_dataset, time_window
from fivdisc.engine.selection import select_slider

__all__ = ["friction_trajectory", "phase_portrait", "separation_intervals", "separation_stats"]

_SEPARATION = 2  # phase code of separation (see the dataset's flag_meanings)


def phase_portrait(data: xr.Dataset | object, t0: float | None = None,
                   t1: float | None = None, slider: int = 0) -> xr.Dataset:
    """Slider angle and angular velocity over a window (paper Fig. 17a, c, ...).

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    t0, t1 : float, optional
        Window [s].
    slider : int
        Which slider (from 0).

    Returns
    -------
    xarray.Dataset
        ``phi`` [rad] and ``phi_dot`` [rad/s] on the window's ``time``.

    Raises
    ------
    fivdisc.analysis.spectra.AnalysisError
        If the window is outside the data.
    """
    ds = select_slider(as_dataset(data), slider)
    return time_window(ds[["phi", "phi_dot"]], t0, t1)


def friction_trajectory(data: xr.Dataset | object, t0: float | None = None,
                        t1: float | None = None, slider: int = 0) -> xr.Dataset:
    """Friction force against relative sliding speed (paper Fig. 17b, d, ...).

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    t0, t1 : float, optional
        Window [s].
    slider : int
        Which slider (from 0).

    Returns
    -------
    xarray.Dataset
        ``relative_velocity`` = disc speed - slider angular velocity [rad/s] (zero
        while sticking) and ``friction_force`` [N] on the window's ``time``.

    Raises
    ------
    fivdisc.analysis.spectra.AnalysisError
        If the window is outside the data.
    """
    ds = select_slider(as_dataset(data), slider)
    ds = time_window(ds[["disc_speed", "phi_dot", "friction_force"]], t0, t1)
    relative = (ds["disc_speed"] - ds["phi_dot"]).assign_attrs(
        units="rad/s", long_name="relative angular velocity (disc minus slider)"
    )
    return xr.Dataset({"relative_velocity": relative, "friction_force": ds["friction_force"]},
                      attrs=ds.attrs)


def separation_intervals(data: xr.Dataset | object,
                         slider: int = 0) -> list[tuple[float, float]]:
    """Time intervals [s] in which a slider is separated from the disc.

    Taken from the event table (``separation`` to the next ``recontact`` event), which
    has the exact switch times; a dataset without one falls back to runs of
    ``phase == separation`` in the samples, exact only to one sample. An interval still
    open at the end of the record ends there; intervals are clipped to the record, so a
    time slice of a result gives the intervals within the slice.

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    slider : int
        Which slider (from 0).

    Returns
    -------
    list of (float, float)
        ``(start, end)`` pairs [s], in time order.
    """
    ds = select_slider(as_dataset(data), slider)
    time = ds["time"].values
    first, last = float(time[0]), float(time[-1])
    if "event_time" in ds and "event_kind" in ds:
        # The phase at the first event tells whether the run began separated.
        separated = bool(ds["event_from"].values[0] == _SEPARATION) if (
            "event_from" in ds and ds.sizes["event"]
        ) else bool(ds["phase"].values[0] == _SEPARATION)
        start = -np.inf
        bounds = []
        for when, kind in zip(ds["event_time"].values, ds["event_kind"].values, strict=True):
            if kind == "separation" and not separated:
                separated, start = True, float(when)
            elif kind == "recontact" and separated:
                separated = False
                bounds.append((start, float(when)))
        if separated:
            bounds.append((start, np.inf))
    else:
        flag = np.concatenate(([False], ds["phase"].values == _SEPARATION, [False]))
        edges = np.flatnonzero(np.diff(flag.astype(np.int8)))
        # A run of separated samples i..j-1 lasts until sample j, where contact is back.
        bounds = [(float(time[i]), float(time[min(j, time.size - 1)]))
                  for i, j in zip(edges[::2], edges[1::2], strict=True)]
    clipped = [(max(a, first), min(b, last)) for a, b in bounds]
    return [(a, b) for a, b in clipped if b > a]


def separation_stats(data: xr.Dataset | object, slider: int = 0) -> dict[str, float | int]:
    """How much a slider separates from the disc.

    Parameters
    ----------
    data : xarray.Dataset or Result
        Simulation result.
    slider : int
        Which slider (from 0).

    Returns
    -------
    dict
        ``count``: separation intervals; ``first_time``: start of the first [s] (nan
        if none); ``fraction``: share of the record spent separated; ``largest_gap``:
        maximum of ``gap`` [m] (0 if always in contact); ``impacts``: re-contact
        events of the slider, 0 when the run ignored impacts (attribute ``impact``
        false).

    Examples
    --------
    A kick of the first disc mode's velocity throws the slider off the disc once, for
    half a millisecond, until a plastic impact brings it back:

    >>> import fivdisc
    >>> case = fivdisc.Case(simulation={"duration": 0.02})
    >>> result = fivdisc.simulate(case, initial={"q_dot": [5.0, 0, 0, 0, 0, 0, 0]})
    >>> stats = fivdisc.separation_stats(result)
    >>> stats["count"], stats["impacts"]
    (1, 1)
    >>> print(f"from {stats['first_time'] * 1e3:.2f} ms, {stats['fraction']:.1%} of the "
    ...       f"run, largest gap {stats['largest_gap'] * 1e6:.2f} um")
    from 6.45 ms, 2.4% of the run, largest gap 4.36 um
    """
    ds = select_slider(as_dataset(data), slider)
    intervals = separation_intervals(ds)
    time = ds["time"].values
    span = float(time[-1] - time[0])
    separated = sum(b - a for a, b in intervals)
    impacts = 0
    if "event_kind" in ds and ds.attrs.get("impact", 1):
        t = ds["event_time"].values
        recontact = (ds["event_kind"].values == "recontact") & (t >= time[0]) & (t <= time[-1])
        impacts = int(np.sum(recontact))
    return {
        "count": len(intervals),
        "first_time": intervals[0][0] if intervals else float("nan"),
        "fraction": separated / span if span > 0 else 0.0,
        "largest_gap": float(np.nanmax(ds["gap"].values, initial=0.0)),
        "impacts": impacts,
    }
