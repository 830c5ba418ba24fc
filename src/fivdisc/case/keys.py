"""The dotted keys of a case (``slider.mass``, ``sliders.1.preload``, ``speed.value``): which
exist, which to suggest for a wrong one, and their units, symbols and words."""

from __future__ import annotations

from typing import NamedTuple

from fivdisc.case.disc import Disc
from fivdisc.case.friction import LAWS
from fivdisc.case.root import Case
from fivdisc.case.simulation import Perturbation, Simulation
from fivdisc.case.slider import Slider, SliderPerturbation
from fivdisc.case.speed import PROFILES
from fivdisc.case.tree import catalog, template


def is_case_key(key: str) -> bool:
    """Whether ``key`` names a value of some case: a key of :meth:`Case.valid_keys`,
    ``sliders.J.KEY`` for a slider key (whether slider J exists depends on the case) or
    ``sliders.*.KEY`` (every slider)."""
    return template(key) in catalog(Case).leaves


def keys_like(key: str) -> list[str]:
    """The valid keys to suggest for `key`: :meth:`Case.valid_keys`, with the slider keys
    written ``sliders.J.KEY`` when `key` names slider J that way."""
    parts = key.split(".")
    keys = Case.valid_keys()
    if parts[0] == "sliders" and len(parts) > 2 and (parts[1].isdigit() or parts[1] == "*"):
        prefix = f"sliders.{parts[1]}."
        return [prefix + k.split(".", 1)[1] if k.startswith("slider.") else k for k in keys]
    return keys


class KeyInfo(NamedTuple):
    """What :func:`describe_key` knows about a case key: its ``unit`` ("" if
    dimensionless or not a number), its ``symbol`` in the paper as matplotlib mathtext
    without the dollars (``c_z``, ``r_0^2 c_\\phi``; "" if it has none) and a
    ``long_name`` in words (``"slider 1 normal damping"``)."""

    unit: str
    symbol: str
    long_name: str


_TABLE_WORDS = {"disc": "disc", "friction": "friction", "speed": "", "simulation": "",
                "simulation.perturbation": ""}


def describe_key(key: str) -> KeyInfo:
    """Unit, symbol and description of a dotted case key.

    ``sliders.J.KEY`` is described as ``slider.KEY`` of slider J, ``sliders.*.KEY`` as
    that of every slider; the keys of every speed
    profile and friction law are known (a key of two profiles, ``speed.initial``, takes
    the first one's symbol). An unknown key gives its own words and no unit.

    Parameters
    ----------
    key
        E.g. ``"slider.normal_damping"`` -> ``("N s/m", "c_z", "slider normal damping")``.
    """
    table, _, name = template(key).rpartition(".")
    models = {
        "disc": (Disc,),
        "slider": (Slider,),
        "friction": tuple(LAWS.values()),
        "speed": tuple(PROFILES.values()),
        "simulation": (Simulation,),
        "simulation.perturbation": (Perturbation,),
        "slider.perturbation": (SliderPerturbation,),
    }.get(table, ())
    extra: dict[str, str] = {}
    for model in models:
        field = model.model_fields.get(name)
        if field is not None:
            extra = dict(field.json_schema_extra or {})
            break
    words = extra.get("name") or name.replace("_", " ")
    if table.split(".")[0] == "slider":
        parts = key.split(".")
        owner = ("every slider" if parts[0] == "sliders" and parts[1] == "*"
                 else f"slider {parts[1]}" if parts[0] == "sliders" else "slider")
    else:
        owner = _TABLE_WORDS.get(table, table)
    head = owner.split(" ")[0]
    if owner == "every slider":
        words = (words.replace("slider", "every slider", 1) if "slider" in words.split(" ")
                 else f"{words} of every slider")
    elif head and head in words.split(" "):
        words = words.replace(head, owner, 1)
    elif owner:
        words = f"{owner} {words}"
    return KeyInfo(extra.get("unit", ""), extra.get("symbol", ""), words)


def unit_of(key: str) -> str:
    """Unit of a dotted case key (``"slider.normal_damping"`` -> ``"N s/m"``), "" if none.

    ``sliders.J.KEY`` is the unit of ``slider.KEY``; the keys of every speed profile
    and friction law are known.
    """
    return describe_key(key).unit
