"""Exceptions that carry a message a user can act on."""


class FivdiscError(Exception):
    """Base class of errors whose message is meant for the user (one line, no traceback)."""


class CaseError(FivdiscError, ValueError):
    """A case file or case value is invalid; the message names the key, value and allowed range."""


class ModeError(FivdiscError, ValueError):
    """An impossible disc-mode request (negative index, root not found)."""


class SimulationError(FivdiscError, RuntimeError):
    """A simulation could not start (bad initial state, no equilibrium, ...)."""
