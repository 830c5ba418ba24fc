"""Poincare-type sections of a run: the values of one recorded variable at a section.

A :class:`Section` takes one output variable of a run (a time series of
:attr:`fivdisc.Result.dataset`: ``phi_dot``, ``normal_force``, ``w``, ``q``, ...; one
slider, probe or modal coordinate of it) at every time the trajectory crosses a section,
after a transient:

- ``at = "maxima"``: at the variable's local maxima. A sample larger than both of its
  neighbours is refined by the parabola through the three samples (its vertex). A run of
  equal samples larger than the samples on either side (a flat top, such as ``phi_dot``
  held at the disc speed while the slider sticks) is one maximum, of that value.
- ``at = "stick"``, ``"slip"``, ``"separation"``, ``"recontact"`` or ``"reversal"``: at
  every switch of that kind of the chosen slider, located by the integrator to 1e-12 s.
  The value is the one just before the switch (its left limit: what a velocity was
  before an impact, a friction force before the slider sticks), extrapolated to the
  switch from the last samples before it by the polynomial through the last four (fewer
  if the piece since the previous switch of any slider holds fewer).

Accuracy, for samples ``h = 1 / simulation.output_rate`` apart and a component of the
variable of amplitude ``A`` and angular frequency ``omega``: a maximum is within about
``0.024 A (omega h)^4`` (``0.064 M3 h^3`` for a third derivative bounded by ``M3``), a
value at a switch within ``A (omega h)^4`` (``M4 h^4``). At the default 10 kHz, a
225 Hz oscillation (the slider's own in-plane frequency in the paper's Table 1) gives
1e-5 and 4e-4 of its amplitude. Where the piece before a switch holds a single sample
or none (two switches closer than ``h``), the value is interpolated linearly between
the samples around the switch, to about ``h`` times the variable's rate of change.
Raise ``simulation.output_rate`` for more.
"""

from __future__ import annotations

import json
import math
import numbers
import re
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from fivdisc.errors import SweepError, nearest

if TYPE_CHECKING:
    from fivdisc.case import Case
    from fivdisc.engine.result import Result

__all__ = ["AT", "EVENT_AT", "VARIABLES", "Section", "Variable", "section_values"]

EVENT_AT = ("stick", "slip", "separation", "recontact", "reversal")
AT = ("maxima", *EVENT_AT)
_KEYS = ("variable", "at", "slider", "index", "after", "max_points", "name")
DEFAULT_MAX_POINTS = 100
_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
# Samples of the polynomial that extrapolates a variable to a switch (a cubic).
_EXTRAPOLATION_SAMPLES = 4


@dataclass(frozen=True)
class Variable:
    """A time series of a run's dataset, as a section reads it.

    Attributes
    ----------
    dim
        Its dimension besides time: ``"slider"``, ``"probe"``, ``"coordinate"``,
        ``"energy_term"``, or None.
    units
        Its units.
    long_name
        Its description.
    """

    dim: str | None
    units: str
    long_name: str


#: The time series of :attr:`fivdisc.Result.dataset` (as :func:`fivdisc.engine.result.build_dataset`
#: writes them), by name; a test keeps this table equal to a run's dataset.
VARIABLES: dict[str, Variable] = {
    "phi": Variable("slider", "rad", "slider circumferential angle"),
    "phi_dot": Variable("slider", "rad/s", "slider angular velocity"),
    "disc_speed": Variable(None, "rad/s", "disc spinning speed"),
    "normal_force": Variable("slider", "N", "normal contact force"),
    "friction_force": Variable("slider", "N",
                               "friction force on the slider (positive along +phi)"),
    "phase": Variable("slider", "1", "contact phase"),
    "z": Variable("slider", "m", "slider normal displacement"),
    "z_dot": Variable("slider", "m/s", "slider normal velocity"),
    "gap": Variable("slider", "m", "gap between slider and disc surface (positive when apart)"),
    "w": Variable("probe", "m", "disc transverse displacement at the probes"),
    "q": Variable("coordinate", "m", "modal coordinates"),
    "q_dot": Variable("coordinate", "m/s", "modal velocities"),
    "energy_work": Variable("energy_term", "J", "work done since t = 0 by each kind of force"),
}
_INDEXED = {"probe": "probe", "coordinate": "modal coordinate", "energy_term": "energy term"}


def _is_int(value: Any) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


@dataclass(frozen=True)
class Section:
    """Values of one recorded variable at a section of every run of a sweep.

    Parameters
    ----------
    variable
        A time series of the run's dataset (see :data:`VARIABLES`).
    at
        ``"maxima"`` (the variable's local maxima) or a kind of switch of `slider`:
        ``"stick"``, ``"slip"``, ``"separation"``, ``"recontact"``, ``"reversal"``.
    slider
        The slider whose variable is taken and, for a switch, whose switches (default
        0); only for a per-slider variable or a switch.
    index
        The probe (``w``), modal coordinate (``q``, ``q_dot``) or energy term
        (``energy_work``) taken (default 0); only for those variables.
    after
        Transient [s]: values at times before it are left out.
    max_points
        Values kept per point: the first `max_points` after `after`.
    name
        Name of the stored variable (default ``VARIABLE_AT``, with ``_J`` for a slider or
        index J other than 0); its count is stored as ``NAME_count``.
    where
        How error messages name the section, e.g. ``"reduce.section[0]"``.

    Raises
    ------
    SweepError
        A value that is not allowed; the message names it as ``WHERE.KEY``.
    """

    variable: str
    at: str = "maxima"
    slider: int | None = None
    index: int | None = None
    after: float = 0.0
    max_points: int = DEFAULT_MAX_POINTS
    name: str | None = None
    where: str = field(default="section", compare=False, repr=False)

    def __post_init__(self) -> None:
        set_ = object.__setattr__  # frozen dataclass: normalised fields are set once, here
        where = self.where
        if self.variable not in VARIABLES:
            raise SweepError(
                f"{where}.variable = {self.variable!r} is invalid: must be a recorded time "
                f"series of a run ({', '.join(VARIABLES)})"
                f"{nearest(str(self.variable), VARIABLES)}"
            )
        if self.at not in AT:
            raise SweepError(
                f"{where}.at = {self.at!r} is invalid: must be 'maxima' or a kind of switch "
                f"({', '.join(EVENT_AT)}){nearest(str(self.at), AT)}"
            )
        dim = VARIABLES[self.variable].dim
        if self.slider is not None:
            if not _is_int(self.slider) or self.slider < 0:
                raise SweepError(f"{where}.slider = {self.slider!r} is invalid: must be an "
                                 "integer >= 0 (a slider's index)")
            if dim != "slider" and self.at == "maxima":
                raise SweepError(
                    f"{where}.slider = {self.slider!r} is invalid for variable "
                    f"'{self.variable}' at 'maxima': it is not a per-slider variable"
                    + (f" (choose its {_INDEXED[dim]} with index)" if dim in _INDEXED else "")
                )
        elif dim == "slider" or self.at != "maxima":
            set_(self, "slider", 0)
        if self.index is not None:
            if dim not in _INDEXED:
                raise SweepError(
                    f"{where}.index = {self.index!r} is invalid for variable "
                    f"'{self.variable}': index chooses a probe (w), modal coordinate (q, q_dot) "
                    "or energy term (energy_work)"
                    + ("; choose a slider with slider" if dim == "slider" else "")
                )
            if not _is_int(self.index) or self.index < 0:
                raise SweepError(f"{where}.index = {self.index!r} is invalid: must be an "
                                 f"integer >= 0 (a {_INDEXED[dim]}'s index)")
        elif dim in _INDEXED:
            set_(self, "index", 0)
        for key in ("slider", "index"):
            if getattr(self, key) is not None:
                set_(self, key, int(getattr(self, key)))
        if (isinstance(self.after, bool) or not isinstance(self.after, numbers.Real)
                or not math.isfinite(self.after) or self.after < 0):
            raise SweepError(f"{where}.after = {self.after!r} is invalid: must be a number "
                             ">= 0 [s]")
        set_(self, "after", float(self.after))
        if not _is_int(self.max_points) or self.max_points < 1:
            raise SweepError(f"{where}.max_points = {self.max_points!r} is invalid: must be "
                             "an integer >= 1")
        set_(self, "max_points", int(self.max_points))
        if self.name is None:
            chosen = self.slider if dim == "slider" or dim is None else self.index
            suffix = f"_{chosen}" if chosen else ""
            set_(self, "name", f"{self.variable}_{self.at}{suffix}")
        elif not isinstance(self.name, str) or not _NAME.match(self.name):
            raise SweepError(f"{where}.name = {self.name!r} is invalid: must be a name of "
                             "letters, digits and _, starting with a letter")

    @classmethod
    def from_table(cls, table: Any, where: str) -> Section:
        """A section from a ``[[reduce.section]]`` table (or a Section, returned as is).

        Raises
        ------
        SweepError
            Not a table, an unknown key (with the nearest valid one), a missing
            ``variable`` or a value that is not allowed.
        """
        if isinstance(table, Section):
            return table
        if not isinstance(table, Mapping):
            raise SweepError(f"{where} = {table!r} is invalid: must be a table "
                             "([[reduce.section]]) with variable, at, ...")
        for key in table:
            if key not in _KEYS:
                raise SweepError(f"unknown key '{where}.{key}'"
                                 f"{nearest(f'{where}.{key}', [f'{where}.{k}' for k in _KEYS])}")
        if "variable" not in table:
            raise SweepError(f"{where}.variable is missing: name the recorded variable "
                             f"({', '.join(VARIABLES)})")
        return cls(**table, where=where)

    # --- what is stored ---------------------------------------------------------------

    @property
    def count_name(self) -> str:
        """Name of the stored number of values."""
        return f"{self.name}_count"

    @property
    def dim(self) -> str:
        """Name of the stored values' own dimension (besides the sweep's)."""
        return f"{self.name}_index"

    def to_dict(self) -> dict[str, Any]:
        """The section as plain data, every default filled in (without `where`)."""
        data = asdict(self)
        del data["where"]
        return data

    @property
    def selection(self) -> str:
        """Which slider, probe, coordinate or energy term: ``" of slider 0"``,
        ``" (probe 1)"``, or ""."""
        dim = VARIABLES[self.variable].dim
        if dim == "slider":
            return f" of slider {self.slider}"
        if dim in _INDEXED:
            return f" ({_INDEXED[dim]} {self.index})"
        return ""

    @property
    def where_taken(self) -> str:
        """Where the values are taken, e.g. ``"at its local maxima"``."""
        if self.at == "maxima":
            return "at its local maxima"
        return f"just before the {self.at} switches of slider {self.slider}"

    def attrs(self) -> dict[str, Any]:
        """CF attributes of the stored values."""
        variable = VARIABLES[self.variable]
        attrs = {
            "units": variable.units,
            "long_name": f"{variable.long_name}{self.selection} {self.where_taken}, from "
                         f"t = {self.after:g} s (NaN padded)",
            "ancillary_variables": self.count_name,
            "section": json.dumps(self.to_dict(), sort_keys=True),
        }
        return attrs

    def count_attrs(self) -> dict[str, str]:
        """CF attributes of the stored count."""
        return {"units": "1",
                "long_name": f"number of values of {self.name} (the rest is NaN padding)"}

    def empty(self) -> np.ndarray:
        """The stored values of a point without any: NaN."""
        return np.full(self.max_points, np.nan)

    # --- checks against the cases -----------------------------------------------------

    def problem(self, case: Case) -> str | None:
        """Why the section does not apply to `case` (a message's end), or None."""
        dim = VARIABLES[self.variable].dim
        sim = case.simulation
        if self.slider is not None and self.slider >= len(case.sliders):
            return (f"{self.where}.slider = {self.slider} is invalid: must be < "
                    f"{len(case.sliders)}, the number of sliders")
        if self.variable == "energy_work" and not sim.energy_balance:
            return (f"{self.where}.variable = 'energy_work' needs simulation.energy_balance "
                    "= true")
        if dim in _INDEXED:
            size = _size(case, dim)
            if self.index >= size:
                return (f"{self.where}.index = {self.index} is invalid: must be < {size}, the "
                        f"number of {_INDEXED[dim]}s")
        if self.after >= sim.duration:
            return (f"{self.where}.after = {self.after:g} is invalid: must be < "
                    f"simulation.duration = {sim.duration:g} s")
        return None

    # --- the values -------------------------------------------------------------------

    def __call__(self, result: Result) -> tuple[np.ndarray, int]:
        """The section's values in `result`: ``(max_points,)`` values, NaN padded, and
        how many are valid."""
        _, found = section_values(result, self)
        values = self.empty()
        count = min(found.size, self.max_points)
        values[:count] = found[:count]
        return values, count


def _size(case: Case, dim: str) -> int:
    """Entries of a run's dimension `dim` (probes, modal coordinates, energy terms)."""
    if dim == "probe":
        return len(case.simulation.probes)
    if dim == "coordinate":
        return sum(2 if int(l) > 0 else 1 for _, l in case.disc.modes)
    from fivdisc.model.layout import ENERGY_NAMES

    return len(ENERGY_NAMES)


def section_values(result: Result, section: Section) -> tuple[np.ndarray, np.ndarray]:
    """Every crossing of `section` in `result` after its transient, in time order.

    Parameters
    ----------
    result
        A run.
    section
        The section.

    Returns
    -------
    times : ndarray
        When [s]: the switches' times, the vertices of the refined maxima, the first
        sample of a flat top.
    values : ndarray
        The variable's values there, as float64.
    """
    ds = result.dataset
    var = ds[section.variable]
    dim = VARIABLES[section.variable].dim
    if dim == "slider":
        var = var.isel(slider=section.slider)
    elif dim is not None:
        var = var.isel({dim: section.index})
    t = ds["time"].values
    y = np.asarray(var.values, dtype=float)
    if section.at == "maxima":
        return _maxima(t, y, section.after)
    kinds = ds["event_kind"].values
    times = ds["event_time"].values
    mine = (kinds == section.at) & (ds["event_slider"].values == section.slider)
    mine = np.flatnonzero(mine & (times >= section.after))
    values = np.array([_left_value(t, y, times, e) for e in mine], dtype=float)
    return times[mine].astype(float), values


def _maxima(t: np.ndarray, y: np.ndarray, after: float) -> tuple[np.ndarray, np.ndarray]:
    """Times and values of the local maxima of samples `y` at `t` from `after` on:
    parabola-refined peaks and flat tops."""
    # Runs of equal samples: a flat top is one maximum.
    starts = np.flatnonzero(np.r_[True, y[1:] != y[:-1]])
    ends = np.r_[starts[1:], y.size] - 1
    level = y[starts]
    peak = np.zeros(starts.size, dtype=bool)
    peak[1:-1] = (level[1:-1] > level[:-2]) & (level[1:-1] > level[2:])
    peak &= t[starts] >= after
    values = level[peak].copy()
    times = t[starts[peak]].astype(float)
    single = starts[peak] == ends[peak]
    i = starts[peak][single]
    below, above = y[i - 1], y[i + 1]
    # Vertex of the parabola through the three samples (equally spaced).
    curvature = below - 2.0 * y[i] + above
    values[single] = y[i] - (above - below) ** 2 / (8.0 * curvature)
    times[single] += 0.5 * (t[i + 1] - t[i - 1]) * (below - above) / (2.0 * curvature)
    return times, values


def _left_value(t: np.ndarray, y: np.ndarray, times: np.ndarray, e: int) -> float:
    """The value of samples `y` just before switch `e` (of any slider, at `times`),
    extrapolated from the samples since the previous switch."""
    t_e = times[e]
    # Switches at the same instant share the piece before them.
    k = int(np.searchsorted(times, t_e, side="left"))
    t_prev = times[k - 1] if k > 0 else -np.inf
    last = int(np.searchsorted(t, t_e, side="right"))  # samples [0, last) are at <= t_e
    first = int(np.searchsorted(t, t_prev, side="right"))
    first = max(first, last - _EXTRAPOLATION_SAMPLES)
    if last - first >= 2:
        ts, ys = t[first:last], y[first:last]
        # Relative to the switch, in units of the spacing: a well-conditioned fit.
        scale = ts[-1] - ts[0]
        coef = np.polyfit((ts - t_e) / scale, ys, ts.size - 1)
        return float(coef[-1])
    if last == 0:
        return float(y[0])
    if last == t.size:
        return float(y[-1])
    return float(np.interp(t_e, t[last - 1 : last + 1], y[last - 1 : last + 1]))
