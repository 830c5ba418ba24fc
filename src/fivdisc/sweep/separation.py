"""Separation regions (paper section 3.3, Fig. 27): where the slider leaves the disc.

A separation map is a grid sweep over the initial disc speed and either the time
to stop (decelerating disc; each run lasts until the disc stops) or the
acceleration (accelerating disc; runs of a fixed duration), keeping ``separated``
and ``first_separation_time`` so that every run ends at its first separation.
"""

from __future__ import annotations

import json
from os import PathLike
from typing import TYPE_CHECKING, Literal

import numpy as np
import xarray as xr

from fivdisc.case import Case
from fivdisc.conventions import axis_label
from fivdisc.errors import SweepError
from fivdisc.files import write_atomic
from fivdisc.sweep.spec import Sweep

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "DEFAULT_RANGES",
    "fig27_base",
    "plot_separation_map",
    "separation_sweep",
]

Profile = Literal["decelerating", "accelerating"]

KEEP = ("separated", "first_separation_time")

# (x, y) ranges of the maps: 40 x 40 points over the region where fivdisc's
# separation boundary lies for the Fig. 27 parameters.
DEFAULT_RANGES: dict[str, tuple[str, str]] = {
    "decelerating": ("2.0:20.0:40", "1.0:40.0:40"),
    "accelerating": ("2.0:20.0:40", "0.05:2.0:40"),
}
DEFAULT_ACCELERATING_DURATION = 20.0  # [s]

# Recording is not needed to find separations (they are events), so the default
# base case samples sparsely to keep long runs light.
_SPARSE_OUTPUT_RATE = 100.0  # [Hz]

_DPI = 150
_Y_KEY = {"decelerating": "speed.duration", "accelerating": "speed.rate"}
_LABELS = {
    ("decelerating", "speed.initial"): r"initial disc speed $\Omega_0$ [rad/s]",
    ("decelerating", "speed.duration"): r"time to stop $t_{\max}$ [s]",
    ("accelerating", "speed.initial"): r"initial disc speed $\Omega_1$ [rad/s]",
    ("accelerating", "speed.rate"): r"acceleration $c$ [rad/s$^2$]",
}


def fig27_base() -> Case:
    """The paper's Fig. 27 case: Table 1 with c_z = 0.1 N s/m, r0^2 c_phi = 0.1 N m s/rad,
    alpha = 1 s/m, starting at rest, sampled at 100 Hz."""
    return Case(
        slider={"normal_damping": 0.1, "rotational_damping": 0.1},
        friction={"decay": 1.0},
        simulation={"initial_state": "rest", "output_rate": _SPARSE_OUTPUT_RATE},
    )


def separation_sweep(
    profile: Profile = "decelerating",
    x: str | list[float] | None = None,
    y: str | list[float] | None = None,
    base: Case | None = None,
    duration: float | None = None,
) -> Sweep:
    """The grid sweep of a separation map.

    Parameters
    ----------
    profile
        ``"decelerating"``: x is Omega_0 [rad/s], y is t_max [s], and each run lasts
        t_max (until the disc stops). ``"accelerating"``: x is Omega_1 [rad/s], y is
        c [rad/s^2], and each run lasts `duration`.
    x, y
        Axis values, ``"start:stop:n"`` or a list (default :data:`DEFAULT_RANGES`).
    base
        The case the points start from (default :func:`fig27_base`); its speed
        table is replaced.
    duration
        Simulated time of accelerating runs [s] (default 20 s); not allowed for
        decelerating runs.

    Raises
    ------
    SweepError
        Unknown profile, or `duration` given for a decelerating map.
    """
    if profile not in _Y_KEY:
        raise SweepError(
            f"profile = {profile!r} is invalid: must be 'decelerating' or 'accelerating'"
        )
    default_x, default_y = DEFAULT_RANGES[profile]
    base = base if base is not None else fig27_base()
    link: dict[str, str] = {}
    if profile == "decelerating":
        if duration is not None:
            raise SweepError(
                f"duration = {duration!r} is invalid for a decelerating disc: each run lasts "
                "until the disc stops (speed.duration)"
            )
        base = base.replace({"speed.profile": "decelerating"})
        link["simulation.duration"] = "speed.duration"
    else:
        if duration is None:
            duration = DEFAULT_ACCELERATING_DURATION
        base = base.replace({"speed.profile": "accelerating", "simulation.duration": duration})
    axes = {
        "speed.initial": x if x is not None else default_x,
        _Y_KEY[profile]: y if y is not None else default_y,
    }
    return Sweep(base=base, axes=axes, mode="grid", keep=KEEP, link=link)


def _profile_of(grid: xr.Dataset) -> str:
    """Speed profile of the sweep's base case."""
    return json.loads(grid.attrs["sweep_definition"])["base"]["speed"]["profile"]


def plot_separation_map(
    data: xr.Dataset | str | PathLike[str], path: str | PathLike[str] | None = None,
    ax: Axes | None = None,
) -> Figure:
    """Draw a separation map like the paper's Fig. 27.

    Separated points are filled markers over a shaded separation region (SR); points
    without separation are open markers, failed points crosses, and points not yet
    computed are left out.

    Parameters
    ----------
    data
        A two-axis grid sweep keeping ``separated`` (a dataset from
        :func:`~fivdisc.sweep.store.open_sweep`, or the store's path).
    path
        Image file to write (format from its suffix); None only returns the figure.
    ax
        Axes to draw into (the legend then goes into them); None: a new figure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from fivdisc.extras import require
    from fivdisc.sweep.store import open_sweep

    require("plot", "a separation map")
    from matplotlib.figure import Figure

    grid = data if isinstance(data, xr.Dataset) else open_sweep(data)
    if len(grid.dims) != 2 or "separated" not in grid or grid.attrs.get("sweep_mode") != "grid":
        raise SweepError(
            "a separation map needs a grid sweep over two axes keeping 'separated'; got "
            f"dimensions {list(grid.dims)} and variables {list(grid.data_vars)}"
        )
    x_key, y_key = json.loads(grid.attrs["sweep_axes"])
    grid = grid.transpose(x_key, y_key)
    profile = _profile_of(grid)
    xs, ys = grid[x_key].values, grid[y_key].values
    done = grid["done"].values.astype(bool)
    failed = done & (grid["error"].values != "")
    separated = done & ~failed & grid["separated"].values.astype(bool)
    clear = done & ~failed & ~separated
    X, Y = np.meshgrid(xs, ys, indexing="ij")

    if ax is None:
        fig = Figure(figsize=(6.0, 4.8), layout="constrained")
        ax = fig.add_subplot()
        legend = fig
    else:
        fig = ax.figure
        legend = ax
    if separated.any() and len(xs) > 1 and len(ys) > 1:
        ax.contourf(X, Y, separated.astype(float), levels=[0.5, 1.5], colors=["0.85"])
        ax.contour(X, Y, separated.astype(float), levels=[0.5], colors=["0.3"], linewidths=1.0)
    marker = float(np.clip(60.0 / max(len(xs), len(ys)), 2.0, 7.0))
    ax.plot(X[separated], Y[separated], "o", color="k", ms=marker, label="separation")
    ax.plot(X[clear], Y[clear], "o", mfc="none", color="0.4", ms=marker, label="no separation")
    if failed.any():
        ax.plot(X[failed], Y[failed], "x", color="tab:red", ms=marker, label="run failed")
    if separated.any():
        # under the markers, so that it hides none
        ax.text(
            X[separated].mean(),
            Y[separated].mean(),
            "SR",
            ha="center",
            va="center",
            fontsize=14,
            fontweight="bold",
            color="0.45",
            zorder=1,
        )
    for key, set_label in ((x_key, ax.set_xlabel), (y_key, ax.set_ylabel)):
        set_label(_LABELS.get((profile, key), axis_label(grid[key])))
    # Half a grid step around the points, so that markers on the edges show whole.
    for values, set_lim in ((xs, ax.set_xlim), (ys, ax.set_ylim)):
        pad = 0.5 * (values.max() - values.min()) / max(len(values) - 1, 1) or 0.5
        set_lim(values.min() - pad, values.max() + pad)
    name = grid.attrs.get("case_name", "")
    ax.set_title(f"{name + ': ' if name else ''}separation region (SR), {profile} disc",
                 fontsize="medium")
    if legend is fig:
        # Outside the axes, so that it hides no point.
        fig.legend(loc="outside upper center", ncol=3, fontsize="small", frameon=False)
    else:
        ax.legend(loc="upper left", fontsize="small", framealpha=0.9)
    if path is not None:
        write_atomic(path, lambda p: fig.savefig(p, dpi=_DPI))
    return fig

