"""The dotted keys of a tree of case tables (``slider.mass``, ``speed.value``, ...).

The tree is read from the tables themselves, through three class attributes every table
has (see :class:`fivdisc.case.fields.Table`): ``_unions``, its keys that hold one of several
tables told apart by a tag key; ``_arrays``, its keys that hold an array of tables, with
the name a file gives the one table of a one-item array (``sliders`` -> ``slider``); and
the pydantic fields of the rest. This module imports no table, so the error messages
(:mod:`fivdisc.case.messages`), which the tables use, can name keys without importing them.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator
from typing import NamedTuple

from pydantic import BaseModel

#: The slider "index" of a key that names every slider: ``sliders.*.mass``.
EVERY = "*"


def template(key: str) -> str:
    """The key with a slider index removed: ``sliders.2.mass`` -> ``slider.mass``, and
    ``sliders.*.mass`` (every slider) -> ``slider.mass``."""
    parts = key.split(".")
    if parts[0] == "sliders" and len(parts) > 1 and (parts[1].isdigit() or parts[1] == EVERY):
        return ".".join(["slider", *parts[2:]])
    return key


def names_of(model: type[BaseModel]) -> list[str]:
    """The keys of a table as a file may write them: a one-item array's singular name
    first (``slider``), then the fields."""
    arrays = getattr(model, "_arrays", {})
    return [*(singular for singular, _ in arrays.values()), *model.model_fields]


def walk(model: type[BaseModel], prefix: str = "") -> Iterator[tuple[str, list[str] | None]]:
    """Yield (dotted key, names inside it) for every table and leaf; names is None for a leaf.

    A one-item array of tables is walked under its singular name (``slider.mass``); a
    tagged union yields the keys of all its members.
    """
    unions = getattr(model, "_unions", {})
    arrays = getattr(model, "_arrays", {})
    for name, info in model.model_fields.items():
        key = f"{prefix}{name}"
        if name in unions:
            union = unions[name]
            yield key, union.keys()
            for sub in union.models.values():
                yield from walk(sub, key + ".")
        elif name in arrays:
            singular, item = arrays[name]
            yield f"{prefix}{singular}", list(item.model_fields)
            yield from walk(item, f"{prefix}{singular}.")
        elif isinstance(info.annotation, type) and issubclass(info.annotation, BaseModel):
            yield key, list(info.annotation.model_fields)
            yield from walk(info.annotation, key + ".")
        else:
            yield key, None


class Catalog(NamedTuple):
    """The keys of a tree of tables."""

    #: Dotted keys of values (not tables), in the order of the tables' fields.
    leaves: tuple[str, ...]
    #: Dotted table key -> the names of its keys ("" is the top level).
    names: dict[str, list[str]]
    #: Dotted keys of tables, and of arrays of tables (``sliders``).
    tables: frozenset[str]


@functools.cache
def catalog(root: type[BaseModel]) -> Catalog:
    """The keys of the tree of tables under `root` (a case: :class:`fivdisc.Case`)."""
    entries = list(walk(root))
    names = {"": names_of(root)} | {key: inner for key, inner in entries if inner is not None}
    leaves = tuple(dict.fromkeys(key for key, inner in entries if inner is None))
    tables = frozenset([*names, *getattr(root, "_arrays", {})]) - {""}
    return Catalog(leaves, names, tables)
