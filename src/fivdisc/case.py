"""Case files: everything one simulation needs, as validated, immutable data.

A case is a tree of frozen pydantic models that mirrors the TOML file section by
section (``[disc]``, ``[slider]``, ``[friction]``, ``[speed]``, ``[simulation]``
and ``[simulation.perturbation]``). Every key has a default (the paper's Table 1,
a disc spinning at a constant 2 pi rad/s), so an empty file is a valid case.

Every invalid input raises :class:`fivdisc.errors.CaseError` with a one-line
message that names the dotted key, the value given and the allowed range.
This module holds data and validation only; turning a case into kernel arrays
is done elsewhere.
"""

from __future__ import annotations

import difflib
import itertools
import json
import math
import tomllib
from collections.abc import Iterator, Mapping
from os import PathLike
from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal

import annotated_types
import numpy as np
import tomli_w
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
    model_validator,
)
from pydantic.fields import FieldInfo
from pydantic_core import ErrorDetails, PydanticCustomError

from fivdisc.errors import CaseError
from fivdisc.files import read_text
from fivdisc.limits import disc_problem

__all__ = [
    "AcceleratingSpeed",
    "Case",
    "ConstantSpeed",
    "DeceleratingSpeed",
    "Disc",
    "Friction",
    "Perturbation",
    "Simulation",
    "Slider",
    "Speed",
    "TableSpeed",
    "load_case",
    "unit_of",
]

_TWO_PI = 2.0 * math.pi
_MAX_REPORTED_ERRORS = 3
_MAX_SHOWN_CHARS = 80


# --- field types -----------------------------------------------------------------------------


def _plain(value: Any) -> Any:
    """Turn numpy scalars and arrays into Python values.

    Sweeps build values with numpy, and the strict field types below would
    otherwise reject ``np.int64`` or ``np.bool_``.
    """
    if isinstance(value, np.generic | np.ndarray):
        return value.tolist()
    return value


def _rule(rule: str, key: str | None = None, value: Any = None) -> PydanticCustomError:
    """A validation error whose text is `rule` ("must be ...").

    Parameters
    ----------
    rule
        What the value must satisfy, with units.
    key
        Dotted key, relative to the model being validated, of the offending value
        when the error is raised by a model-level check (pydantic then knows
        only the model's location); None for field-level checks.
    value
        The offending value; used only together with `key`.
    """
    ctx: dict[str, Any] = {"rule": rule}
    if key is not None:
        ctx |= {"key": key, "value": value}
    return PydanticCustomError("case_rule", "{rule}", ctx)


def _pair(names: str) -> BeforeValidator:
    """Check that a value is a two-element array before its items are validated."""

    def check(value: Any) -> Any:
        value = _plain(value)
        if not isinstance(value, list | tuple) or len(value) != 2:
            raise _rule(f"must be a pair [{names}]")
        return value

    return BeforeValidator(check)


# Strict types: TOML's "0.1" (a string) or true (a bool) must not pass as a number.
Real = Annotated[float, Strict(), Field(allow_inf_nan=False), BeforeValidator(_plain)]
Count = Annotated[int, Strict(), BeforeValidator(_plain)]
Flag = Annotated[bool, Strict(), BeforeValidator(_plain)]
ModeIndex = Annotated[int, Strict(), Field(ge=0), BeforeValidator(_plain)]
Mode = Annotated[tuple[ModeIndex, ModeIndex], _pair("k, l")]
Probe = Annotated[tuple[Real, Real], _pair("r, theta")]
SpeedValues = Annotated[tuple[Annotated[Real, Field(ge=0)], ...], BeforeValidator(_plain)]


def _field(default: Any, unit: str = "", **constraints: Any) -> Any:
    """A pydantic field that records its unit, for error messages."""
    return Field(default, json_schema_extra={"unit": unit}, **constraints)


def _distinct_modes(modes: tuple[tuple[int, int], ...]) -> tuple[tuple[int, int], ...]:
    """Reject a mode listed twice (its modal coordinates would be duplicated)."""
    seen: set[tuple[int, int]] = set()
    for mode in modes:
        if mode in seen:
            raise _rule(f"must not repeat a mode; {list(mode)} appears twice")
        seen.add(mode)
    return modes


def _increasing_from_zero(times: tuple[float, ...]) -> tuple[float, ...]:
    """Reject a time grid that does not start at 0 or does not strictly increase."""
    # An empty grid is left to the field's min_length check.
    if times and times[0] != 0.0:
        raise _rule("must start at 0 [s]")
    for earlier, later in itertools.pairwise(times):
        if later <= earlier:
            raise _rule(f"must strictly increase [s]; {later!r} follows {earlier!r}")
    return times


# --- the tables ------------------------------------------------------------------------------


class _Table(BaseModel):
    """Base of every case table: frozen, no unknown keys, errors as CaseError."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    # Dotted location of this table in a case file, to name keys in error messages.
    _key: ClassVar[tuple[str, ...]] = ()

    def __init__(self, /, **data: Any) -> None:
        try:
            super().__init__(**data)
        except ValidationError as exc:
            raise CaseError(_describe(exc, type(self))) from None

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
            raise CaseError(_describe(exc, cls)) from None


class Disc(_Table):
    """Annular Kirchhoff plate, clamped at the inner and free at the outer edge.

    Attributes
    ----------
    inner_radius
        a, clamped inner radius [m].
    outer_radius
        b, free outer radius [m]; greater than a.
    thickness
        h [m].
    density
        rho [kg/m^3].
    youngs_modulus
        E [Pa].
    poisson_ratio
        nu, in (-1, 0.5).
    modes
        (k, l) = (nodal circles, nodal diameters) of the modes kept; each l >= 1
        stands for a doublet (cos and sin). Distinct; empty means a rigid disc
        (N = N0), the classic 1-DOF oscillator on a moving belt.
    """

    _key: ClassVar[tuple[str, ...]] = ("disc",)

    inner_radius: Real = _field(0.044, "m", gt=0)
    outer_radius: Real = _field(0.12, "m", gt=0)
    thickness: Real = _field(0.002, "m", gt=0)
    density: Real = _field(7200.0, "kg/m^3", gt=0)
    youngs_modulus: Real = _field(150e9, "Pa", gt=0)
    poisson_ratio: Real = _field(0.211, gt=-1, lt=0.5)
    modes: Annotated[tuple[Mode, ...], AfterValidator(_distinct_modes)] = _field(
        ((0, 0), (0, 1), (0, 2), (0, 3))
    )

    @model_validator(mode="after")
    def _check_annulus(self) -> Disc:
        if self.outer_radius <= self.inner_radius:
            raise _rule(
                f"must be > disc.inner_radius = {self.inner_radius!r} [m]",
                "outer_radius",
                self.outer_radius,
            )
        return self

    @model_validator(mode="after")
    def _check_limits(self) -> Disc:
        # Bounded work: see fivdisc.limits.
        problem = disc_problem(self.inner_radius, self.outer_radius, self.modes)
        if problem is not None:
            key, value, rule = problem
            raise _rule(rule, key, value)
        return self


class Slider(_Table):
    """The slider: a mass on a transverse spring-damper and an in-plane one.

    Attributes
    ----------
    track_radius
        r0, radius of the slider's track [m]; strictly between the disc's radii.
    mass
        m [kg]; its moment of inertia about the disc axis is m r0^2.
    normal_stiffness
        k_z [N/m].
    normal_damping
        c_z [N s/m].
    rotational_stiffness
        r0^2 k_phi [N m/rad].
    rotational_damping
        r0^2 c_phi [N m s/rad].
    preload
        N0, normal preload [N].
    """

    _key: ClassVar[tuple[str, ...]] = ("slider",)

    track_radius: Real = _field(0.1, "m", gt=0)
    mass: Real = _field(0.1, "kg", gt=0)
    normal_stiffness: Real = _field(3e4, "N/m", gt=0)
    normal_damping: Real = _field(0.1, "N s/m", ge=0)
    rotational_stiffness: Real = _field(2e3, "N m/rad", gt=0)
    rotational_damping: Real = _field(0.1, "N m s/rad", ge=0)
    preload: Real = _field(500.0, "N", ge=0)


class Friction(_Table):
    """Friction law ``mu(v) = mu_1 + (mu_0 - mu_1) exp(-alpha |r0 v|)`` and static limit.

    Attributes
    ----------
    static
        mu_s, static coefficient; not below mu_0 nor mu_1.
    kinetic_max
        mu_0, kinetic coefficient at zero relative speed.
    kinetic_min
        mu_1, kinetic coefficient at high relative speed.
    decay
        alpha, decay rate of the kinetic coefficient with sliding speed [s/m].
    """

    _key: ClassVar[tuple[str, ...]] = ("friction",)

    static: Real = _field(0.8, ge=0)
    kinetic_max: Real = _field(0.6, ge=0)
    kinetic_min: Real = _field(0.35, ge=0)
    decay: Real = _field(1.0, "s/m", ge=0)

    @model_validator(mode="after")
    def _check_static_limit(self) -> Friction:
        for name in ("kinetic_max", "kinetic_min"):
            kinetic = getattr(self, name)
            if self.static < kinetic:
                raise _rule(
                    f"must be >= friction.{name} = {kinetic!r} "
                    "(static friction is the upper limit)",
                    "static",
                    self.static,
                )
        return self


class ConstantSpeed(_Table):
    """Disc speed ``Omega(t) = Omega_c``.

    Attributes
    ----------
    profile
        "constant".
    value
        Omega_c [rad/s], >= 0.
    """

    _key: ClassVar[tuple[str, ...]] = ("speed",)

    profile: Literal["constant"] = "constant"
    value: Real = _field(_TWO_PI, "rad/s", ge=0)


class DeceleratingSpeed(_Table):
    """Disc speed ``Omega(t) = Omega_0 (1 - t / t_max)`` for ``0 <= t <= t_max``.

    Defaults are those of the paper's Figs. 10 and 11.

    Attributes
    ----------
    profile
        "decelerating".
    initial
        Omega_0 [rad/s], >= 0.
    duration
        t_max, time to stop [s], > 0.
    """

    _key: ClassVar[tuple[str, ...]] = ("speed",)

    profile: Literal["decelerating"] = "decelerating"
    initial: Real = _field(_TWO_PI, "rad/s", ge=0)
    duration: Real = _field(35.0, "s", gt=0)


class AcceleratingSpeed(_Table):
    """Disc speed ``Omega(t) = Omega_1 + c t``.

    Defaults are those of the paper's Figs. 24 and 25.

    Attributes
    ----------
    profile
        "accelerating".
    initial
        Omega_1 [rad/s], >= 0.
    rate
        c [rad/s^2], >= 0.
    """

    _key: ClassVar[tuple[str, ...]] = ("speed",)

    profile: Literal["accelerating"] = "accelerating"
    initial: Real = _field(_TWO_PI, "rad/s", ge=0)
    rate: Real = _field(0.2, "rad/s^2", ge=0)


class TableSpeed(_Table):
    """Disc speed interpolated linearly between tabulated points.

    Attributes
    ----------
    profile
        "table".
    times
        Knot times [s]: start at 0, strictly increase, at least two.
    values
        Omega at the knots [rad/s], each >= 0; as many as `times`.
    """

    _key: ClassVar[tuple[str, ...]] = ("speed",)

    profile: Literal["table"] = "table"
    times: Annotated[tuple[Real, ...], AfterValidator(_increasing_from_zero)] = _field(
        (0.0, 1.0), "s", min_length=2
    )
    values: SpeedValues = _field((_TWO_PI, _TWO_PI), "rad/s", min_length=2)

    @model_validator(mode="after")
    def _check_lengths(self) -> TableSpeed:
        if len(self.values) != len(self.times):
            raise _rule(
                f"must have as many entries as speed.times ({len(self.times)})",
                "values",
                self.values,
            )
        return self


_SPEEDS: dict[str, type[_Table]] = {
    "constant": ConstantSpeed,
    "decelerating": DeceleratingSpeed,
    "accelerating": AcceleratingSpeed,
    "table": TableSpeed,
}


def _speed_profile(data: Any) -> Any:
    """The tag that selects the speed model; a table without `profile` is constant."""
    if isinstance(data, Mapping):
        return data.get("profile", "constant")
    return getattr(data, "profile", None)


Speed = Annotated[
    Annotated[ConstantSpeed, Tag("constant")]
    | Annotated[DeceleratingSpeed, Tag("decelerating")]
    | Annotated[AcceleratingSpeed, Tag("accelerating")]
    | Annotated[TableSpeed, Tag("table")],
    Discriminator(
        _speed_profile,
        custom_error_type="speed_profile",
        custom_error_message="unknown speed profile",
    ),
]
"""Any of the four disc-speed profiles, told apart by their `profile` key."""


class Perturbation(_Table):
    """Offsets added to the sliding equilibrium when a run starts from it.

    Attributes
    ----------
    phi
        Offset of the slider's angle [rad].
    phi_dot
        Offset of the slider's angular velocity [rad/s].
    """

    _key: ClassVar[tuple[str, ...]] = ("simulation", "perturbation")

    phi: Real = _field(1e-3, "rad")
    phi_dot: Real = _field(0.0, "rad/s")


class Simulation(_Table):
    """How to run: time span, output, initial state, options and tolerances.

    Attributes
    ----------
    duration
        Simulated time [s], > 0.
    output_rate
        Output samples per second [Hz], > 0.
    impact
        Apply the perfectly plastic impact at re-contact (else velocities are kept).
    initial_state
        "rest" (all displacements and velocities zero) or "equilibrium" (the
        sliding equilibrium plus `perturbation`; constant speed only).
    probes
        (r [m], theta [rad]) points of the disc whose displacement w is recorded;
        each r within [a, b].
    omega_dot_terms
        Keep the disc's dOmega/dt terms (the paper's printed equations omit them).
    printed_gyroscopic_sign
        Use the printed paper's sign of the gyroscopic term of the D equations
        (+2 l M Omega dC/dt instead of -). That form is not skew: it acts as a
        speed-proportional negative damping. For comparison with the paper only.
    rtol
        Relative tolerance of the integrator, in (0, 0.1].
    atol
        Absolute tolerance of the integrator, > 0.
    max_step
        Largest integrator step [s]; 0 means no limit.
    max_switches
        Phase switches (slip, stick, separation) after which the run stops, >= 1.
    perturbation
        Offsets from the sliding equilibrium used when `initial_state` is "equilibrium".
    """

    _key: ClassVar[tuple[str, ...]] = ("simulation",)

    duration: Real = _field(1.0, "s", gt=0)
    output_rate: Real = _field(10000.0, "Hz", gt=0)
    impact: Flag = True
    initial_state: Literal["rest", "equilibrium"] = "rest"
    probes: tuple[Probe, ...] = _field(((0.1, 0.0), (0.1, 1.0)))
    omega_dot_terms: Flag = True
    printed_gyroscopic_sign: Flag = False
    rtol: Real = _field(1e-6, gt=0, le=0.1)
    atol: Real = _field(1e-9, gt=0)
    max_step: Real = _field(0.0, "s", ge=0)
    max_switches: Count = _field(10_000_000, ge=1)
    perturbation: Perturbation = Perturbation()


class Case(_Table):
    """One simulation case: the disc, the slider, friction, disc speed and run settings.

    Build it with keyword tables (``Case(slider={"normal_damping": 2.0})``), from
    TOML (:func:`load_case`, :meth:`from_toml`) or from another case
    (:meth:`replace`). Instances are immutable; equal cases compare equal.

    Attributes
    ----------
    disc
        The annular disc and its modes.
    slider
        The slider and its springs, dampers and preload.
    friction
        The friction law.
    speed
        The disc speed profile Omega(t).
    simulation
        Run settings.
    """

    disc: Disc = Disc()
    slider: Slider = Slider()
    friction: Friction = Friction()
    speed: Speed = ConstantSpeed()
    simulation: Simulation = Simulation()

    @model_validator(mode="after")
    def _check_geometry_and_start(self) -> Case:
        a, b = self.disc.inner_radius, self.disc.outer_radius
        r0 = self.slider.track_radius
        if not a < r0 < b:
            raise _rule(
                f"must lie in (disc.inner_radius, disc.outer_radius) = ({a!r}, {b!r}) [m]",
                "slider.track_radius",
                r0,
            )
        for i, probe in enumerate(self.simulation.probes):
            if not a <= probe[0] <= b:
                raise _rule(
                    "radius must lie in [disc.inner_radius, disc.outer_radius] "
                    f"= [{a!r}, {b!r}] [m]",
                    f"simulation.probes[{i}]",
                    probe,
                )
        if self.simulation.initial_state == "equilibrium" and self.speed.profile != "constant":
            raise _rule(
                f'must be "rest" when speed.profile = "{self.speed.profile}" '
                "(a sliding equilibrium exists only at constant speed)",
                "simulation.initial_state",
                self.simulation.initial_state,
            )
        return self

    @classmethod
    def from_toml(cls, text: str) -> Case:
        """Parse and validate a case from TOML text.

        Parameters
        ----------
        text
            The case file's content.

        Raises
        ------
        CaseError
            Invalid TOML or an invalid case.
        """
        return _parse(text, source=None)

    def to_toml(self) -> str:
        """The case as TOML text, every key written out (defaults included)."""
        return tomli_w.dumps(self.model_dump(mode="json"))

    def save(self, path: str | PathLike[str]) -> None:
        """Write the case as a TOML file (see :meth:`to_toml`)."""
        Path(path).write_text(self.to_toml(), encoding="utf-8")

    @classmethod
    def valid_keys(cls) -> list[str]:
        """All dotted keys of values (not tables), e.g. ``"slider.mass"``.

        The speed keys of every profile are included (``speed.value``,
        ``speed.initial``, ``speed.duration``, ...).
        """
        return list(_LEAVES)

    def get(self, key: str) -> Any:
        """The value (or table) at a dotted key, e.g. ``case.get("slider.mass")``.

        Raises
        ------
        CaseError
            The key does not exist in this case.
        """
        node: Any = self
        for name in key.split("."):
            if not isinstance(node, BaseModel) or name not in type(node).model_fields:
                raise CaseError(_unknown_key(key, profile=self.speed.profile))
            node = getattr(node, name)
        return node

    def replace(self, updates: Mapping[str, Any]) -> Case:
        """A new, validated case with some values changed.

        Parameters
        ----------
        updates
            Dotted key -> new value, e.g. ``{"slider.normal_damping": 2.0}``. A
            key may also name a whole table (``"speed"``, ``"simulation"``,
            ``"simulation.perturbation"``), whose value (a dict or model) then
            replaces that table; keys it leaves out take their defaults. Tables
            are applied before the keys inside them. Setting ``speed.profile`` to
            a different profile starts the speed table afresh, so
            ``{"speed.profile": "decelerating", "speed.initial": 10.0}`` works
            from any case.

        Raises
        ------
        CaseError
            An unknown key or an invalid resulting case.
        """
        data = self.model_dump()
        # Shallow keys first, then speed.profile before its sibling speed keys.
        for key in sorted(updates, key=lambda k: (k.count("."), k != "speed.profile")):
            if key not in _LEAVES and key not in _TABLES:
                raise CaseError(_unknown_key(key))
            *path, name = key.split(".")
            table = data
            for i, part in enumerate(path):
                child = table.get(part, {})
                if isinstance(child, BaseModel):
                    child = child.model_dump()
                elif not isinstance(child, Mapping):
                    raise CaseError(
                        f"cannot set '{key}': {'.'.join(path[: i + 1])} = {_show(child)} "
                        "is not a table"
                    )
                table[part] = dict(child)
                table = table[part]
            if key == "speed.profile" and updates[key] != table.get("profile", "constant"):
                table.clear()
            table[name] = updates[key]
        return _validate(data, source=None)


# --- reading ---------------------------------------------------------------------------------


def load_case(path: str | PathLike[str]) -> Case:
    """Read and validate a TOML case file.

    Parameters
    ----------
    path
        The case file.

    Returns
    -------
    Case
        The validated case; keys the file leaves out take their defaults.

    Raises
    ------
    CaseError
        Invalid TOML or an invalid case; the message starts with the file's path.
    FivdiscError
        The path is a directory, cannot be read, or is not UTF-8 text.
    FileNotFoundError
        The file does not exist.
    """
    return _parse(read_text(path), source=str(path))


def _parse(text: str, source: str | None) -> Case:
    """Parse TOML `text` and validate it; `source` (a path) prefixes error messages."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        message = f"invalid TOML: {exc}"
        raise CaseError(f"{source}: {message}" if source else message) from None
    return _validate(data, source)


def _validate(data: Any, source: str | None) -> Case:
    """Validate a dict as a case; `source` (a path) prefixes error messages."""
    try:
        return Case.model_validate(data)
    except CaseError as exc:
        if source is None:
            raise
        raise CaseError(f"{source}: {exc}") from None


# --- keys ------------------------------------------------------------------------------------


def _walk(model: type[BaseModel], prefix: str) -> Iterator[tuple[str, list[str] | None]]:
    """Yield (dotted key, names inside it) for every table and leaf; names is None for a leaf."""
    for name, info in model.model_fields.items():
        key = f"{prefix}{name}"
        if model is Case and name == "speed":
            yield key, list(dict.fromkeys(n for s in _SPEEDS.values() for n in s.model_fields))
            for sub in _SPEEDS.values():
                yield from _walk(sub, key + ".")
        elif isinstance(info.annotation, type) and issubclass(info.annotation, _Table):
            yield key, list(info.annotation.model_fields)
            yield from _walk(info.annotation, key + ".")
        else:
            yield key, None


def _tables() -> dict[str, list[str]]:
    """Dotted table key -> names of its keys ("" is the top level)."""
    tables = {"": list(Case.model_fields)}
    for key, names in _walk(Case, ""):
        if names is not None:
            tables[key] = names
    return tables


_LEAVES: tuple[str, ...] = tuple(dict.fromkeys(k for k, names in _walk(Case, "") if names is None))
_TABLE_NAMES: dict[str, list[str]] = _tables()
_TABLES: frozenset[str] = frozenset(_TABLE_NAMES) - {""}


def _unknown_key(key: str, names: list[str] | None = None, profile: str | None = None) -> str:
    """Message for an unknown dotted key, with the nearest valid key if there is one.

    Parameters
    ----------
    key
        The dotted key.
    names
        The valid names in the key's table; None looks them up by the key's path.
    profile
        The case's speed profile, to explain a speed key that belongs to another one.
    """
    table, _, name = key.rpartition(".")
    if table == "speed" and profile in _SPEEDS and key in _LEAVES:
        own = ", ".join(f"'{n}'" for n in _SPEEDS[profile].model_fields)
        return f"unknown key '{key}' for speed profile '{profile}', which takes {own}"
    if names is None:
        names = _TABLE_NAMES.get(table)
    if names is not None:
        matches = difflib.get_close_matches(name, names, n=1)
        suggestion = f"{table}.{matches[0]}" if matches and table else (matches or [""])[0]
    else:
        candidates = [*_LEAVES, *_TABLES]
        suggestion = (difflib.get_close_matches(key, candidates, n=1) or [""])[0]
    hint = f"; did you mean '{suggestion}'?" if suggestion else ""
    return f"unknown key '{key}'{hint}"


# --- error messages --------------------------------------------------------------------------


def _show(value: Any) -> str:
    """A value as it would be written in TOML, shortened to one readable line."""
    if isinstance(value, BaseModel):
        value = value.model_dump()
    if isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, str):
        text = json.dumps(value)
    elif isinstance(value, list | tuple):
        text = "[" + ", ".join(_show(v) for v in value) + "]"
    elif isinstance(value, Mapping):
        text = "{" + ", ".join(f"{k} = {_show(v)}" for k, v in value.items()) + "}"
    else:
        text = repr(_plain(value))
    if len(text) > _MAX_SHOWN_CHARS:
        text = text[: _MAX_SHOWN_CHARS - 3] + "..."
    return text


def _join(parts: list[str | int]) -> str:
    """Dotted key with list indices, e.g. ``disc.modes[2][0]``."""
    text = ""
    for part in parts:
        if isinstance(part, int):
            text += f"[{part}]"
        else:
            text += f".{part}" if text else part
    return text


def _locate(
    root: type[_Table], loc: tuple[str | int, ...]
) -> tuple[list[str | int], type[BaseModel] | None, FieldInfo | None, bool]:
    """Follow a pydantic error location through the case tables.

    Returns
    -------
    parts
        Key path from the top of a case file, without the speed profile tag
        pydantic inserts for the discriminated union.
    owner
        The model that holds (or should hold) the last named key.
    field
        That key's field, or None if it is not a field of `owner`.
    item
        Whether the location ends inside an array value (an index).
    """
    parts: list[str | int] = list(root._key)
    model: type[BaseModel] | None = root
    owner: type[BaseModel] | None = root
    field: FieldInfo | None = None
    after_speed = False
    for part in loc:
        if isinstance(part, int):
            parts.append(part)
            continue
        if after_speed and part in _SPEEDS:
            model = owner = _SPEEDS[part]
            after_speed = False
            continue
        after_speed = False
        parts.append(part)
        owner = model
        field = model.model_fields.get(part) if model is not None else None
        model = None
        if field is None:
            continue
        if owner is Case and part == "speed":
            after_speed = True
        elif isinstance(field.annotation, type) and issubclass(field.annotation, _Table):
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


def _describe_error(error: ErrorDetails, root: type[_Table]) -> str:
    """One pydantic error as "key = value is invalid: rule [unit]"."""
    parts, owner, field, item = _locate(root, error["loc"])
    kind = error["type"]
    ctx = error.get("ctx", {})
    value = error["input"]

    if kind == "extra_forbidden":
        names = list(owner.model_fields) if owner is not None else None
        profile = owner.model_fields["profile"].default if owner in _SPEEDS.values() else None
        return _unknown_key(_join(parts), names, profile)
    if kind == "speed_profile":
        if isinstance(value, Mapping):
            parts, value = [*parts, "profile"], value.get("profile")
            rule = "must be one of " + ", ".join(f'"{p}"' for p in _SPEEDS)
        else:
            rule = "must be a table"
    elif kind == "case_rule":
        rule = ctx["rule"]
        if "key" in ctx:
            parts, value = [*parts, *ctx["key"].split(".")], ctx["value"]
    elif kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        bounds = _field_bounds(field) if field is not None and not item else {}
        rule = _interval(bounds or ctx)
        unit = (field.json_schema_extra or {}).get("unit") if field is not None else None
        if unit:
            rule += f" [{unit}]"
    elif kind in ("too_short", "too_long"):
        bound = ctx["min_length"] if kind == "too_short" else ctx["max_length"]
        entries = "entry" if bound == 1 else "entries"
        rule = f"must have at {'least' if kind == 'too_short' else 'most'} {bound} {entries}"
    elif kind in _TYPE_RULES:
        rule = _TYPE_RULES[kind]
    else:
        rule = error["msg"].replace("Input should", "must")
    return f"{_join(parts) or 'case'} = {_show(value)} is invalid: {rule}"


def _describe(exc: ValidationError, root: type[_Table]) -> str:
    """The first few errors of a ValidationError, on one line."""
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
    messages = [_describe_error(e, root) for e in errors[:_MAX_REPORTED_ERRORS]]
    if len(errors) > _MAX_REPORTED_ERRORS:
        messages.append(f"and {len(errors) - _MAX_REPORTED_ERRORS} more errors")
    return "; ".join(messages)


def unit_of(key: str) -> str:
    """Unit of a dotted case key (``"slider.normal_damping"`` -> ``"N s/m"``), "" if none."""
    table, _, name = key.rpartition(".")
    models = {
        "disc": (Disc,),
        "slider": (Slider,),
        "friction": (Friction,),
        "speed": (ConstantSpeed, DeceleratingSpeed, AcceleratingSpeed, TableSpeed),
        "simulation": (Simulation,),
        "simulation.perturbation": (Perturbation,),
    }.get(table, ())
    for model in models:
        field = model.model_fields.get(name)
        if field is not None:
            return str((field.json_schema_extra or {}).get("unit", ""))
    return ""

