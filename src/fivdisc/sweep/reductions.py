"""Per-run reductions: the numbers a sweep keeps from each simulation.

Built-in reductions are named (see :data:`BUILTIN`); user reductions are named by
import path, ``"package.module:function"``, and are called with the run's
:class:`~fivdisc.engine.result.Result`, returning a real number (stored as float64).

A reduction whose value may not be usable brings its mark along: keeping
``largest_lyapunov`` stores ``largest_lyapunov_inconclusive`` too (see :data:`COMPANIONS`
and :func:`stored`).

A reduction that is final once some event has happened (``separated`` after the
first separation) lets the run stop there; see :func:`stop_events`. Sections
(:class:`fivdisc.sweep.sections.Section`) keep many values per run and need it whole.
"""

from __future__ import annotations

import importlib
import math
import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from functools import cache, lru_cache, partial
from typing import TYPE_CHECKING, Any

from fivdisc.case import Case
from fivdisc.engine.result import Result
from fivdisc.errors import FivdiscError, SweepError, nearest

if TYPE_CHECKING:
    from fivdisc.sweep.sections import Section

__all__ = [
    "BUILTIN",
    "COMPANIONS",
    "LYAPUNOV_REDUCTIONS",
    "LyapunovSettings",
    "Reduction",
    "RunFailed",
    "SweepError",
    "evaluate",
    "resolve",
    "stop_events",
    "stored",
]


class RunFailed(FivdiscError):
    """A simulation of a sweep point did not end as requested."""


@dataclass(frozen=True)
class Reduction:
    """One stored quantity.

    Attributes
    ----------
    spec
        As written in ``reduce.keep``.
    name
        Variable name in the store (the function's name for a user reduction).
    dtype
        ``"bool"`` or ``"float64"``.
    units
        Units of the value.
    long_name
        Description, stored as the variable's ``long_name``.
    decided_by
        Event kinds after which the value is final, so the run may stop at the
        first of them; None if the value needs the whole run.
    needs_run
        Whether the value comes from a simulation (False: from the case alone).
    func
        ``func(result, case) -> value``; `result` is None when `needs_run` is False.
    """

    spec: str
    name: str
    dtype: str
    units: str
    long_name: str
    decided_by: tuple[str, ...] | None
    needs_run: bool
    func: Callable[[Result | None, Case], Any]

    def __call__(self, result: Result | None, case: Case) -> bool | float:
        """The value for one run, checked and converted to the stored type."""
        value = self.func(result, case)
        if self.dtype == "bool":
            return bool(value)
        if not isinstance(value, numbers.Real):
            raise RunFailed(
                f"reduction '{self.spec}' returned {value!r} ({type(value).__name__}): "
                "must be a real number"
            )
        return float(value)

    @property
    def fill(self) -> bool | float:
        """Value stored before the point is computed and when it fails."""
        return False if self.dtype == "bool" else math.nan


def _first_separation(result: Result | None, case: Case) -> float:
    times = result.events("separation")
    return float(times[0]) if times.size else math.nan


def _phase_fraction(phase: str) -> Callable[[Result | None, Case], float]:
    def fraction(result: Result | None, case: Case) -> float:
        shares = [
            slider.time_in_phase[phase] / sum(slider.time_in_phase.values())
            for slider in result.summary().sliders
            if sum(slider.time_in_phase.values()) > 0
        ]
        return sum(shares) / len(shares) if shares else math.nan

    return fraction


def _dominant_frequency(result: Result | None, case: Case) -> float:
    from fivdisc.analysis.spectra import dominant_frequency

    return dominant_frequency(result.dataset, var="phi")


def _max_growth_rate(result: Result | None, case: Case) -> float:
    from fivdisc.analysis.stability import linear_stability

    return linear_stability(case).max_growth_rate


@dataclass(frozen=True)
class LyapunovSettings:
    """How the ``largest_lyapunov`` reduction measures (``[reduce.largest_lyapunov]``).

    The exponent is measured from `transient` for `duration` (see
    :func:`fivdisc.lyapunov`), in a run of its own that carries a tangent
    vector, through the transient too.

    Attributes
    ----------
    transient
        Simulated time before the measurement [s]; None: a fifth of the point's
        ``simulation.duration``. A sweep with sections defaults it to their largest
        ``after``.
    duration
        Length of the measurement [s]; None: until the point's ``simulation.duration``,
        the window the sections see.
    interval
        Re-orthonormalisation interval [s]; None: 0.05 s, or the measurement's duration
        when shorter.
    """

    transient: float | None = None
    duration: float | None = None
    interval: float | None = None

    def window(self, case: Case) -> tuple[float, float]:
        """(transient, duration) [s] of the measurement for `case`."""
        end = case.simulation.duration
        transient = 0.2 * end if self.transient is None else self.transient
        duration = end - transient if self.duration is None else self.duration
        return transient, duration


@lru_cache(maxsize=2)
def _lyapunov_run(case: Case, settings: LyapunovSettings) -> Any:
    """The exponent's run, once for both reductions that read it."""
    from fivdisc.analysis.exponents import lyapunov

    transient, duration = settings.window(case)
    return lyapunov(case, n=1, transient=transient, duration=duration,
                    interval=settings.interval)


def _largest_lyapunov(result: Result | None, case: Case,
                      settings: LyapunovSettings | None = None) -> float:
    return _lyapunov_run(case, settings or LyapunovSettings()).largest


def _largest_lyapunov_uncertainty(result: Result | None, case: Case,
                                  settings: LyapunovSettings | None = None) -> float:
    return float(_lyapunov_run(case, settings or LyapunovSettings()).uncertainty[0])


def _largest_lyapunov_inconclusive(result: Result | None, case: Case,
                                   settings: LyapunovSettings | None = None) -> bool:
    return not _lyapunov_run(case, settings or LyapunovSettings()).conclusive[0]


def _builtin(
    name: str,
    func: Callable[[Result | None, Case], Any],
    units: str,
    long_name: str,
    dtype: str = "float64",
    decided_by: tuple[str, ...] | None = None,
    needs_run: bool = True,
) -> Reduction:
    return Reduction(name, name, dtype, units, long_name, decided_by, needs_run, func)


BUILTIN: dict[str, Reduction] = {
    r.name: r
    for r in (
        _builtin(
            "separated",
            lambda result, case: result.events("separation").size > 0,
            "1",
            "a slider separated from the disc at least once",
            dtype="bool",
            decided_by=("separation",),
        ),
        _builtin(
            "first_separation_time",
            _first_separation,
            "s",
            "time of the first separation of any slider (nan if none)",
            decided_by=("separation",),
        ),
        _builtin(
            "stick_fraction",
            _phase_fraction("stick"),
            "1",
            "fraction of the output samples' time spent in stick (mean over sliders)",
        ),
        _builtin(
            "separation_fraction",
            _phase_fraction("separation"),
            "1",
            "fraction of the output samples' time spent in separation (mean over sliders)",
        ),
        _builtin(
            "max_abs_w",
            lambda result, case: result.summary().max_abs_w,
            "m",
            "largest |w| at the probes",
        ),
        _builtin(
            "max_normal_force",
            lambda result, case: result.summary().peak_normal_force,
            "N",
            "largest normal contact force of any slider",
        ),
        _builtin(
            "dominant_frequency",
            _dominant_frequency,
            "Hz",
            "dominant frequency of the angle phi of slider 0",
        ),
        _builtin(
            "max_growth_rate",
            _max_growth_rate,
            "1/s",
            "largest real part of the linearised system's eigenvalues (constant speed)",
            needs_run=False,
        ),
        _builtin(
            "largest_lyapunov",
            _largest_lyapunov,
            "1/s",
            "largest Lyapunov exponent, over a run of its own with a tangent vector "
            "(settings: [reduce.largest_lyapunov])",
            needs_run=False,
        ),
        _builtin(
            "largest_lyapunov_uncertainty",
            _largest_lyapunov_uncertainty,
            "1/s",
            "uncertainty of largest_lyapunov: the standard error from ten blocks of the "
            "measurement combined with the drift from its second half (the same run)",
            needs_run=False,
        ),
        _builtin(
            "largest_lyapunov_inconclusive",
            _largest_lyapunov_inconclusive,
            "1",
            "largest_lyapunov is inconclusive: its uncertainty is unknown or larger than "
            "its magnitude (even its sign is not known), or it is positive where the "
            "motion stays near a periodic orbit (its sticks recur regularly)",
            dtype="bool",
            needs_run=False,
        ),
    )
}

#: The reductions that read the Lyapunov run, set by ``[reduce.largest_lyapunov]``.
LYAPUNOV_REDUCTIONS = ("largest_lyapunov", "largest_lyapunov_uncertainty",
                       "largest_lyapunov_inconclusive")

#: Built-in reductions stored whenever another is kept: the mark that says whether its
#: value can be used, so that no reader sees the value without it.
COMPANIONS: dict[str, tuple[str, ...]] = {
    "largest_lyapunov": ("largest_lyapunov_inconclusive",),
}


def stored(keep: Sequence[str]) -> tuple[str, ...]:
    """The reductions a sweep keeping `keep` stores, in order: each kept one followed by
    its companions (:data:`COMPANIONS`) that `keep` does not list itself."""
    names: list[str] = []
    for spec in keep:  # a spec given twice stays twice: resolve refuses it, naming it
        names += [spec, *(name for name in COMPANIONS.get(spec, ())
                          if name not in keep and name not in names)]
    return tuple(names)

# Modules the built-ins import when they run: checked up front so that a missing one
# stops the sweep before it starts rather than failing every point.
_NEEDS_MODULE = {
    "dominant_frequency": "fivdisc.analysis.spectra",
    "max_growth_rate": "fivdisc.analysis.stability",
    "largest_lyapunov": "fivdisc.analysis.exponents",
    "largest_lyapunov_uncertainty": "fivdisc.analysis.exponents",
    "largest_lyapunov_inconclusive": "fivdisc.analysis.exponents",
}


def _user(spec: str) -> Reduction:
    """A user reduction from ``"package.module:function"``."""
    where = f"reduce.keep: '{spec}'"
    module_name, _, attr = spec.partition(":")
    if not module_name or not attr.isidentifier():
        raise SweepError(
            f"{where} is invalid: must be a built-in reduction"
            f"{nearest(spec, BUILTIN)} ({', '.join(BUILTIN)}) or 'package.module:function'"
        )
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise SweepError(f"{where} is invalid: cannot import '{module_name}' ({exc})") from None
    func = getattr(module, attr, None)
    if not callable(func):
        names = [n for n in vars(module) if callable(getattr(module, n)) and not n.startswith("_")]
        raise SweepError(
            f"{where} is invalid: '{module_name}' has no function '{attr}'{nearest(attr, names)}"
        )
    doc = (func.__doc__ or "").strip().splitlines()
    return Reduction(
        spec=spec,
        name=attr,
        dtype="float64",
        units="",
        long_name=doc[0] if doc else spec,
        decided_by=None,
        needs_run=True,
        func=lambda result, case: func(result),
    )


@cache
def _resolve(keep: tuple[str, ...], lyapunov: LyapunovSettings | None) -> tuple[Reduction, ...]:
    reductions = []
    for spec in stored(keep):
        if ":" in spec:
            reductions.append(_user(spec))
            continue
        if spec not in BUILTIN:
            raise SweepError(
                f"reduce.keep: unknown reduction '{spec}'{nearest(spec, BUILTIN)}; built-in are "
                f"{', '.join(BUILTIN)}, or give a user one as 'package.module:function'"
            )
        if spec in _NEEDS_MODULE:
            try:
                importlib.import_module(_NEEDS_MODULE[spec])
            except ImportError as exc:
                raise SweepError(
                    f"reduce.keep: reduction '{spec}' needs {_NEEDS_MODULE[spec]}, which cannot "
                    f"be imported ({exc})"
                ) from None
        reduction = BUILTIN[spec]
        if spec in LYAPUNOV_REDUCTIONS and lyapunov is not None:
            reduction = replace(reduction, func=partial(reduction.func, settings=lyapunov))
        reductions.append(reduction)
    seen: dict[str, str] = {}
    for r in reductions:
        if r.name in seen or r.name in ("error", "done"):
            other = seen.get(r.name, "the sweep's own variable")
            raise SweepError(
                f"reduce.keep: '{r.spec}' and '{other}' would both be stored as '{r.name}'"
            )
        seen[r.name] = r.spec
    return tuple(reductions)


def resolve(keep: Sequence[str], lyapunov: LyapunovSettings | None = None
            ) -> tuple[Reduction, ...]:
    """The reductions named in `keep` and their companions (see :func:`stored`), checked
    (user functions are imported).

    Parameters
    ----------
    keep
        Reduction names, as in ``reduce.keep``.
    lyapunov
        Settings of ``largest_lyapunov`` (default: :class:`LyapunovSettings`'s).

    Raises
    ------
    SweepError
        An unknown built-in (with the nearest name), an import path that does not
        resolve to a function, or two reductions with the same stored name.
    """
    for spec in keep:
        if not isinstance(spec, str):
            raise SweepError(f"reduce.keep entry {spec!r} is invalid: must be a string")
    return _resolve(tuple(keep), lyapunov)


def stop_events(reductions: Sequence[Reduction]) -> tuple[str, ...]:
    """Event kinds at which a run may stop: those that decide every kept value.

    Reductions computed from the case alone do not constrain the run; any
    reduction that needs the whole run means no early stop (an empty tuple).
    """
    kinds: set[str] = set()
    for r in reductions:
        if not r.needs_run:
            continue
        if r.decided_by is None:
            return ()
        kinds.update(r.decided_by)
    return tuple(sorted(kinds))


def evaluate(
    case: Case,
    keep: Sequence[str],
    sections: Sequence[Section] = (),
    lyapunov: LyapunovSettings | None = None,
) -> dict[str, Any]:
    """Simulate one case (if any kept reduction or section needs it) and reduce the run.

    Parameters
    ----------
    case
        The point's case.
    keep
        Reduction names, as in ``reduce.keep``.
    sections
        Sections whose values to take from the run.
    lyapunov
        Settings of ``largest_lyapunov``.

    Returns
    -------
    dict
        Stored name -> value: a bool or float per reduction; per section its
        ``(max_points,)`` values (NaN padded) and, under its ``count_name``, how many
        are valid.

    Raises
    ------
    RunFailed
        The run did not end as requested (its status and message are given), or a
        user reduction returned something other than a real number.
    """
    # Imported here: the simulator loads xarray, which validating a sweep does not need.
    from fivdisc.engine.simulation import simulate

    reductions = resolve(keep, lyapunov)
    result = None
    if sections or any(r.needs_run for r in reductions):
        result = simulate(case, stop_on=() if sections else stop_events(reductions))
        if not result.ok:
            raise RunFailed(f"simulation {result.status}: {result.message}")
    values: dict[str, Any] = {r.name: r(result, case) for r in reductions}
    for section in sections:
        values[section.name], values[section.count_name] = section(result)
    return values
