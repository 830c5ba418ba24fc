"""The case itself (:class:`Case`): the tables of one simulation, read from a file, written
back, changed by dotted keys."""

from __future__ import annotations

import math
from collections.abc import Mapping
from os import PathLike
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import tomli_w
from pydantic import BaseModel, Field, model_validator

from fivdisc.case.disc import Disc
from fivdisc.case.fields import Table, TaggedUnion
from fivdisc.case.friction import FRICTION, ExponentialFriction, FrictionLaw
from fivdisc.case.messages import join, plain, rule, show, unknown_key
from fivdisc.case.simulation import Simulation
from fivdisc.case.slider import Slider
from fivdisc.case.speed import SPEED, ConstantSpeed, Speed
from fivdisc.case.toml import inline_arrays, read_toml
from fivdisc.case.tree import EVERY, catalog, template
from fivdisc.errors import CaseError
from fivdisc.files import read_text
from fivdisc.limits import MAX_SLIDERS

# Sliders whose angles differ by no more than this [rad] (modulo 2 pi) are in one place.
_SAME_ANGLE = 1e-12
_EPS = float(np.finfo(float).eps)
#: Largest angle of a place on the disc (a slider's base, a probe) [rad], as for a
#: slider's initial rotation (:data:`fivdisc.engine.equilibrium.MAX_PHI`): further out a
#: double resolves the angle to no better than 1e-10 rad, and at 1e300 not at all.
MAX_ANGLE = 1e6
#: Least distance between two sliders on one face [m]: closer, they press on one spot of
#: the disc (a contact spot is micrometres across at least), and a case that puts them
#: there is one slider given twice.
MIN_SLIDER_GAP = 1e-6


class Case(Table):
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

    See Also
    --------
    load_case : A case from a TOML file.
    fivdisc.examples.path : The files of the packaged example cases.

    Examples
    --------
    Tables are given as dicts; the keys left out keep the defaults (the paper's Table 1):

    >>> import fivdisc
    >>> case = fivdisc.Case(slider={"normal_damping": 2.0}, speed={"value": 10.0})
    >>> case.slider.normal_damping, case.slider.preload, case.speed.value
    (2.0, 500.0, 10.0)

    Cases are immutable: :meth:`replace` makes a new one from dotted keys.

    >>> faster = case.replace({"speed.value": 12.0, "simulation.duration": 0.05})
    >>> faster.get("speed.value"), faster == case
    (12.0, False)
    >>> print(faster.to_toml().split("[slider]")[0])
    [disc]
    inner_radius = 0.044
    outer_radius = 0.12
    thickness = 0.002
    density = 7200.0
    youngs_modulus = 150000000000.0
    poisson_ratio = 0.211
    modes = [[0, 0], [0, 1], [0, 2], [0, 3]]
    damping_ratio = 0.0
    damping_frame = "material"
    <BLANKLINE>
    """

    _unions: ClassVar[Mapping[str, TaggedUnion]] = {"speed": SPEED, "friction": FRICTION}
    _arrays: ClassVar[Mapping[str, tuple[str, type[Table]]]] = {"sliders": ("slider", Slider)}

    disc: Disc = Disc()
    sliders: tuple[Slider, ...] = Field((Slider(),), min_length=1)
    friction: FrictionLaw = ExponentialFriction()
    speed: Speed = ConstantSpeed()
    simulation: Simulation = Simulation()

    @model_validator(mode="before")
    @classmethod
    def _one_slider_table(cls, data: Any) -> Any:
        # `[slider]` is the one-slider spelling of `[[sliders]]`; next to `[[sliders]]` it
        # holds what every slider shares (each `[[sliders]]` table overrides it).
        if isinstance(data, Mapping) and "slider" in data:
            shared = plain(data["slider"])
            if "sliders" in data:
                items = plain(data["sliders"])
                if not isinstance(shared, Mapping) or not isinstance(items, list | tuple):
                    raise rule(
                        "must be a table of the keys every [[sliders]] table shares, next "
                        "to [[sliders]] tables",
                        "slider",
                        data["slider"],
                    )
                merged = [_merged(shared, item) for item in items]
                data = {k: v for k, v in data.items() if k != "slider"}
                data["sliders"] = merged
                return data
            data = {("sliders" if k == "slider" else k): v for k, v in data.items()}
            data["sliders"] = [shared]
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
            raise rule(f"must have at most {MAX_SLIDERS} sliders (got {len(self.sliders)}: "
                        "the work per step grows as the cube of their number)", "sliders",
                        f"[{len(self.sliders)} tables]")
        for j, slider in enumerate(self.sliders):
            r0 = slider.track_radius
            if not a < r0 < b:
                raise rule(
                    f"must lie in (disc.inner_radius, disc.outer_radius) = ({a!r}, {b!r}) [m]",
                    f"{self.slider_key(j)}.track_radius",
                    r0,
                )
            if not abs(slider.angle) <= MAX_ANGLE:
                raise rule(
                    f"must lie within +-{MAX_ANGLE:g} rad (further out a double places the "
                    "slider to no better than 1e-10 rad; only the angle modulo 2 pi counts)",
                    f"{self.slider_key(j)}.angle",
                    slider.angle,
                )
            for i, other in enumerate(self.sliders[:j]):
                if other.face != slider.face:
                    continue
                # Angles are the same place modulo 2 pi, up to their round-off.
                turn = math.remainder(slider.angle - other.angle, math.tau)
                r1 = other.track_radius
                gap = math.hypot(r0 - r1, 2.0 * math.sqrt(r0 * r1) * math.sin(turn / 2.0))
                same = _SAME_ANGLE + 8 * _EPS * max(abs(slider.angle), abs(other.angle))
                if r0 == r1 and abs(turn) <= same:
                    raise rule(
                        f"puts sliders.{j} where sliders.{i} is (r = {r0!r} m on the "
                        f"{slider.face} face, angles equal modulo 2 pi): sliders on one face "
                        "need different angles or radii",
                        f"sliders.{j}.angle",
                        slider.angle,
                    )
                if gap < MIN_SLIDER_GAP:
                    raise rule(
                        f"puts sliders.{j} {gap:.3g} m from sliders.{i} (r = {r1!r} and "
                        f"{r0!r} m, angles {other.angle!r} and {slider.angle!r} rad on the "
                        f"{slider.face} face): sliders on one face must be at least "
                        f"{MIN_SLIDER_GAP:g} m apart (closer, they press on one spot of the "
                        "disc: give one slider with their stiffnesses, dampers and preloads "
                        "added)",
                        f"sliders.{j}.angle",
                        slider.angle,
                    )
        for i, probe in enumerate(self.simulation.probes):
            if not a <= probe[0] <= b:
                raise rule(
                    "radius must lie in [disc.inner_radius, disc.outer_radius] "
                    f"= [{a!r}, {b!r}] [m]",
                    f"simulation.probes[{i}]",
                    probe,
                )
            if not abs(probe[1]) <= MAX_ANGLE:
                raise rule(
                    f"theta must lie within +-{MAX_ANGLE:g} rad (further out a double places "
                    "the probe to no better than 1e-10 rad; only the angle modulo 2 pi "
                    "counts)",
                    f"simulation.probes[{i}]",
                    probe,
                )
        sim = self.simulation
        if sim.initial_state != "equilibrium" and sim.perturbation != type(sim.perturbation)():
            raise rule(
                "must keep its defaults unless simulation.initial_state = "
                '"equilibrium" (it is added to the sliding equilibrium: a run from rest '
                'would ignore it); set initial_state = "equilibrium", or leave the '
                "perturbation out",
                "simulation.perturbation",
                sim.perturbation,
            )
        if self.simulation.initial_state == "equilibrium" and self.speed.profile != "constant":
            raise rule(
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
        return inline_arrays(tomli_w.dumps(data))

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
        return list(catalog(Case).leaves)

    def get(self, key: str) -> Any:
        """The value (or table) at a dotted key, e.g. ``case.get("slider.mass")``.

        A key of every slider (``sliders.*.KEY``, or ``slider.KEY`` in a case with several
        sliders) gives the value they share.

        Raises
        ------
        CaseError
            The key does not exist in this case, or names every slider and their values
            differ.
        """
        values = [self._at(key, path) for path in self._paths(key)]
        if len(values) > 1 and any(v != values[0] for v in values[1:]):
            one = key.split(".", 2)[-1] if key.startswith("sliders.") else key.split(".", 1)[1]
            raise CaseError(
                f"'{key}' has no single value: the sliders' values differ "
                f"({', '.join(show(v) for v in values)}); set it, or name one slider "
                f"(sliders.J.{one}, J from 0 to {len(self.sliders) - 1})"
            )
        return values[0]

    def _at(self, key: str, path: list[str | int]) -> Any:
        node: Any = self
        for name in path:
            if isinstance(node, tuple):
                node = node[name]
            elif isinstance(node, BaseModel) and name in type(node).model_fields:
                node = getattr(node, name)
            else:
                raise CaseError(self._unknown(key))
        return node

    def _unknown(self, key: str) -> str:
        """Message for an unknown dotted key (a key of another speed profile or friction
        law is explained as such)."""
        table = key.rpartition(".")[0]
        keys = catalog(Case)
        names = keys.names.get(template(table) if table else table)
        member = type(getattr(self, table)) if table in self._unions else None
        return unknown_key(key, names, member, everything=[*keys.leaves, *keys.tables])

    def _paths(self, key: str) -> list[list[str | int]]:
        """Paths of a dotted key through the model: ``sliders.J.X`` leads to
        ``["sliders", J, "X"]``; ``sliders.*.X`` to one path per slider, and so does
        ``slider.X`` (the one slider's, or with several sliders every slider's: the rule
        of ``docs/model.md``)."""
        parts: list[str | int] = list(key.split("."))
        if parts[0] == "slider":
            return [["sliders", j, *parts[1:]] for j in range(len(self.sliders))]
        if parts[0] == "sliders" and len(parts) > 1:
            index = parts[1]
            if index == EVERY:
                return [["sliders", j, *parts[2:]] for j in range(len(self.sliders))]
            if not (isinstance(index, str) and index.isdigit()
                    and int(index) < len(self.sliders)):
                raise CaseError(
                    f"'{key}': slider index {index!r} is invalid: the case has "
                    f"{len(self.sliders)} slider(s), numbered from 0 (or * for every slider)"
                )
            return [["sliders", int(index), *parts[2:]]]
        return [parts]

    def replace(self, updates: Mapping[str, Any]) -> Case:
        """A new, validated case with some values changed.

        Parameters
        ----------
        updates
            Dotted key -> new value, e.g. ``{"slider.normal_damping": 2.0}`` or, with
            several sliders, ``{"sliders.1.preload": 300.0}``; ``sliders.*.KEY`` (and
            ``slider.KEY`` with several sliders) sets KEY of every slider. A key may also name a
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
            raise CaseError(f"updates = {show(updates)} is invalid: must be a mapping of "
                            "dotted keys to values, e.g. {'slider.mass': 0.2}")
        for key in updates:
            if not isinstance(key, str):
                raise CaseError(f"updates key {key!r} is invalid: must be a dotted key "
                                "(str), e.g. 'slider.mass'")
        data = self.model_dump()
        keys = catalog(Case)
        tags = {f"{u.table}.{u.tag}" for u in self._unions.values()}
        # Shallow keys first, then a union's tag before its sibling keys.
        for key in sorted(updates, key=lambda k: (k.count("."), k not in tags)):
            if template(key) not in keys.leaves and template(key) not in keys.tables:
                raise CaseError(self._unknown(key))
            for full in self._paths(key):
                *path, name = full
                table: Any = data
                for i, part in enumerate(path):
                    child = table[part] if isinstance(part, int) else table.get(part, {})
                    if isinstance(child, BaseModel):
                        child = child.model_dump()
                    elif not isinstance(child, Mapping | list | tuple):
                        raise CaseError(
                            f"cannot set '{key}': {join(path[: i + 1])} = {show(child)} "
                            "is not a table"
                        )
                    table[part] = list(child) if isinstance(child, list | tuple) else dict(child)
                    table = table[part]
                if key in tags:
                    union = self._unions[key.split(".")[0]]
                    if updates[key] != table.get(union.tag, union.default):
                        table.clear()
                table[name] = plain(updates[key])
        return _validate(data, source=None)


def _merged(shared: Mapping[str, Any], item: Any) -> Any:
    """A ``[[sliders]]`` table over the ``[slider]`` keys every slider shares (a nested
    table merged key by key)."""
    if isinstance(item, BaseModel):
        item = item.model_dump()
    if not isinstance(item, Mapping):
        return item
    out = dict(shared)
    for k, v in item.items():
        out[k] = (_merged(out[k], v) if isinstance(out.get(k), Mapping)
                  and isinstance(v, Mapping) else v)
    return out


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

    See Also
    --------
    Case : A case built in Python; :meth:`Case.save` writes one to a file.

    Examples
    --------
    The paper's Fig. 10 case, which ships with fivdisc:

    >>> import fivdisc
    >>> from fivdisc import examples
    >>> case = fivdisc.load_case(examples.path("fig10"))
    >>> case.speed
    DeceleratingSpeed(profile='decelerating', initial=6.283185307179586, duration=35.0)

    A case written with :meth:`Case.save` reads back equal:

    >>> case.replace({"slider.preload": 300.0}).save("mycase.toml")
    >>> fivdisc.load_case("mycase.toml") == case.replace({"slider.preload": 300.0})
    True
    """
    return _parse(read_text(path), source=str(path))


def _parse(text: str, source: str | None) -> Case:
    """Parse TOML `text` and validate it; `source` (a path) prefixes error messages."""
    return _validate(read_toml(text, source), source)


def _validate(data: Any, source: str | None) -> Case:
    """Validate a dict as a case; `source` (a path) prefixes error messages."""
    try:
        return Case.model_validate(data)
    except CaseError as exc:
        if source is None:
            raise
        raise CaseError(f"{source}: {exc}") from None
