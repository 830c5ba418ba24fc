"""The ``[friction]`` table: the friction laws, told apart by their ``law`` key."""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

from pydantic import BeforeValidator, model_validator

from fivdisc.case.fields import NonNegative, Real, Table, TaggedUnion, field, increasing_from_zero
from fivdisc.case.messages import plain, rule


class _FrictionLaw(Table):
    """Common part of the friction laws: the static limit."""

    _key: ClassVar[tuple[str, ...]] = ("friction",)

    static: Real = field(0.8, "", r"\mu_s", "static friction coefficient", ge=0)

    def kinetic_at_rest(self) -> tuple[tuple[str, float], ...]:
        """(key, value) pairs that the static coefficient may not be below."""
        raise NotImplementedError

    @model_validator(mode="after")
    def _check_static_limit(self) -> _FrictionLaw:
        for name, kinetic in self.kinetic_at_rest():
            if self.static < kinetic:
                raise rule(
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
    kinetic_max: Real = field(0.6, "", r"\mu_0", "kinetic friction coefficient at rest", ge=0)
    kinetic_min: Real = field(0.35, "", r"\mu_1", "kinetic friction coefficient at high speed",
                               ge=0)
    decay: Real = field(1.0, "s/m", r"\alpha", "friction decay rate", ge=0)

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
    kinetic_max: Real = field(0.6, "", r"\mu_0", "kinetic friction coefficient at rest", ge=0)
    kinetic_min: Real = field(0.35, "", r"\mu_1", "kinetic friction coefficient at high speed",
                               ge=0)
    stribeck_velocity: Real = field(1.0, "m/s", "v_s", gt=0)
    stribeck_exponent: Real = field(2.0, "", r"\delta", gt=0)
    viscous: Real = field(0.0, "s/m", r"\mu_v", "viscous friction coefficient", ge=0)

    def kinetic_at_rest(self) -> tuple[tuple[str, float], ...]:
        return (("kinetic_max", self.kinetic_max), ("kinetic_min", self.kinetic_min))


class TableFriction(_FrictionLaw):
    """Measured friction curve: PCHIP through (sliding speed, mu), constant beyond the last.

    Attributes
    ----------
    law
        "table".
    static
        mu_s, static coefficient; not below any tabulated value.
    speeds
        Sliding speeds u [m/s]: start at 0, strictly increase, at least two.
    values
        Kinetic coefficients at `speeds`, each >= 0; as many as `speeds`.
    """

    law: Literal["table"] = "table"
    speeds: Annotated[tuple[Real, ...], increasing_from_zero("m/s")] = field(
        (0.0, 1.0), "m/s", min_length=2
    )
    values: Annotated[tuple[NonNegative, ...], BeforeValidator(plain)] = field(
        (0.6, 0.35), min_length=2
    )

    @model_validator(mode="after")
    def _check_lengths(self) -> TableFriction:
        if len(self.values) != len(self.speeds):
            raise rule(
                f"must have as many entries as friction.speeds ({len(self.speeds)})",
                "values",
                self.values,
            )
        # The curve (monotone between the points, constant beyond) stays within the
        # values: static friction is its upper limit, as for the other laws' kinetic
        # coefficients.
        top = max(range(len(self.values)), key=lambda i: self.values[i])
        if self.static < self.values[top]:
            raise rule(
                f"must be >= every value of friction.values: friction.values[{top}] = "
                f"{self.values[top]!r} at friction.speeds[{top}] = {self.speeds[top]!r} m/s "
                "is above it (static friction is the upper limit of friction; a curve that "
                'rises with speed beyond it: law = "stribeck" with viscous)',
                "static",
                self.static,
            )
        return self

    def kinetic_at_rest(self) -> tuple[tuple[str, float], ...]:
        return (("values[0]", self.values[0]),)


LAWS: dict[str, type[Table]] = {
    "exponential": ExponentialFriction,
    "stribeck": StribeckFriction,
    "table": TableFriction,
}
FRICTION = TaggedUnion("friction", "law", LAWS, "friction law")

FrictionLaw = FRICTION.annotation()
"""Any of the friction laws, told apart by their `law` key."""
