"""Exceptions that carry a message a user can act on, and the hint naming the nearest
valid name that every message about an unknown key or name ends with."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


class FivdiscError(Exception):
    """Base class of errors whose message is meant for the user (one line, no traceback).

    Every error fivdisc raises about a user's input or a computation that cannot go on
    is one: catch it to report the message, which names what to change.

    Examples
    --------
    >>> import fivdisc
    >>> try:
    ...     fivdisc.Case(slider={"mas": 0.2})
    ... except fivdisc.FivdiscError as error:
    ...     print(f"{type(error).__name__}: {error}")
    CaseError: unknown key 'slider.mas'; did you mean 'slider.mass'?
    """


class CaseError(FivdiscError, ValueError):
    """A case file or case value is invalid; the message names the key, value and allowed range.

    Examples
    --------
    >>> import fivdisc
    >>> fivdisc.Case(slider={"mass": -1.0})
    Traceback (most recent call last):
        ...
    fivdisc.errors.CaseError: slider.mass = -1.0 is invalid: must be > 0 [kg]
    """


class ModeError(FivdiscError, ValueError):
    """An impossible disc-mode request (negative index, root not found).

    Examples
    --------
    >>> import fivdisc
    >>> plate = fivdisc.AnnularPlate(0.044, 0.12, 0.002, 7200.0, 150e9, 0.211)
    >>> plate.mode(-1, 0)
    Traceback (most recent call last):
        ...
    fivdisc.errors.ModeError: k = -1 is out of range; allowed: integer >= 0
    """


class SimulationError(FivdiscError, RuntimeError):
    """A simulation could not start (bad initial state, no equilibrium, ...).

    Examples
    --------
    >>> import fivdisc
    >>> fivdisc.sliding_equilibrium(fivdisc.Case(speed={"profile": "decelerating"}))
    Traceback (most recent call last):
        ...
    fivdisc.errors.SimulationError: a sliding equilibrium exists only at constant disc speed; ...
    """


class AnalysisError(FivdiscError, ValueError):
    """Invalid input to an analysis or plotting function.

    The message names the parameter, its value and what is allowed.

    Examples
    --------
    >>> import fivdisc
    >>> result = fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.01}))
    >>> fivdisc.spectrum(result, "phii")
    Traceback (most recent call last):
        ...
    fivdisc.errors.AnalysisError: var = 'phii' is not a time series of the data: must be one of ...
    """


class SweepError(FivdiscError, ValueError):
    """A sweep file or sweep value is invalid; the message names the key, value and allowed.

    Examples
    --------
    >>> from fivdisc.sweep import Sweep
    >>> Sweep.from_toml('''
    ... mode = "grid"
    ... [axes]
    ... "speed.value" = "1:2:3"
    ... [reduce]
    ... keep = ["separatd"]
    ... ''')
    Traceback (most recent call last):
        ...
    fivdisc.errors.SweepError: reduce.keep: unknown reduction 'separatd'; did you mean ...
    """


class MissingExtraError(FivdiscError, ImportError):
    """An optional extra that a command or function needs is not installed.

    Functions that need one check for it before any work (:func:`fivdisc.extras.require`)
    and raise this with the command that installs it.

    Examples
    --------
    >>> import fivdisc
    >>> from fivdisc.extras import EXTRAS, require
    >>> EXTRAS["plot"]
    ('matplotlib',)
    >>> require("plot", "my figure")  # silent: matplotlib is installed
    >>> issubclass(fivdisc.MissingExtraError, ImportError)
    True
    """


class FivdiscWarning(UserWarning):
    """Something the user should know before or after a long computation (its estimated
    time, for one); the command line prints it as one line, ``warning: ...``.

    Examples
    --------
    A script that would rather stop than start a run of minutes turns the warning into
    an error (a short run warns of nothing):

    >>> import warnings
    >>> import fivdisc
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("error", fivdisc.FivdiscWarning)
    ...     result = fivdisc.simulate(fivdisc.Case(simulation={"duration": 0.01}))
    >>> result.ok
    True
    """


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
    ``reason`` says which budget ran out or what failed.

    Examples
    --------
    One Newton iteration is too few for the orbit of this stick-slip oscillator:

    >>> import fivdisc
    >>> case = fivdisc.Case(
    ...     disc={"modes": [[0, 0]]},
    ...     slider={"rotational_damping": 0.0, "normal_damping": 5.0},
    ...     friction={"kinetic_max": 0.5, "kinetic_min": 0.5},
    ...     speed={"value": 1.0},
    ... )
    >>> try:
    ...     fivdisc.periodic_orbit(case, transient=0.1, max_iterations=1)
    ... except fivdisc.ConvergenceError as error:
    ...     print(f"{error.result.verdict}: {error.reason}")
    not converged: the iteration budget (1 Newton iterations) ran out
    """

    def __init__(self, message: str, result: object = None, reason: str = "") -> None:
        super().__init__(message)
        self.result = result
        self.reason = reason
