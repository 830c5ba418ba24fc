"""Bounds on the work a request may start: checked before anything is computed or allocated.

Each check estimates what a request needs (memory, or the cost of the disc modes) and
refuses it with a one-line :class:`~fivdisc.errors.FivdiscError` that names the
parameters, their values and what to change, instead of running out of memory or running
for hours.

Mode limits (:data:`MAX_NODAL_CIRCLES`, :data:`MAX_NODAL_DIAMETERS`, :data:`MAX_MODES`,
:data:`MIN_RADIUS_RATIO`) keep ``fivdisc modes`` on any valid case to a few seconds
(measured: at most 2.4 s for 31 modes at the limits, over radius ratios from 1e-3 to
0.99999 and Poisson ratios from -0.999 to 0.4999; ``tests/case/test_bounded_work.py``). Below the
radius ratio the root finder of :mod:`fivdisc.model.plate` loses roots (the hub's Bessel columns
overflow) and slows down without bound.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from fivdisc.errors import FivdiscError

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "MAX_MODES",
    "MAX_NODAL_CIRCLES",
    "MAX_NODAL_DIAMETERS",
    "MAX_RASTER_SIDE",
    "MAX_SHOOTING_RTOL",
    "MAX_SHOOTING_TOL",
    "MAX_SLIDERS",
    "MIN_RADIUS_RATIO",
    "MIN_SHOOTING_RTOL",
    "MIN_SHOOTING_TOL",
    "available_memory",
    "check_memory",
    "check_raster",
    "check_simulation",
    "disc_problem",
    "duration_words",
    "physical_memory",
    "simulation_bytes",
]

MAX_NODAL_CIRCLES = 15
MAX_NODAL_DIAMETERS = 30
MAX_MODES = 32
MIN_RADIUS_RATIO = 1e-3
#: Most sliders of a case: the contact solve of each right-hand side grows as the cube of
#: their number, and a switch re-checks every slider (measured: 1.8 s to choose the
#: phases at the start of 100 sliders, 0.2 s per 20 steps; 1000 never got past the start).
MAX_SLIDERS = 100
#: Integration tolerances a periodic orbit's shooting runs accept: below the lower, the
#: error control asks for less than double precision's round-off (unbounded work); above
#: the upper, as for ``simulation.rtol``, the integrator no longer resolves the dynamics.
MIN_SHOOTING_RTOL = 1e-14
MAX_SHOOTING_RTOL = 0.1
#: Shooting residuals (relative to the orbit's size) an orbit may be converged to: above
#: the upper, the first return of a transient already meets it (0.5 % on Table 1) and
#: the "orbit" is a trajectory that does not close; below the lower, round-off.
MIN_SHOOTING_TOL = 1e-14
MAX_SHOOTING_TOL = 1e-4
#: Largest raster side matplotlib's Agg renderer draws [pixels].
MAX_RASTER_SIDE = 2**16 - 1
# Share of the available memory one request may plan to use.
_MEMORY_SHARE = 0.8
# Share of the machine's memory below which a request is not checked against what is
# available now (1/64: 384 MiB of 24 GiB, 32 MiB of 2 GiB).
_SMALL_SHARE = 1 / 64
# float64 values held per output sample of a run with n modal coordinates and p probes:
# the kernel's state and auxiliary buffers (2 n + 9), the dataset's copies of them
# (2 n + 12 + p) and the netCDF writer's copy of the largest variables (2 n + 2); about
# twice the peak measured (275 bytes per sample for n = 7, p = 2).
_SAMPLE_DOUBLES = (6, 23)  # 6 n + 23 + p
_GiB = 2.0**30


def available_memory() -> int:
    """Memory the machine can give this process now [bytes] (psutil's "available")."""
    import psutil

    return int(psutil.virtual_memory().available)


def physical_memory() -> int:
    """The machine's memory [bytes], or 0 where the system does not say (no import)."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):  # os.sysconf is not on every system
        return 0


def _size(nbytes: float) -> str:
    return f"{nbytes / _GiB:.3g} GiB"


def duration_words(seconds: float) -> str:
    """A duration in the unit a person reads it in: "40 s", "12 min", "3.2 h", "4.1 days"."""
    for unit, size in (("days", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= 2 * size:
            return f"{seconds / size:.2g} {unit}"
    return f"{seconds:.2g} s"


def check_memory(nbytes: float, what: str, change: str) -> None:
    """Refuse a request whose estimated memory exceeds what the machine has available.

    Parameters
    ----------
    nbytes
        Estimated need [bytes].
    what
        The request, e.g. ``"simulation.duration = 1e+05 s at simulation.output_rate =
        1e+04 Hz (1e+09 samples)"``.
    change
        What to change, e.g. ``"lower simulation.output_rate or simulation.duration"``.

    Raises
    ------
    FivdiscError
        If `nbytes` exceeds 80 % of the available memory (asked only for a need above
        1/64 of the machine's memory: a smaller one fits unless the machine is nearly
        out of memory already).
    """
    if nbytes <= _SMALL_SHARE * physical_memory():
        # Refusing this would take a machine nearly out of memory already; the check then
        # costs more than the work it guards (psutil's import, 15 ms of a 0.5 s command).
        return
    have = available_memory()
    if not nbytes <= _MEMORY_SHARE * have:
        raise FivdiscError(
            f"{what} needs about {_size(nbytes)} of memory, but {_size(have)} is available: "
            f"{change}"
        )


def disc_problem(
    inner_radius: float, outer_radius: float, modes: Sequence[tuple[int, int]]
) -> tuple[str, Any, str] | None:
    """Why a disc's mode request exceeds the limits, or None if it does not.

    Returns
    -------
    (key, value, rule) or None
        `key` relative to the ``[disc]`` table (``"modes"`` or ``"inner_radius"``), the
        offending value and the rule it breaks.
    """
    if len(modes) > MAX_MODES:
        return "modes", modes, f"must have at most {MAX_MODES} modes (got {len(modes)})"
    for i, (k, l) in enumerate(modes):
        if k > MAX_NODAL_CIRCLES or l > MAX_NODAL_DIAMETERS:
            return (
                f"modes[{i}]",
                [k, l],
                f"must have k <= {MAX_NODAL_CIRCLES} nodal circles and l <= "
                f"{MAX_NODAL_DIAMETERS} nodal diameters (higher modes are too stiff to "
                "integrate in reasonable time)",
            )
    if inner_radius < MIN_RADIUS_RATIO * outer_radius:
        return (
            "inner_radius",
            inner_radius,
            f"must be >= {MIN_RADIUS_RATIO:g} * disc.outer_radius = "
            f"{MIN_RADIUS_RATIO * outer_radius!r} [m] (the disc modes cannot be computed "
            "reliably for a smaller hub)",
        )
    return None


def simulation_bytes(case: Any) -> float:
    """Estimated peak memory of one run of a :class:`fivdisc.case.Case` and its result [bytes].

    Proportional to the recorded samples, ``simulation.duration * simulation.output_rate``,
    and to the modal coordinates (one per l = 0 mode, two per l >= 1 mode) and probes.
    """
    sim = case.simulation
    n = sum(1 if l == 0 else 2 for _, l in case.disc.modes)
    count = sim.duration * sim.output_rate
    samples = math.floor(count) + 1 if math.isfinite(count) else math.inf
    per_sample = _SAMPLE_DOUBLES[0] * n + _SAMPLE_DOUBLES[1] + len(sim.probes)
    return 8.0 * samples * per_sample


def check_simulation(case: Any) -> None:
    """Refuse a case whose recorded output would not fit in memory.

    Parameters
    ----------
    case
        A :class:`fivdisc.case.Case`.

    Raises
    ------
    FivdiscError
        Naming ``simulation.duration`` and ``simulation.output_rate`` and what to change.
    """
    sim = case.simulation
    check_memory(
        simulation_bytes(case),
        f"simulation.duration = {sim.duration!r} s at simulation.output_rate = "
        f"{sim.output_rate!r} Hz ({sim.duration * sim.output_rate:.3g} samples)",
        "lower simulation.output_rate or simulation.duration",
    )


def check_raster(figure: Figure, dpi: float, option: str = "--dpi") -> None:
    """Refuse a resolution at which `figure` cannot be drawn as a raster image.

    Parameters
    ----------
    figure
        The figure, whose size [in] is set.
    dpi
        Resolution [pixels/in].
    option
        The option that gave `dpi`, named in the message.

    Raises
    ------
    FivdiscError
        If a side exceeds :data:`MAX_RASTER_SIDE` pixels or the image would not fit in
        memory; the message gives the largest resolution allowed.
    """
    width, height = figure.get_size_inches()
    largest = int(MAX_RASTER_SIDE / max(width, height))
    pixels = (width * dpi, height * dpi)
    if max(pixels) > MAX_RASTER_SIDE:
        raise FivdiscError(
            f"{option} {dpi:g} is invalid: the {width:g} x {height:g} in figure would be "
            f"{pixels[0]:.0f} x {pixels[1]:.0f} pixels; must be <= {largest} (at most "
            f"{MAX_RASTER_SIDE} pixels a side)"
        )
    # RGBA, plus the encoder's copy.
    check_memory(
        8.0 * pixels[0] * pixels[1],
        f"{option} {dpi:g} ({pixels[0]:.0f} x {pixels[1]:.0f} pixels)",
        f"lower {option}",
    )
