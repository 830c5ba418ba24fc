"""Case files: everything one simulation needs, as validated, immutable data.

A case is a tree of frozen pydantic models that mirrors the TOML file section by
section (``[disc]``, ``[slider]`` or ``[[sliders]]``, ``[friction]``, ``[speed]``,
``[simulation]`` and ``[simulation.perturbation]``). Every key has a default (the
paper's Table 1: one slider, a disc spinning at a constant 2 pi rad/s), so an empty
file is a valid case.

Every invalid input raises :class:`fivdisc.errors.CaseError` with a one-line
message that names the dotted key, the value given and the allowed range.
This package holds data and validation only; turning a case into kernel arrays
is done elsewhere.

Its modules, from the bottom: ``tree`` (the dotted keys of a tree of tables) and
``messages`` (the one-line errors), which import no table; ``fields`` (the tables' base,
field types and tagged union); one module per table (``disc``, ``slider``, ``friction``,
``speed``, ``simulation``); ``root`` (:class:`Case` and :func:`load_case`); ``keys`` (what
a dotted key means); ``toml`` (reading and writing the text).
"""

from __future__ import annotations

from fivdisc.case.disc import Disc
from fivdisc.case.friction import (
    ExponentialFriction,
    StribeckFriction,
    TableFriction,
)
from fivdisc.case.keys import KeyInfo, describe_key, is_case_key, keys_like, unit_of
from fivdisc.case.root import Case, load_case
from fivdisc.case.simulation import Perturbation, Simulation
from fivdisc.case.slider import Slider, SliderPerturbation
from fivdisc.case.speed import (
    AcceleratingSpeed,
    ConstantSpeed,
    DeceleratingSpeed,
    TableSpeed,
)
from fivdisc.case.speed import Speed as _Speed

# The two aliases are defined here, with their docstrings, so that the API page shows them.
Friction = ExponentialFriction
"""The default friction law, the paper's (:class:`ExponentialFriction`)."""

Speed = _Speed
"""Any of the four disc-speed profiles, told apart by their `profile` key."""

__all__ = [
    "AcceleratingSpeed",
    "Case",
    "ConstantSpeed",
    "DeceleratingSpeed",
    "Disc",
    "ExponentialFriction",
    "Friction",
    "KeyInfo",
    "Perturbation",
    "Simulation",
    "Slider",
    "SliderPerturbation",
    "Speed",
    "StribeckFriction",
    "TableFriction",
    "TableSpeed",
    "describe_key",
    "is_case_key",
    "keys_like",
    "load_case",
    "unit_of",
]
