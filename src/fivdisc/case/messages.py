"""What a case says when it is wrong: one line naming the dotted key, the value and the rule.

The tables raise :func:`rule` from their checks, and turn pydantic's ValidationError into
:class:`fivdisc.errors.CaseError` with :func:`describe`. This module imports no table: it
reads the tree of tables through their class attributes (:mod:`fivdisc.case.tree`), so the
tables can import it.
"""

from __future__ import annotations

import json
from collections.abc import Collection, Mapping
from typing import Any

import annotated_types
import numpy as np
from pydantic import BaseModel, ValidationError
from pydantic.fields import FieldInfo
from pydantic_core import ErrorDetails, PydanticCustomError

from fivdisc.case.tree import names_of
from fivdisc.errors import nearest

_MAX_REPORTED_ERRORS = 3
_MAX_SHOWN_CHARS = 80


def plain(value: Any) -> Any:
    """Turn numpy scalars and arrays into Python values.

    Sweeps build values with numpy, and the strict field types of the tables would
    otherwise reject ``np.int64`` or ``np.bool_``.
    """
    if isinstance(value, np.generic | np.ndarray):
        return value.tolist()
    return value


def rule(text: str, key: str | None = None, value: Any = None) -> PydanticCustomError:
    """A validation error whose text is `text` ("must be ...").

    Parameters
    ----------
    text
        What the value must satisfy, with units.
    key
        Dotted key, relative to the model being validated, of the offending value
        when the error is raised by a model-level check (pydantic then knows
        only the model's location); None for field-level checks.
    value
        The offending value; used only together with `key`.
    """
    ctx: dict[str, Any] = {"rule": text}
    if key is not None:
        ctx |= {"key": key, "value": value}
    return PydanticCustomError("case_rule", "{rule}", ctx)


def show(value: Any) -> str:
    """A value as it would be written in TOML, shortened to one readable line."""
    if isinstance(value, BaseModel):
        value = value.model_dump()
    if isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, str):
        text = json.dumps(value)
    elif isinstance(value, list | tuple):
        text = "[" + ", ".join(show(v) for v in value) + "]"
    elif isinstance(value, Mapping):
        text = "{" + ", ".join(f"{k} = {show(v)}" for k, v in value.items()) + "}"
    else:
        text = repr(plain(value))
    if len(text) > _MAX_SHOWN_CHARS:
        text = text[: _MAX_SHOWN_CHARS - 3] + "..."
    return text


def join(parts: list[str | int]) -> str:
    """Dotted key with list indices, e.g. ``disc.modes[2][0]``."""
    text = ""
    for part in parts:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            text += f".{part}" if text else part
    return text


def unknown_key(key: str, names: list[str] | None, member: type[BaseModel] | None = None,
                everything: Collection[str] = ()) -> str:
    """Message for an unknown dotted key, ending with the nearest valid key.

    Parameters
    ----------
    key
        The dotted key.
    names
        The valid names in the key's table; None if the table is unknown.
    member
        The table that holds the key when it is a member of a tagged union (a speed
        profile, a friction law): a key of another member is explained as such.
    everything
        The valid dotted keys to suggest from when `names` is None.
    """
    table, _, name = key.rpartition(".")
    union = getattr(member, "_union", None)
    if union is not None and table == union.table and name in union.keys():
        tag = member.model_fields[union.tag].default
        own = ", ".join(f"'{n}'" for n in member.model_fields)
        owners = " or ".join(f"'{o}'" for o in union.owner(name))
        return (f"unknown key '{key}' for {union.what} '{tag}', which takes {own} "
                f"('{name}' belongs to {union.what} {owners})")
    if names is not None:
        candidates = [f"{table}.{n}" if table else n for n in names]
    else:
        candidates = list(everything)
    return f"unknown key '{key}'{nearest(key, candidates)}"


def _locate(
    root: type[BaseModel], loc: tuple[str | int, ...], single: bool
) -> tuple[list[str | int], type[BaseModel] | None, FieldInfo | None, bool]:
    """Follow a pydantic error location through the case tables.

    Parameters
    ----------
    root
        The table that was validated.
    loc
        pydantic's location of the error.
    single
        Whether the case has one slider, named ``slider`` rather than ``sliders.J``.

    Returns
    -------
    parts
        Key path from the top of a case file, without the profile or law tag
        pydantic inserts for a discriminated union.
    owner
        The table that holds (or should hold) the last named key.
    field
        That key's field, or None if it is not a field of `owner`.
    item
        Whether the location ends inside an array value (an index).
    """
    parts: list[str | int] = list(getattr(root, "_key", ()))
    model: type[BaseModel] | None = root
    owner: type[BaseModel] | None = root
    field: FieldInfo | None = None
    union: Any = None
    array: tuple[str, type[BaseModel]] | None = None
    for part in loc:
        if array is not None and isinstance(part, int):
            # Slider J is keyed `sliders.J` (or `slider` when it is the only one).
            singular, item = array
            parts[-1:] = [singular] if single else [parts[-1], str(part)]
            model = owner = item
            array = None
            continue
        array = None
        if isinstance(part, int):
            parts.append(part)
            continue
        if union is not None and part in union.models:
            model = owner = union.models[part]
            union = None
            continue
        union = None
        parts.append(part)
        owner = model
        field = model.model_fields.get(part) if model is not None else None
        model = None
        if field is None:
            continue
        if part in getattr(owner, "_unions", {}):
            union = owner._unions[part]
        elif part in getattr(owner, "_arrays", {}):
            array = owner._arrays[part]
        elif isinstance(field.annotation, type) and issubclass(field.annotation, BaseModel):
            model = field.annotation
    return parts, owner, field, bool(loc) and isinstance(loc[-1], int)


def _interval(bounds: Mapping[str, Any]) -> str:
    """Text of an allowed range from gt/ge/lt/le bounds, e.g. "must lie in (0, 0.1]"."""
    symbol = {"gt": ">", "ge": ">=", "lt": "<", "le": "<="}
    low = [k for k in ("gt", "ge") if k in bounds]
    high = [k for k in ("lt", "le") if k in bounds]
    if low and high:
        left = "(" if low[0] == "gt" else "["
        right = ")" if high[0] == "lt" else "]"
        return f"must lie in {left}{bounds[low[0]]!r}, {bounds[high[0]]!r}{right}"
    return " and ".join(f"must be {symbol[k]} {bounds[k]!r}" for k in low + high)


def _field_bounds(field: FieldInfo) -> dict[str, Any]:
    """The gt/ge/lt/le constraints declared on a field."""
    bounds: dict[str, Any] = {}
    for meta in field.metadata:
        if isinstance(meta, annotated_types.Gt | annotated_types.Ge):
            bounds |= {"gt": meta.gt} if isinstance(meta, annotated_types.Gt) else {"ge": meta.ge}
        elif isinstance(meta, annotated_types.Lt | annotated_types.Le):
            bounds |= {"lt": meta.lt} if isinstance(meta, annotated_types.Lt) else {"le": meta.le}
    return bounds


_TYPE_RULES = {
    "float_type": "must be a number",
    "int_type": "must be an integer",
    "bool_type": "must be true or false",
    "string_type": "must be a string",
    "tuple_type": "must be an array",
    "model_type": "must be a table",
    "model_attributes_type": "must be a table",
    "finite_number": "must be finite",
}


def _describe_error(error: ErrorDetails, root: type[BaseModel], single: bool) -> str:
    """One pydantic error as "key = value is invalid: rule [unit]"."""
    parts, owner, field, item = _locate(root, error["loc"], single)
    kind = error["type"]
    ctx = error.get("ctx", {})
    value = error["input"]

    if kind == "extra_forbidden":
        names = names_of(owner) if owner is not None else None
        return unknown_key(join(parts), names, owner)
    if kind == "union_tag":
        unions = getattr(owner, "_unions", {})
        union = unions.get(str(parts[-1])) if parts else None
        if isinstance(value, Mapping) and union is not None:
            parts, value = [*parts, union.tag], value.get(union.tag)
            allowed = "must be one of " + ", ".join(f'"{p}"' for p in union.models)
        else:
            allowed = "must be a table"
    elif kind == "case_rule":
        allowed = ctx["rule"]
        if "key" in ctx:
            parts, value = [*parts, *ctx["key"].split(".")], ctx["value"]
    elif kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        bounds = _field_bounds(field) if field is not None and not item else {}
        allowed = _interval(bounds or ctx)
        unit = (field.json_schema_extra or {}).get("unit") if field is not None else None
        if unit:
            allowed += f" [{unit}]"
    elif kind in ("too_short", "too_long"):
        bound = ctx["min_length"] if kind == "too_short" else ctx["max_length"]
        entries = "entry" if bound == 1 else "entries"
        allowed = f"must have at {'least' if kind == 'too_short' else 'most'} {bound} {entries}"
    elif kind in _TYPE_RULES:
        allowed = _TYPE_RULES[kind]
    else:
        allowed = error["msg"].replace("Input should", "must")
    return f"{join(parts) or 'case'} = {show(value)} is invalid: {allowed}"


def describe(exc: ValidationError, root: type[BaseModel], data: Any = None) -> str:
    """The first few errors of a ValidationError, on one line.

    `data` is the input that was validated (to name the sliders as the file does).
    """
    errors = exc.errors(include_url=False)
    # pydantic counts only the valid items against an array's minimum length, so a
    # bad item also triggers a spurious "too short" on its array: report the item.
    item_locs = [e["loc"] for e in errors]
    errors = [
        e
        for e in errors
        if e["type"] != "too_short"
        or not any(
            len(loc) > len(e["loc"]) and loc[: len(e["loc"])] == e["loc"] for loc in item_locs
        )
    ]
    given = data if isinstance(data, Mapping) else {}
    arrays = [given.get(name) for name in getattr(root, "_arrays", {})]
    single = all(not isinstance(items, list | tuple) or len(items) == 1 for items in arrays)
    messages = [_describe_error(e, root, single) for e in errors[:_MAX_REPORTED_ERRORS]]
    if len(errors) > _MAX_REPORTED_ERRORS:
        messages.append(f"and {len(errors) - _MAX_REPORTED_ERRORS} more errors")
    return "; ".join(messages)
