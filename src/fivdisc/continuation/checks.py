"""Checks of a continuation's key, target and window, before any work."""

from __future__ import annotations

import numpy as np

from fivdisc.case import Case, is_case_key
from fivdisc.errors import CaseError, FivdiscError


def full_key(key: str, option: str = "key") -> str:
    """The dotted case key of `key`, which may be its last part alone (``normal_damping``
    for ``slider.normal_damping``), as the stability scans take it; a one-line error for
    an unknown or ambiguous one."""
    if is_case_key(key):
        return key
    from fivdisc.analysis.stability import resolve_key

    return resolve_key(key, option)


def check_key(case: Case, key: str, option: str = "key") -> float:
    """The current value of a numeric case key, or a one-line error.

    Raises
    ------
    CaseError
        The key is unknown, a simulation setting, or not a single number (a table, a
        list, a name, a switch).
    """
    if not is_case_key(key):
        from fivdisc.analysis.stability import resolve_key

        key = resolve_key(key, option)
    if key.startswith("simulation."):
        raise CaseError(f"{option} = {key!r} is invalid: the simulation settings do not "
                        "change the system, so its periodic orbits do not depend on them; "
                        "continue in a key of disc, slider(s), friction or speed")
    value = case.get(key)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise CaseError(f"{option} = {key!r} is invalid: its value {value!r} is not a number; "
                        "continuation needs a numeric key")
    return float(value)


def check_window(key: str, p0: float, to: float, back_to: float, option: str = "back_to"
                 ) -> None:
    """A one-line refusal of a window's far end ``back_to`` that is not finite or lies
    between the start's value ``p0`` and ``to``."""
    if not (np.isfinite(back_to) and (back_to - p0) * (to - p0) <= 0):
        raise CaseError(f"{option} = {back_to!r} is invalid: must be a finite value of {key} "
                        f"at the start's value {p0:g} or on its side away from {to:g}")


def check_target(case: Case, key: str, to: float) -> float:
    """The one-line refusals of a continuation's key and target; the key's value in
    ``case``."""
    if case.speed.profile != "constant":
        raise FivdiscError(f"continuation needs a constant disc speed (speed.profile = "
                           f"'constant'), not {case.speed.profile!r}: with a varying speed "
                           "the system is not autonomous and has no periodic orbits")
    p0 = check_key(case, key)
    if not np.isfinite(to):
        raise CaseError(f"to = {to!r} is invalid: must be a finite value of {key}")
    case.replace({key: float(to)})  # the target must be an allowed value
    if to == p0:
        raise CaseError(f"to = {to!r} is invalid: it is the case's own value of {key}; "
                        "give the value to continue to")
    return p0


def check_search(case: Case, options: dict, rtol: float,
                 names: tuple[str, ...] = ("period", "transient", "window", "rtol")) -> None:
    """The one-line refusals of the first orbit's search (as ``fivdisc orbit`` refuses
    them, :func:`~fivdisc.analysis.checks.check_orbit_request`): a period guess shorter
    than any motion of the model or too long to integrate, a transient too long to
    integrate, a disc without modes, no preload. ``options`` are the search's keyword
    arguments (``period``, ``transient``, ``window``, ...); ``names`` name the first four
    in messages."""
    from fivdisc.analysis.checks import check_orbit_request

    check_orbit_request(case, period=options.get("period"), transient=options.get("transient"),
                        window=options.get("window", 1.0), rtol=rtol, names=names)
