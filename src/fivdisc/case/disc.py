"""The ``[disc]`` table: the annular plate, its modes and damping."""

from __future__ import annotations

import math
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import AfterValidator, PlainSerializer, PlainValidator, model_validator

from fivdisc.case.fields import Mode, Real, Table, field
from fivdisc.case.messages import plain, rule
from fivdisc.limits import disc_problem

# Smallest normal double: a product below it has lost its precision.
_TINY = float(np.finfo(float).tiny)


def _distinct_modes(modes: tuple[tuple[int, int], ...]) -> tuple[tuple[int, int], ...]:
    """Reject a mode listed twice (its modal coordinates would be duplicated)."""
    seen: set[tuple[int, int]] = set()
    for mode in modes:
        if mode in seen:
            raise rule(f"must not repeat a mode; {list(mode)} appears twice")
        seen.add(mode)
    return modes


def _damping_ratios(value: Any) -> float | tuple[float, ...]:
    """One damping ratio >= 0, or an array of them."""
    value = plain(value)
    items = value if isinstance(value, list | tuple) else [value]
    for i, item in enumerate(items):
        where = f"entry {i} " if isinstance(value, list | tuple) else ""
        if isinstance(item, bool) or not isinstance(item, int | float):
            raise rule(f"{where}must be a number >= 0, or an array of them")
        if not (math.isfinite(item) and item >= 0):
            raise rule(f"{where}must be a finite number >= 0")
    if isinstance(value, list | tuple):
        return tuple(float(v) for v in value)
    return float(value)


class Disc(Table):
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

    inner_radius: Real = field(0.044, "m", "a", "disc inner radius", gt=0)
    outer_radius: Real = field(0.12, "m", "b", "disc outer radius", gt=0)
    thickness: Real = field(0.002, "m", "h", gt=0)
    density: Real = field(7200.0, "kg/m^3", r"\rho", gt=0)
    youngs_modulus: Real = field(150e9, "Pa", "E", gt=0)
    poisson_ratio: Real = field(0.211, "", r"\nu", gt=-1, lt=0.5)
    modes: Annotated[tuple[Mode, ...], AfterValidator(_distinct_modes)] = field(
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
            raise rule(
                f"must be > disc.inner_radius = {self.inner_radius!r} [m]",
                "outer_radius",
                self.outer_radius,
            )
        if isinstance(self.damping_ratio, tuple) and len(self.damping_ratio) != len(self.modes):
            raise rule(
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
            raise rule(f"must be < disc.outer_radius = {self.outer_radius!r} [m] (a plate)",
                        "thickness", h)
        with np.errstate(all="ignore"):
            rigidity = np.float64(self.youngs_modulus) * np.float64(h) ** 3
            per_area = np.float64(self.density) * h
            # numpy's power: Python's raises OverflowError for a radius like 1e300.
            scale = np.sqrt(rigidity / per_area) / np.float64(self.outer_radius) ** 2
        if not (np.isfinite(rigidity) and rigidity >= _TINY and per_area >= _TINY
                and np.isfinite(per_area)):
            raise rule(
                "with disc.youngs_modulus and disc.density gives a plate whose stiffness "
                f"E h^3 = {rigidity:.3g} N m or mass per area rho h = {per_area:.3g} kg/m^2 "
                "is out of floating-point range",
                "thickness", h)
        if not (np.isfinite(scale) and scale > 0):
            raise rule(
                "gives the plate a frequency scale sqrt(E h^3 / (rho h)) / b^2 = "
                f"{scale:.3g} rad/s out of floating-point range",
                "outer_radius", self.outer_radius)
        return self

    @model_validator(mode="after")
    def _check_limits(self) -> Disc:
        # Bounded work: see fivdisc.limits.
        problem = disc_problem(self.inner_radius, self.outer_radius, self.modes)
        if problem is not None:
            key, value, allowed = problem
            raise rule(allowed, key, value)
        return self

    def mode_damping(self) -> tuple[float, ...]:
        """Damping ratio of each entry of `modes` [-]."""
        if isinstance(self.damping_ratio, tuple):
            return self.damping_ratio
        return (self.damping_ratio,) * len(self.modes)
