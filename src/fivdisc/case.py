"""Case files: everything one simulation needs, as validated, immutable data.

A case is a tree of frozen pydantic models that mirrors the TOML file section by
section (``[disc]``, ``[slider]`` or ``[[sliders]]``, ``[friction]``, ``[speed]``,
``[simulation]`` and ``[simulation.perturbation]``). Every key has a default (the
paper's Table 1: one slider, a disc spinning at a constant 2 pi rad/s), so an empty
file is a valid case.

Every invalid input raises :class:`fivdisc.errors.CaseError` with a one-line
message that names the dotted key, the value given and the allowed range.
This module holds data and validation only; turning a case into kernel arrays
is done elsewhere.
"""

from __future__ import annotations

import itertools
import json
import math
import tomllib
from collections.abc import Iterator, Mapping
from os import PathLike
from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal, NamedTuple, Union

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
    PlainSerializer,
    PlainValidator,
    Strict,
    Tag,
    ValidationError,
    model_validator,
)
from pydantic.fields import FieldInfo
from pydantic_core import ErrorDetails, PydanticCustomError

from fivdisc.errors import CaseError, nearest
from fivdisc.files import read_text
from fivdisc.limits import MAX_SLIDERS, disc_problem

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

_TWO_PI = 2.0 * math.pi
# Sliders whose angles differ by no more than this [rad] (modulo 2 pi) are in one place.
_SAME_ANGLE = 1e-12
_EPS = float(np.finfo(float).eps)
# Smallest normal double: a product below it has lost its precision.
_TINY = float(np.finfo(float).tiny)
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
NonNegative = Annotated[Real, Field(ge=0)]
SpeedValues = Annotated[tuple[NonNegative, ...], BeforeValidator(_plain)]


def _field(default: Any, unit: str = "", symbol: str = "", name: str = "",
           **constraints: Any) -> Any:
    """A pydantic field that records its unit (for error messages), and its symbol in the
    paper (matplotlib mathtext, for axis labels) and a name where the key's words are not
    one (for ``long_name`` attributes); see :func:`describe_key`."""
    extra = {"unit": unit, "symbol": symbol, "name": name}
    return Field(default, json_schema_extra=extra, **constraints)


def _distinct_modes(modes: tuple[tuple[int, int], ...]) -> tuple[tuple[int, int], ...]:
    """Reject a mode listed twice (its modal coordinates would be duplicated)."""
    seen: set[tuple[int, int]] = set()
    for mode in modes:
        if mode in seen:
            raise _rule(f"must not repeat a mode; {list(mode)} appears twice")
        seen.add(mode)
    return modes


def _damping_ratios(value: Any) -> float | tuple[float, ...]:
    """One damping ratio >= 0, or an array of them."""
    value = _plain(value)
    items = value if isinstance(value, list | tuple) else [value]
    for i, item in enumerate(items):
        where = f"entry {i} " if isinstance(value, list | tuple) else ""
        if isinstance(item, bool) or not isinstance(item, int | float):
            raise _rule(f"{where}must be a number >= 0, or an array of them")
        if not (math.isfinite(item) and item >= 0):
            raise _rule(f"{where}must be a finite number >= 0")
    if isinstance(value, list | tuple):
        return tuple(float(v) for v in value)
    return float(value)


def _increasing_from_zero(unit: str) -> AfterValidator:
    """Reject a grid that does not start at 0 or does not strictly increase."""

    def check(points: tuple[float, ...]) -> tuple[float, ...]:
        # An empty grid is left to the field's min_length check.
        if points and points[0] != 0.0:
            raise _rule(f"must start at 0 [{unit}]")
        for earlier, later in itertools.pairwise(points):
            if later <= earlier:
                raise _rule(f"must strictly increase [{unit}]; {later!r} follows {earlier!r}")
        return points

    return AfterValidator(check)


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
            raise CaseError(_describe(exc, type(self), data)) from None

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
            raise CaseError(_describe(exc, cls, obj)) from None


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
    damping_ratio
        zeta, modal damping ratio [-], >= 0: one number for every mode, or one per
        entry of `modes` (the two coordinates of a doublet share it).
    damping_frame
        "material": the damping acts on the velocity of the disc's material,
        w_t + Omega w_theta (rotating-frame damping, the default); "space": on w_t.
    """

    _key: ClassVar[tuple[str, ...]] = ("disc",)

    inner_radius: Real = _field(0.044, "m", "a", "disc inner radius", gt=0)
    outer_radius: Real = _field(0.12, "m", "b", "disc outer radius", gt=0)
    thickness: Real = _field(0.002, "m", "h", gt=0)
    density: Real = _field(7200.0, "kg/m^3", r"\rho", gt=0)
    youngs_modulus: Real = _field(150e9, "Pa", "E", gt=0)
    poisson_ratio: Real = _field(0.211, "", r"\nu", gt=-1, lt=0.5)
    modes: Annotated[tuple[Mode, ...], AfterValidator(_distinct_modes)] = _field(
        ((0, 0), (0, 1), (0, 2), (0, 3))
    )
    damping_ratio: Annotated[
        float | tuple[float, ...],
        PlainValidator(_damping_ratios),
        # The union confuses pydantic's serializer for the tuple form; the value is plain.
        PlainSerializer(lambda value: list(value) if isinstance(value, tuple) else value),
    ] = 0.0
    damping_frame: Literal["material", "space"] = "material"

    @model_validator(mode="after")
    def _check_annulus(self) -> Disc:
        if self.outer_radius <= self.inner_radius:
            raise _rule(
                f"must be > disc.inner_radius = {self.inner_radius!r} [m]",
                "outer_radius",
                self.outer_radius,
            )
        if isinstance(self.damping_ratio, tuple) and len(self.damping_ratio) != len(self.modes):
            raise _rule(
                f"must be one number, or one per entry of disc.modes ({len(self.modes)})",
                "damping_ratio",
                self.damping_ratio,
            )
        return self

    @model_validator(mode="after")
    def _check_plate(self) -> Disc:
        # Thin-plate theory, and floating point: the plate's stiffness and mass per area
        # must be representable, or the modes overflow.
        h = self.thickness
        if not h < self.outer_radius:
            raise _rule(f"must be < disc.outer_radius = {self.outer_radius!r} [m] (a plate)",
                        "thickness", h)
        with np.errstate(all="ignore"):
            rigidity = np.float64(self.youngs_modulus) * np.float64(h) ** 3
            per_area = np.float64(self.density) * h
            scale = np.sqrt(rigidity / per_area) / self.outer_radius**2
        if not (np.isfinite(scale) and scale > 0 and np.isfinite(rigidity)
                and rigidity >= _TINY and per_area >= _TINY and np.isfinite(per_area)):
            raise _rule(
                "with disc.youngs_modulus and disc.density gives a plate whose stiffness "
                f"E h^3 = {rigidity:.3g} N m or mass per area rho h = {per_area:.3g} kg/m^2 "
                "is out of floating-point range",
                "thickness", h)
        return self

    @model_validator(mode="after")
    def _check_limits(self) -> Disc:
        # Bounded work: see fivdisc.limits.
        problem = disc_problem(self.inner_radius, self.outer_radius, self.modes)
        if problem is not None:
            key, value, rule = problem
            raise _rule(rule, key, value)
        return self

    def mode_damping(self) -> tuple[float, ...]:
        """Damping ratio of each entry of `modes` [-]."""
        if isinstance(self.damping_ratio, tuple):
            return self.damping_ratio
        return (self.damping_ratio,) * len(self.modes)


class Slider(_Table):
    """A slider: a mass on a transverse spring-damper and an in-plane one.

    Attributes
    ----------
    track_radius
        r_j, radius of the slider's track [m]; strictly between the disc's radii.
    mass
        m_j [kg]; its moment of inertia about the disc axis is m_j r_j^2.
    normal_stiffness
        k_z [N/m].
    normal_damping
        c_z [N s/m].
    rotational_stiffness
        r_j^2 k_phi [N m/rad].
    rotational_damping
        r_j^2 c_phi [N m s/rad].
    preload
        N0, normal preload [N], pressing the slider onto its face.
    angle
        theta_j, space-fixed angle of the slider's base [rad]; the slider sits at
        theta_j + phi_j.
    face
        "top" (the paper's side, on +w, pressed towards -w) or "bottom" (on -w,
        pressed towards +w).
    """

    _key: ClassVar[tuple[str, ...]] = ("slider",)

    track_radius: Real = _field(0.1, "m", "r_0", gt=0)
    mass: Real = _field(0.1, "kg", "m", gt=0)
    normal_stiffness: Real = _field(3e4, "N/m", "k_z", gt=0)
    normal_damping: Real = _field(0.1, "N s/m", "c_z", ge=0)
    rotational_stiffness: Real = _field(2e3, "N m/rad", r"r_0^2 k_\phi", gt=0)
    rotational_damping: Real = _field(0.1, "N m s/rad", r"r_0^2 c_\phi", ge=0)
    preload: Real = _field(500.0, "N", "N_0", ge=0)
    angle: Real = _field(0.0, "rad", r"\theta", "slider base angle")
    face: Literal["top", "bottom"] = "top"

    @property
    def sigma(self) -> float:
        """+1 on the top face, -1 on the bottom face."""
        return 1.0 if self.face == "top" else -1.0


class _FrictionLaw(_Table):
    """Common part of the friction laws: the static limit."""

    _key: ClassVar[tuple[str, ...]] = ("friction",)

    static: Real = _field(0.8, "", r"\mu_s", "static friction coefficient", ge=0)

    def kinetic_at_rest(self) -> tuple[tuple[str, float], ...]:
        """(key, value) pairs that the static coefficient may not be below."""
        raise NotImplementedError

    @model_validator(mode="after")
    def _check_static_limit(self) -> _FrictionLaw:
        for name, kinetic in self.kinetic_at_rest():
            if self.static < kinetic:
                raise _rule(
                    f"must be >= friction.{name} = {kinetic!r} "
                    "(static friction is the upper limit)",
                    "static",
                    self.static,
                )
        return self


class ExponentialFriction(_FrictionLaw):
    """The paper's law ``mu(u) = mu_1 + (mu_0 - mu_1) exp(-alpha u)``, u = r |Omega - phidot|.

    Attributes
    ----------
    law
        "exponential".
    static
        mu_s, static coefficient; not below mu_0 nor mu_1.
    kinetic_max
        mu_0, kinetic coefficient at zero sliding speed.
    kinetic_min
        mu_1, kinetic coefficient at high sliding speed.
    decay
        alpha, decay rate of the kinetic coefficient with sliding speed [s/m].
    """

    law: Literal["exponential"] = "exponential"
    kinetic_max: Real = _field(0.6, "", r"\mu_0", "kinetic friction coefficient at rest", ge=0)
    kinetic_min: Real = _field(0.35, "", r"\mu_1", "kinetic friction coefficient at high speed",
                               ge=0)
    decay: Real = _field(1.0, "s/m", r"\alpha", "friction decay rate", ge=0)

    def kinetic_at_rest(self) -> tuple[tuple[str, float], ...]:
        return (("kinetic_max", self.kinetic_max), ("kinetic_min", self.kinetic_min))


class StribeckFriction(_FrictionLaw):
    """Stribeck law ``mu(u) = mu_1 + (mu_0 - mu_1) exp(-(u / v_s)^delta) + mu_v u``.

    Attributes
    ----------
    law
        "stribeck".
    static
        mu_s, static coefficient; not below mu_0 nor mu_1.
    kinetic_max
        mu_0, kinetic coefficient at zero sliding speed.
    kinetic_min
        mu_1, the Coulomb level at high sliding speed (before the viscous part).
    stribeck_velocity
        v_s, Stribeck velocity [m/s], > 0.
    stribeck_exponent
        delta, shape exponent, > 0 (1: the exponential law with alpha = 1 / v_s).
    viscous
        mu_v, viscous friction coefficient [s/m], >= 0.
    """

    law: Literal["stribeck"] = "stribeck"
    kinetic_max: Real = _field(0.6, "", r"\mu_0", "kinetic friction coefficient at rest", ge=0)
    kinetic_min: Real = _field(0.35, "", r"\mu_1", "kinetic friction coefficient at high speed",
                               ge=0)
    stribeck_velocity: Real = _field(1.0, "m/s", "v_s", gt=0)
    stribeck_exponent: Real = _field(2.0, "", r"\delta", gt=0)
    viscous: Real = _field(0.0, "s/m", r"\mu_v", "viscous friction coefficient", ge=0)

    def kinetic_at_rest(self) -> tuple[tuple[str, float], ...]:
        return (("kinetic_max", self.kinetic_max), ("kinetic_min", self.kinetic_min))


class TableFriction(_FrictionLaw):
    """Measured friction curve: PCHIP through (sliding speed, mu), constant beyond the last.

    Attributes
    ----------
    law
        "table".
    static
        mu_s, static coefficient; not below the first tabulated value.
    speeds
        Sliding speeds u [m/s]: start at 0, strictly increase, at least two.
    values
        Kinetic coefficients at `speeds`, each >= 0; as many as `speeds`.
    """

    law: Literal["table"] = "table"
    speeds: Annotated[tuple[Real, ...], _increasing_from_zero("m/s")] = _field(
        (0.0, 1.0), "m/s", min_length=2
    )
    values: Annotated[tuple[NonNegative, ...], BeforeValidator(_plain)] = _field(
        (0.6, 0.35), min_length=2
    )

    @model_validator(mode="after")
    def _check_lengths(self) -> TableFriction:
        if len(self.values) != len(self.speeds):
            raise _rule(
                f"must have as many entries as friction.speeds ({len(self.speeds)})",
                "values",
                self.values,
            )
        return self

    def kinetic_at_rest(self) -> tuple[tuple[str, float], ...]:
        return (("values[0]", self.values[0]),)


Friction = ExponentialFriction
"""The default friction law, the paper's (:class:`ExponentialFriction`)."""


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
    value: Real = _field(_TWO_PI, "rad/s", r"\Omega_c", "disc speed", ge=0)


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
    initial: Real = _field(_TWO_PI, "rad/s", r"\Omega_0", "initial disc speed", ge=0)
    duration: Real = _field(35.0, "s", r"t_{\max}", "time to stop", gt=0)


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
    initial: Real = _field(_TWO_PI, "rad/s", r"\Omega_1", "initial disc speed", ge=0)
    rate: Real = _field(0.2, "rad/s^2", "c", "disc acceleration", ge=0)


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
    times: Annotated[tuple[Real, ...], _increasing_from_zero("s")] = _field(
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
_LAWS: dict[str, type[_Table]] = {
    "exponential": ExponentialFriction,
    "stribeck": StribeckFriction,
    "table": TableFriction,
}


class _Union:
    """A table that is one of several models, told apart by a tag key."""

    def __init__(self, table: str, tag: str, models: dict[str, type[_Table]], what: str) -> None:
        self.table = table
        self.tag = tag
        self.models = models
        self.default = next(iter(models))
        self.what = what

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


_UNIONS: dict[str, _Union] = {
    "speed": _Union("speed", "profile", _SPEEDS, "speed profile"),
    "friction": _Union("friction", "law", _LAWS, "friction law"),
}

Speed = _UNIONS["speed"].annotation()
"""Any of the four disc-speed profiles, told apart by their `profile` key."""

FrictionLaw = _UNIONS["friction"].annotation()
"""Any of the friction laws, told apart by their `law` key."""


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

    phi: Real = _field(1e-3, "rad", r"\Delta\phi", "perturbation of the slider angle")
    phi_dot: Real = _field(0.0, "rad/s", r"\Delta\dot\phi",
                          "perturbation of the slider angular velocity")


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
    max_steps
        Integrator steps (accepted and rejected) after which the run stops with status
        ``too_many_steps``, keeping what was computed, >= 1; a run estimated to need more
        is refused before it starts. The default is some minutes of work, about a
        hundred times what the longest of the paper's cases takes.
    min_flight_time
        Shortest flight of a slider that is resolved [s], > 0: a landing impact that
        would release another slider for less than this keeps it in contact (it ends
        the ever shorter flights of an impact cascade between several sliders).
    energy_balance
        Integrate the power of every force alongside the state, so that
        :func:`fivdisc.energy_balance` can account for the energy of the run.
    perturbation
        Offsets from the sliding equilibrium used when `initial_state` is "equilibrium"
        (the same offsets for every slider).
    """

    _key: ClassVar[tuple[str, ...]] = ("simulation",)

    duration: Real = _field(1.0, "s", "", "simulated time", gt=0)
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
    max_steps: Count = _field(100_000_000, ge=1)
    min_flight_time: Real = _field(1e-11, "s", gt=0)
    energy_balance: Flag = False
    perturbation: Perturbation = Perturbation()


class Case(_Table):
    """One simulation case: the disc, its sliders, friction, disc speed and run settings.

    Build it with keyword tables (``Case(slider={"normal_damping": 2.0})`` or
    ``Case(sliders=[{...}, {...}])``), from TOML (:func:`load_case`,
    :meth:`from_toml`) or from another case (:meth:`replace`). Instances are
    immutable; equal cases compare equal.

    Attributes
    ----------
    disc
        The annular disc, its modes and damping.
    sliders
        The sliders (one or more), each with its springs, dampers, preload, base
        angle and face. A file gives either one ``[slider]`` table or an array of
        ``[[sliders]]`` tables.
    friction
        The friction law (the same for every slider).
    speed
        The disc speed profile Omega(t).
    simulation
        Run settings.
    """

    disc: Disc = Disc()
    sliders: tuple[Slider, ...] = Field((Slider(),), min_length=1)
    friction: FrictionLaw = ExponentialFriction()
    speed: Speed = ConstantSpeed()
    simulation: Simulation = Simulation()

    @model_validator(mode="before")
    @classmethod
    def _one_slider_table(cls, data: Any) -> Any:
        # `[slider]` is the one-slider spelling of `[[sliders]]`.
        if isinstance(data, Mapping) and "slider" in data:
            if "sliders" in data:
                raise _rule(
                    "a case has either one [slider] table or [[sliders]] tables, not both; "
                    "pick one",
                    "slider",
                    data["slider"],
                )
            data = {("sliders" if k == "slider" else k): v for k, v in data.items()}
            data["sliders"] = [_plain(data["sliders"])]
        return data

    @property
    def slider(self) -> Slider:
        """The slider of a one-slider case.

        Raises
        ------
        CaseError
            The case has several sliders (use :attr:`sliders`).
        """
        if len(self.sliders) != 1:
            raise CaseError(
                f"the case has {len(self.sliders)} sliders: use case.sliders[j] "
                "(and keys sliders.J.KEY) instead of case.slider"
            )
        return self.sliders[0]

    def slider_key(self, j: int) -> str:
        """Dotted prefix of slider `j` in keys and messages: ``slider`` or ``sliders.J``."""
        return "slider" if len(self.sliders) == 1 else f"sliders.{j}"

    @model_validator(mode="after")
    def _check_geometry_and_start(self) -> Case:
        a, b = self.disc.inner_radius, self.disc.outer_radius
        if len(self.sliders) > MAX_SLIDERS:
            raise _rule(f"must have at most {MAX_SLIDERS} sliders (got {len(self.sliders)}: "
                        "the work per step grows as the cube of their number)", "sliders",
                        f"[{len(self.sliders)} tables]")
        for j, slider in enumerate(self.sliders):
            r0 = slider.track_radius
            if not a < r0 < b:
                raise _rule(
                    f"must lie in (disc.inner_radius, disc.outer_radius) = ({a!r}, {b!r}) [m]",
                    f"{self.slider_key(j)}.track_radius",
                    r0,
                )
            for i, other in enumerate(self.sliders[:j]):
                if (other.track_radius, other.face) != (r0, slider.face):
                    continue
                # Angles are the same place modulo 2 pi, up to their round-off.
                gap = abs(math.remainder(slider.angle - other.angle, _TWO_PI))
                if gap <= _SAME_ANGLE + 8 * _EPS * max(abs(slider.angle), abs(other.angle)):
                    raise _rule(
                        f"puts sliders.{j} where sliders.{i} is (r = {r0!r} m on the "
                        f"{slider.face} face, angles equal modulo 2 pi): sliders on one face "
                        "need different angles or radii",
                        f"sliders.{j}.angle",
                        slider.angle,
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
        """The case as TOML text, every key written out (defaults included).

        One slider is written as a ``[slider]`` table, several as ``[[sliders]]``.
        """
        data = self.model_dump(mode="json")
        if len(self.sliders) == 1:
            data = {("slider" if k == "sliders" else k): (v[0] if k == "sliders" else v)
                    for k, v in data.items()}
        return _inline_arrays(tomli_w.dumps(data))

    def save(self, path: str | PathLike[str]) -> None:
        """Write the case as a TOML file (see :meth:`to_toml`)."""
        Path(path).write_text(self.to_toml(), encoding="utf-8")

    @classmethod
    def valid_keys(cls) -> list[str]:
        """All dotted keys of values (not tables), e.g. ``"slider.mass"``.

        The keys of every speed profile and friction law are included
        (``speed.value``, ``speed.initial``, ``friction.decay``, ...). A slider's
        keys are listed as ``slider.KEY`` (the one slider); slider ``J`` of a case
        with several is ``sliders.J.KEY``.
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
        for name in self._path(key):
            if isinstance(node, tuple):
                node = node[name]
            elif isinstance(node, BaseModel) and name in type(node).model_fields:
                node = getattr(node, name)
            else:
                raise CaseError(self._unknown(key))
        return node

    def _unknown(self, key: str) -> str:
        return _unknown_key(key, profile=self.speed.profile, law=self.friction.law)

    def _path(self, key: str) -> list[str | int]:
        """Path of a dotted key through the model: ``slider.X`` and ``sliders.J.X`` lead to
        ``["sliders", J, "X"]``."""
        parts: list[str | int] = list(key.split("."))
        if parts[0] == "slider":
            if len(self.sliders) != 1:
                raise CaseError(
                    f"'{key}' is ambiguous: the case has {len(self.sliders)} sliders; write "
                    f"sliders.J.{'.'.join(map(str, parts[1:])) or 'KEY'} with J from 0 to "
                    f"{len(self.sliders) - 1}"
                )
            return ["sliders", 0, *parts[1:]]
        if parts[0] == "sliders" and len(parts) > 1:
            index = parts[1]
            if not (isinstance(index, str) and index.isdigit()
                    and int(index) < len(self.sliders)):
                raise CaseError(
                    f"'{key}': slider index {index!r} is invalid: the case has "
                    f"{len(self.sliders)} slider(s), numbered from 0"
                )
            return ["sliders", int(index), *parts[2:]]
        return parts

    def replace(self, updates: Mapping[str, Any]) -> Case:
        """A new, validated case with some values changed.

        Parameters
        ----------
        updates
            Dotted key -> new value, e.g. ``{"slider.normal_damping": 2.0}`` or, with
            several sliders, ``{"sliders.1.preload": 300.0}``. A key may also name a
            whole table (``"speed"``, ``"simulation"``, ``"sliders.1"``,
            ``"simulation.perturbation"``) or the list ``"sliders"``, whose value (a
            dict or model, or a list of them) then replaces it; keys it leaves out take
            their defaults. Tables are applied before the keys inside them. Setting
            ``speed.profile`` (``friction.law``) to a different profile (law) starts
            that table afresh, so ``{"speed.profile": "decelerating",
            "speed.initial": 10.0}`` works from any case.

        Raises
        ------
        CaseError
            An unknown key or an invalid resulting case.
        """
        if not isinstance(updates, Mapping):
            raise CaseError(f"updates = {_show(updates)} is invalid: must be a mapping of "
                            "dotted keys to values, e.g. {'slider.mass': 0.2}")
        for key in updates:
            if not isinstance(key, str):
                raise CaseError(f"updates key {key!r} is invalid: must be a dotted key "
                                "(str), e.g. 'slider.mass'")
        data = self.model_dump()
        tags = {f"{u.table}.{u.tag}" for u in _UNIONS.values()}
        # Shallow keys first, then a union's tag before its sibling keys.
        for key in sorted(updates, key=lambda k: (k.count("."), k not in tags)):
            if _template(key) not in _LEAVES and _template(key) not in _TABLES:
                raise CaseError(self._unknown(key))
            *path, name = self._path(key)
            table: Any = data
            for i, part in enumerate(path):
                child = table[part] if isinstance(part, int) else table.get(part, {})
                if isinstance(child, BaseModel):
                    child = child.model_dump()
                elif not isinstance(child, Mapping | list | tuple):
                    raise CaseError(
                        f"cannot set '{key}': {_join(path[: i + 1])} = {_show(child)} "
                        "is not a table"
                    )
                table[part] = list(child) if isinstance(child, list | tuple) else dict(child)
                table = table[part]
            if key in tags:
                union = _UNIONS[key.split(".")[0]]
                if updates[key] != table.get(union.tag, union.default):
                    table.clear()
            table[name] = _plain(updates[key])
        return _validate(data, source=None)


def _inline_arrays(text: str, width: int = 88) -> str:
    """TOML `text` with each array on one line (``modes = [[0, 0], [0, 1]]``), or one line
    per element when that is wider than `width`: tomli_w writes one number per line."""
    out: list[str] = []
    lines = iter(text.splitlines())
    for line in lines:
        key, sep, value = line.partition(" = ")
        if not (sep and value == "["):
            out.append(line)
            continue
        block = [line]
        for inner in lines:
            block.append(inner)
            if inner == "]":
                break
        items = tomllib.loads("\n".join(block))[key.strip().strip('"')]
        inline = [json.dumps(item, separators=(", ", ": ")) for item in items]
        one = f"{key} = [{', '.join(inline)}]"
        out += [one] if len(one) <= width else [f"{key} = [", *(f"    {i}," for i in inline), "]"]
    return "\n".join(out) + "\n"


def is_case_key(key: str) -> bool:
    """Whether ``key`` names a value of some case: a key of :meth:`Case.valid_keys` or
    ``sliders.J.KEY`` for a slider key (whether slider J exists depends on the case)."""
    return _template(key) in _LEAVES


def keys_like(key: str) -> list[str]:
    """The valid keys to suggest for `key`: :meth:`Case.valid_keys`, with the slider keys
    written ``sliders.J.KEY`` when `key` names slider J that way."""
    parts = key.split(".")
    keys = Case.valid_keys()
    if parts[0] == "sliders" and len(parts) > 2 and parts[1].isdigit():
        prefix = f"sliders.{parts[1]}."
        return [prefix + k.split(".", 1)[1] if k.startswith("slider.") else k for k in keys]
    return keys


def _template(key: str) -> str:
    """The key with a slider index removed: ``sliders.2.mass`` -> ``slider.mass``."""
    parts = key.split(".")
    if parts[0] == "sliders" and len(parts) > 1 and parts[1].isdigit():
        return ".".join(["slider", *parts[2:]])
    return key


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
    except RecursionError:
        message = "invalid TOML: arrays or tables nested too deeply"
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
        if model is Case and name in _UNIONS:
            union = _UNIONS[name]
            yield key, union.keys()
            for sub in union.models.values():
                yield from _walk(sub, key + ".")
        elif model is Case and name == "sliders":
            yield "slider", list(Slider.model_fields)
            yield from _walk(Slider, "slider.")
        elif isinstance(info.annotation, type) and issubclass(info.annotation, _Table):
            yield key, list(info.annotation.model_fields)
            yield from _walk(info.annotation, key + ".")
        else:
            yield key, None


def _tables() -> dict[str, list[str]]:
    """Dotted table key -> names of its keys ("" is the top level)."""
    tables = {"": ["slider", *Case.model_fields]}
    for key, names in _walk(Case, ""):
        if names is not None:
            tables[key] = names
    return tables


_LEAVES: tuple[str, ...] = tuple(dict.fromkeys(k for k, names in _walk(Case, "") if names is None))
_TABLE_NAMES: dict[str, list[str]] = _tables()
_TABLES: frozenset[str] = frozenset([*_TABLE_NAMES, "sliders"]) - {""}


def _unknown_key(key: str, names: list[str] | None = None, profile: str | None = None,
                 law: str | None = None) -> str:
    """Message for an unknown dotted key, ending with the nearest valid key.

    Parameters
    ----------
    key
        The dotted key.
    names
        The valid names in the key's table; None looks them up by the key's path.
    profile, law
        The case's speed profile and friction law, to explain a key that belongs to
        another profile or law.
    """
    table, _, name = key.rpartition(".")
    template_table = _template(table) if table else table
    for union, tag in ((_UNIONS["speed"], profile), (_UNIONS["friction"], law)):
        if table == union.table and tag in union.models and key in _LEAVES:
            own = ", ".join(f"'{n}'" for n in union.models[tag].model_fields)
            owners = " or ".join(f"'{o}'" for o in union.owner(name))
            return (f"unknown key '{key}' for {union.what} '{tag}', which takes {own} "
                    f"('{name}' belongs to {union.what} {owners})")
    if names is None:
        names = _TABLE_NAMES.get(template_table)
    if names is not None:
        candidates = [f"{table}.{n}" if table else n for n in names]
    else:
        candidates = [*_LEAVES, *_TABLES]
    return f"unknown key '{key}'{nearest(key, candidates)}"


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
    root: type[_Table], loc: tuple[str | int, ...], single: bool
) -> tuple[list[str | int], type[BaseModel] | None, FieldInfo | None, bool]:
    """Follow a pydantic error location through the case tables.

    Parameters
    ----------
    root
        The model that was validated.
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
    union: _Union | None = None
    in_sliders = False
    for part in loc:
        if in_sliders and isinstance(part, int):
            # Slider J is keyed `sliders.J` (or `slider` when it is the only one).
            parts[-1:] = ["slider"] if single else ["sliders", str(part)]
            model = owner = Slider
            in_sliders = False
            continue
        in_sliders = False
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
        if owner is Case and part in _UNIONS:
            union = _UNIONS[part]
        elif owner is Case and part == "sliders":
            in_sliders = True
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


def _describe_error(error: ErrorDetails, root: type[_Table], single: bool) -> str:
    """One pydantic error as "key = value is invalid: rule [unit]"."""
    parts, owner, field, item = _locate(root, error["loc"], single)
    kind = error["type"]
    ctx = error.get("ctx", {})
    value = error["input"]

    if kind == "extra_forbidden":
        names = list(owner.model_fields) if owner is not None else None
        if owner is Case:
            names = _TABLE_NAMES[""]
        tags = {u.table: owner.model_fields[u.tag].default
                for u in _UNIONS.values() if owner in u.models.values()}
        return _unknown_key(_join(parts), names, tags.get("speed"), tags.get("friction"))
    if kind == "union_tag":
        union = _UNIONS[str(parts[-1])] if parts and parts[-1] in _UNIONS else None
        if isinstance(value, Mapping) and union is not None:
            parts, value = [*parts, union.tag], value.get(union.tag)
            rule = "must be one of " + ", ".join(f'"{p}"' for p in union.models)
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


def _describe(exc: ValidationError, root: type[_Table], data: Any = None) -> str:
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
    sliders = data.get("sliders") if isinstance(data, Mapping) else None
    single = not isinstance(sliders, list | tuple) or len(sliders) == 1
    messages = [_describe_error(e, root, single) for e in errors[:_MAX_REPORTED_ERRORS]]
    if len(errors) > _MAX_REPORTED_ERRORS:
        messages.append(f"and {len(errors) - _MAX_REPORTED_ERRORS} more errors")
    return "; ".join(messages)


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

    ``sliders.J.KEY`` is described as ``slider.KEY`` of slider J; the keys of every speed
    profile and friction law are known (a key of two profiles, ``speed.initial``, takes
    the first one's symbol). An unknown key gives its own words and no unit.

    Parameters
    ----------
    key
        E.g. ``"slider.normal_damping"`` -> ``("N s/m", "c_z", "slider normal damping")``.
    """
    table, _, name = _template(key).rpartition(".")
    models = {
        "disc": (Disc,),
        "slider": (Slider,),
        "friction": tuple(_LAWS.values()),
        "speed": tuple(_SPEEDS.values()),
        "simulation": (Simulation,),
        "simulation.perturbation": (Perturbation,),
    }.get(table, ())
    extra: dict[str, str] = {}
    for model in models:
        field = model.model_fields.get(name)
        if field is not None:
            extra = dict(field.json_schema_extra or {})
            break
    words = extra.get("name") or name.replace("_", " ")
    if table == "slider":
        parts = key.split(".")
        owner = f"slider {parts[1]}" if parts[0] == "sliders" else "slider"
    else:
        owner = _TABLE_WORDS.get(table, table)
    head = owner.split(" ")[0]
    if head and head in words.split(" "):
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
