"""The ``[speed]`` table: the disc-speed profiles, told apart by their ``profile`` key."""

from __future__ import annotations

import math
from typing import Annotated, ClassVar, Literal

from pydantic import model_validator

from fivdisc.case.fields import Real, SpeedValues, Table, TaggedUnion, field, increasing_from_zero
from fivdisc.case.messages import rule


class ConstantSpeed(Table):
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
    value: Real = field(math.tau, "rad/s", r"\Omega_c", "disc speed", ge=0)


class DeceleratingSpeed(Table):
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
    initial: Real = field(math.tau, "rad/s", r"\Omega_0", "initial disc speed", ge=0)
    duration: Real = field(35.0, "s", r"t_{\max}", "time to stop", gt=0)


class AcceleratingSpeed(Table):
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
    initial: Real = field(math.tau, "rad/s", r"\Omega_1", "initial disc speed", ge=0)
    rate: Real = field(0.2, "rad/s^2", "c", "disc acceleration", ge=0)


class TableSpeed(Table):
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
    times: Annotated[tuple[Real, ...], increasing_from_zero("s")] = field(
        (0.0, 1.0), "s", min_length=2
    )
    values: SpeedValues = field((math.tau, math.tau), "rad/s", min_length=2)

    @model_validator(mode="after")
    def _check_lengths(self) -> TableSpeed:
        if len(self.values) != len(self.times):
            raise rule(
                f"must have as many entries as speed.times ({len(self.times)})",
                "values",
                self.values,
            )
        return self


PROFILES: dict[str, type[Table]] = {
    "constant": ConstantSpeed,
    "decelerating": DeceleratingSpeed,
    "accelerating": AcceleratingSpeed,
    "table": TableSpeed,
}
SPEED = TaggedUnion("speed", "profile", PROFILES, "speed profile")

# Any of the four profiles, told apart by their `profile` key (documented in fivdisc.case).
Speed = SPEED.annotation()
