"""Exceptions that carry a message a user can act on, and the hint naming the nearest
valid name that every message about an unknown key or name ends with."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


class FivdiscError(Exception):
    """Base class of errors whose message is meant for the user (one line, no traceback)."""


class CaseError(FivdiscError, ValueError):
    """A case file or case value is invalid; the message names the key, value and allowed range."""


class ModeError(FivdiscError, ValueError):
    """An impossible disc-mode request (negative index, root not found)."""


class SimulationError(FivdiscError, RuntimeError):
    """A simulation could not start (bad initial state, no equilibrium, ...)."""


class AnalysisError(FivdiscError, ValueError):
    """Invalid input to an analysis or plotting function.

    The message names the parameter, its value and what is allowed.
    """


class SweepError(FivdiscError, ValueError):
    """A sweep file or sweep value is invalid; the message names the key, value and allowed."""


class MissingExtraError(FivdiscError, ImportError):
    """An optional extra that a command or function needs is not installed."""


class FivdiscWarning(UserWarning):
    """Something the user should know before or after a long computation (its estimated
    time, for one); the command line prints it as one line, ``warning: ...``."""


def nearest(name: str, names: Iterable[str]) -> str:
    """The valid name closest to `name`, as the end of a message: ``"; did you mean
    'slider.mass'?"`` ("" if there are no names).

    Dotted names are compared whole and by their last part, so that ``dcay`` finds
    ``friction.decay``, and regardless of case; the closest is named however far it is.

    Parameters
    ----------
    name
        The unknown name.
    names
        The valid ones.
    """
    candidates = list(dict.fromkeys(names))
    if not candidates:
        return ""

    typed = name.lower()  # ``SPEED.VALUE`` is speed.value in capitals, not a misspelling

    def likeness(candidate: str) -> float:
        candidate = candidate.lower()
        whole = difflib.SequenceMatcher(None, typed, candidate).ratio()
        last = difflib.SequenceMatcher(None, typed.rsplit(".", 1)[-1],
                                       candidate.rsplit(".", 1)[-1]).ratio()
        return max(whole, last)

    return f"; did you mean '{max(candidates, key=likeness)}'?"


class ConvergenceError(FivdiscError, RuntimeError):
    """An iterative solve (a periodic orbit's Newton shooting, a continuation step) did
    not converge. ``result`` holds the last iterate (for an orbit, a
    :class:`~fivdisc.analysis.orbits.PeriodicOrbit` whose ``converged`` is False), and
    ``reason`` says which budget ran out or what failed."""

    def __init__(self, message: str, result: object = None, reason: str = "") -> None:
        super().__init__(message)
        self.result = result
        self.reason = reason
