"""What the case tables are made of: their base class, the field types with their checks,
and the tagged union (a table that is one of several, told apart by a key)."""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from typing import Annotated, Any, ClassVar, Union

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Discriminator,
    Field,
    Strict,
    Tag,
    ValidationError,
)

from fivdisc.case.messages import describe, plain, rule
from fivdisc.errors import CaseError


class Table(BaseModel):
    """Base of every case table: frozen, no unknown keys, errors as CaseError.

    The class attributes describe the table's place in a case file, for the keys
    (:mod:`fivdisc.case.tree`) and the error messages (:mod:`fivdisc.case.messages`).
    """

    model_config = ConfigDict(frozen=True, extra="forbid", defer_build=True)

    # Dotted location of this table in a case file, to name keys in error messages.
    _key: ClassVar[tuple[str, ...]] = ()
    # Keys holding one of several tables told apart by a tag key: name -> TaggedUnion.
    _unions: ClassVar[Mapping[str, TaggedUnion]] = {}
    # Keys holding an array of tables: name -> (the name of its only table, that table),
    # e.g. "sliders" -> ("slider", Slider).
    _arrays: ClassVar[Mapping[str, tuple[str, type[Table]]]] = {}
    # The tagged union this table is a member of, if any (set by TaggedUnion).
    _union: ClassVar[TaggedUnion | None] = None

    def __init__(self, /, **data: Any) -> None:
        try:
            super().__init__(**data)
        except ValidationError as exc:
            raise CaseError(describe(exc, type(self), data)) from None

    # Marks this __init__ as pydantic's own, as pydantic's RootModel does: otherwise
    # pydantic calls it while validating a parent table, and the CaseError raised
    # here would be wrapped (and its location lost) in the parent's error.
    __init__.__pydantic_base_init__ = True  # type: ignore[attr-defined]

    @classmethod
    def model_validate(cls, obj: Any, *args: Any, **kwargs: Any) -> Any:
        """pydantic's ``model_validate``, raising CaseError (one line) on invalid input."""
        try:
            return super().model_validate(obj, *args, **kwargs)
        except ValidationError as exc:
            raise CaseError(describe(exc, cls, obj)) from None


class TaggedUnion:
    """A table that is one of several models, told apart by a tag key."""

    def __init__(self, table: str, tag: str, models: dict[str, type[Table]], what: str) -> None:
        self.table = table
        self.tag = tag
        self.models = models
        self.default = next(iter(models))
        self.what = what
        for model in models.values():
            model._union = self

    def tag_of(self, data: Any) -> Any:
        """The tag that selects the model; a table without the tag key takes the default."""
        if isinstance(data, Mapping):
            return data.get(self.tag, self.default)
        return getattr(data, self.tag, None)

    def annotation(self) -> Any:
        members = tuple(Annotated[model, Tag(name)] for name, model in self.models.items())
        return Annotated[
            Union[members],  # noqa: UP007 - a runtime union of a tuple of members
            Discriminator(self.tag_of, custom_error_type="union_tag",
                          custom_error_message=f"unknown {self.what}"),
        ]

    def keys(self) -> list[str]:
        """Every key of every member, in order of first appearance."""
        return list(dict.fromkeys(n for m in self.models.values() for n in m.model_fields))

    def owner(self, name: str) -> list[str]:
        """Tags of the members that have key `name`."""
        return [tag for tag, model in self.models.items() if name in model.model_fields]


def _pair(names: str) -> BeforeValidator:
    """Check that a value is a two-element array before its items are validated."""

    def check(value: Any) -> Any:
        value = plain(value)
        if not isinstance(value, list | tuple) or len(value) != 2:
            raise rule(f"must be a pair [{names}]")
        return value

    return BeforeValidator(check)


# Strict types: TOML's "0.1" (a string) or true (a bool) must not pass as a number.
Real = Annotated[float, Strict(), Field(allow_inf_nan=False), BeforeValidator(plain)]
Count = Annotated[int, Strict(), BeforeValidator(plain)]
Flag = Annotated[bool, Strict(), BeforeValidator(plain)]
ModeIndex = Annotated[int, Strict(), Field(ge=0), BeforeValidator(plain)]
Mode = Annotated[tuple[ModeIndex, ModeIndex], _pair("k, l")]
Probe = Annotated[tuple[Real, Real], _pair("r, theta")]
NonNegative = Annotated[Real, Field(ge=0)]
SpeedValues = Annotated[tuple[NonNegative, ...], BeforeValidator(plain)]


def field(default: Any, unit: str = "", symbol: str = "", name: str = "",
          **constraints: Any) -> Any:
    """A pydantic field that records its unit (for error messages), and its symbol in the
    paper (matplotlib mathtext, for axis labels) and a name where the key's words are not
    one (for ``long_name`` attributes); see :func:`fivdisc.case.describe_key`."""
    extra = {"unit": unit, "symbol": symbol, "name": name}
    return Field(default, json_schema_extra=extra, **constraints)


def increasing_from_zero(unit: str) -> AfterValidator:
    """Reject a grid that does not start at 0 or does not strictly increase."""

    def check(points: tuple[float, ...]) -> tuple[float, ...]:
        # An empty grid is left to the field's min_length check.
        if points and points[0] != 0.0:
            raise rule(f"must start at 0 [{unit}]")
        for earlier, later in itertools.pairwise(points):
            if later <= earlier:
                raise rule(f"must strictly increase [{unit}]; {later!r} follows {earlier!r}")
        return points

    return AfterValidator(check)

