"""Separation regions (paper section 3.3, Fig. 27): where the slider leaves the disc.

A separation map is a grid sweep over the initial disc speed and either the time
to stop (decelerating disc; each run lasts until the disc stops) or the
acceleration (accelerating disc; runs of a fixed duration), keeping ``separated``
and ``first_separation_time`` so that every run ends at its first separation.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal

from fivdisc.case import Case
from fivdisc.errors import SweepError
from fivdisc.sweep.spec import Sweep

if TYPE_CHECKING:
    pass

__all__ = [
    "DEFAULT_RANGES",
    "fig27_base",
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

_Y_KEY = {"decelerating": "speed.duration", "accelerating": "speed.rate"}


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
