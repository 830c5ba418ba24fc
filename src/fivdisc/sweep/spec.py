"""Sweep definitions: a base case, axes over case keys, and the reductions to keep.

A sweep file is TOML::

    base = "fig27_base.toml"             # a case file (relative to this file), or a [base] table
    mode = "grid"                        # or "zip": all axes the same length, walked together
    [override]                           # optional: keys of the base changed for this sweep
    "simulation.duration" = 2.0          # (or [override.simulation] duration = 2.0)
    [axes]
    "speed.initial" = "2.0:20.0:40"      # start:stop:n (inclusive linspace), or a list of values
    "speed.duration" = [5.0, 10.0, 35.0]
    [link]                               # optional: keys that copy another key at every point
    "simulation.duration" = "speed.duration"
    [reduce]
    keep = ["separated", "first_separation_time"]
    [[reduce.section]]                   # optional: values at a section, many per point
    variable = "phi_dot"
    at = "maxima"                        # or a kind of switch: "stick", "slip", ...
    after = 2.0                          # transient [s]
    [reduce.largest_lyapunov]            # optional: settings of that reduction
    transient = 2.0

Points are numbered in C order (the first axis varies slowest). Building a
:class:`Sweep` validates everything, including the case of every point, so a sweep
that starts cannot fail on its input halfway through. The documentation's page "Sweep
files" describes every key.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
import tomllib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from os import PathLike
from pathlib import Path
from typing import Any, Literal

import numpy as np

from fivdisc.case import Case, is_case_key, keys_like, load_case
from fivdisc.errors import CaseError, nearest
from fivdisc.files import read_text
from fivdisc.limits import check_memory, check_simulation, simulation_bytes
from fivdisc.sweep.reductions import (
    LYAPUNOV_REDUCTIONS,
    LyapunovSettings,
    Reduction,
    SweepError,
    resolve,
    stop_events,
)
from fivdisc.sweep.sections import Section

__all__ = ["Sweep", "SweepError", "load_sweep", "parse_range"]

FORMAT = "fivdisc-sweep/1"
MODES = ("grid", "zip")
_FILE_KEYS = ("base", "override", "mode", "axes", "link", "reduce")
# A TOML file cannot give `base` a value and open a [base.X] table as well.
_BASE_CONFLICT = re.compile(r"^\s*base\s*=.*^\s*\[\s*base[.\]]", re.MULTILINE | re.DOTALL)
_REDUCE_KEYS = ("keep", "section", "largest_lyapunov")
_LYAPUNOV_KEYS = ("transient", "duration", "interval")
# Names the store gives its own variables.
_RESERVED = ("error", "checksum", "done")
_RANGE = re.compile(r"^\s*([^:]+):([^:]+):([^:]+)\s*$")
_INTEGER = re.compile(r"^\s*[+-]?\d+\s*$")
# Memory per axis value while parsing (the values, as floats and as Python objects), and
# per point of a sweep: its validated case (measured: 6.3 kB) and its share of the store
# template and the coordinator's bookkeeping.
_VALUE_BYTES = 64
_POINT_BYTES = 10_000


def parse_range(text: str, where: str = "range") -> list[float] | list[int]:
    """Values of a ``"start:stop:n"`` range: n evenly spaced values, both ends included.

    Parameters
    ----------
    text
        ``"start:stop:n"``; integers for start and stop give integer values when
        the spacing is a whole number.
    where
        Name of the setting, for error messages.

    Raises
    ------
    SweepError
        Not of that form, a non-finite end, n < 1, or n = 1 with start != stop.
    """
    match = _RANGE.match(text)
    rule = 'must be "start:stop:n" (n evenly spaced values, ends included) or a list of values'
    if match is None:
        raise SweepError(f"{where} = {text!r} is invalid: {rule}")
    start_text, stop_text, n_text = match.groups()
    try:
        start, stop, n = float(start_text), float(stop_text), int(n_text)
    except ValueError:
        raise SweepError(f"{where} = {text!r} is invalid: {rule}") from None
    if not (math.isfinite(start) and math.isfinite(stop)):
        raise SweepError(f"{where} = {text!r} is invalid: start and stop must be finite")
    if n < 1:
        raise SweepError(f"{where} = {text!r} is invalid: n must be >= 1")
    if n == 1 and start != stop:
        raise SweepError(f"{where} = {text!r} is invalid: n = 1 needs start == stop")
    check_memory(_VALUE_BYTES * n, f"{where} = {text!r} ({n} values)", "lower n")
    values = np.linspace(start, stop, n)
    if (
        _INTEGER.match(start_text)
        and _INTEGER.match(stop_text)
        and (n == 1 or (int(stop) - int(start)) % (n - 1) == 0)
    ):
        return [int(v) for v in np.rint(values)]
    return values.tolist()


def _unsigned_zero(value: Any) -> Any:
    """`value` with every -0.0 in it made 0.0: the same point of a case."""
    if isinstance(value, float) and value == 0.0:
        return 0.0
    if isinstance(value, list | tuple):
        return [_unsigned_zero(v) for v in value]
    if isinstance(value, Mapping):
        return {k: _unsigned_zero(v) for k, v in value.items()}
    return value


def _axis_values(key: str, raw: Any) -> tuple[Any, ...]:
    """An axis's values from a range string or a list."""
    where = f"axes.'{key}'"
    if isinstance(raw, str):
        return tuple(parse_range(raw, where))
    if isinstance(raw, np.ndarray):
        raw = raw.tolist()
    if not isinstance(raw, list | tuple) or not raw:
        raise SweepError(
            f'{where} = {raw!r} is invalid: must be a non-empty list of values or "start:stop:n"'
        )
    return tuple(v.item() if isinstance(v, np.generic) else v for v in raw)


def strides_of(shape: Sequence[int]) -> tuple[int, ...]:
    """Point-index step of each axis of a C-ordered grid of `shape`."""
    return tuple(int(s) for s in np.cumprod((1, *shape[:0:-1]))[::-1])


def _plain(value: Any) -> Any:
    """A case value as plain data: tuples (arrays in a case) become lists."""
    return _canonical(value) if isinstance(value, tuple) else value


def _canonical(value: Any) -> Any:
    """A value as plain JSON data (tuples become lists)."""
    return json.loads(json.dumps(value))


@dataclass(frozen=True)
class Sweep:
    """A validated sweep: base case, axes, linked keys and kept reductions.

    Parameters
    ----------
    base
        The case every point starts from.
    axes
        Dotted case key -> values, in order (a list, or ``"start:stop:n"``).
    mode
        ``"grid"``: every combination, first axis slowest; ``"zip"``: the axes,
        all of the same length, walked together.
    keep
        Reductions stored per point: built-in names (see
        :data:`fivdisc.sweep.reductions.BUILTIN`) or ``"package.module:function"``; may
        be empty when there are `sections`.
    link
        Dotted key -> dotted key whose value it copies at every point, after the
        axes are applied (e.g. ``{"simulation.duration": "speed.duration"}``).
    source
        File the sweep was read from, prefixed to error messages; None otherwise.
    sections
        Sections whose values are stored per point (``[[reduce.section]]``):
        :class:`~fivdisc.sweep.sections.Section` objects or tables of their keywords.
    lyapunov
        Settings of the ``largest_lyapunov`` reduction (``[reduce.largest_lyapunov]``):
        a table with ``transient``, ``duration``, ``interval`` [s], or
        :class:`~fivdisc.sweep.reductions.LyapunovSettings`; only with that reduction
        kept. Without them, or without a transient, the transient is the sections'
        largest ``after``.

    Raises
    ------
    SweepError
        Invalid axes, mode, link, reductions, sections or Lyapunov settings.
    CaseError
        The case of some point is invalid (the message names the point).
    """

    base: Case
    axes: Mapping[str, Any]
    mode: Literal["grid", "zip"] = "grid"
    keep: Sequence[str] = ("separated",)
    link: Mapping[str, str] = field(default_factory=dict)
    source: str | None = None
    sections: Sequence[Section | Mapping[str, Any]] = ()
    lyapunov: LyapunovSettings | Mapping[str, Any] | None = None
    reductions: tuple[Reduction, ...] = field(init=False, repr=False, compare=False)
    cases: tuple[Case, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        prefix = f"{self.source}: " if self.source else ""
        try:
            self._validate()
        except (SweepError, CaseError) as exc:
            raise type(exc)(f"{prefix}{exc}") from None

    def _validate(self) -> None:
        set_ = object.__setattr__  # frozen dataclass: normalised fields are set once, here
        if not isinstance(self.base, Case):
            raise SweepError(f"base = {self.base!r} is invalid: must be a fivdisc Case")
        if self.mode not in MODES:
            raise SweepError(
                f"mode = {self.mode!r} is invalid: must be one of {', '.join(map(repr, MODES))}"
            )
        valid = Case.valid_keys()
        for name in ("axes", "link"):
            if not isinstance(getattr(self, name), Mapping):
                raise SweepError(
                    f"{name} = {getattr(self, name)!r} is invalid: must be a table (mapping)"
                )
        if not self.axes:
            raise SweepError("axes is empty: name at least one case key to vary")
        axes: dict[str, tuple[Any, ...]] = {}
        for key, raw in self.axes.items():
            if not is_case_key(key):
                raise SweepError(f"axes: unknown case key '{key}'{nearest(key, keys_like(key))} "
                                 "(every key, with its unit: fivdisc examples default)")
            axes[key] = _axis_values(key, raw)
        if self.mode == "zip" and len({len(v) for v in axes.values()}) > 1:
            lengths = ", ".join(f"'{k}' has {len(v)}" for k, v in axes.items())
            raise SweepError(f"mode = 'zip' needs axes of equal length: {lengths}")
        set_(self, "axes", axes)

        link = dict(self.link)
        for target, origin in link.items():
            if not is_case_key(target):
                raise SweepError(f"link: unknown case key '{target}'{nearest(target, valid)}")
            if target in axes:
                raise SweepError(f"link: '{target}' is an axis; it cannot also copy '{origin}'")
            if not isinstance(origin, str) or not is_case_key(origin):
                raise SweepError(
                    f"link.'{target}' = {origin!r} is invalid: must be a case key"
                    f"{nearest(str(origin), valid)}"
                )
            if origin in link:
                # Links are applied one after the other: a chain or a circle of them would
                # depend on their order (a circle swaps values).
                raise SweepError(
                    f"link.'{target}' = '{origin}' is invalid: '{origin}' is itself linked "
                    f"(to '{link[origin]}'); link '{target}' to an axis or an unlinked key"
                )
        set_(self, "link", link)

        if isinstance(self.sections, str | Mapping) or not isinstance(self.sections, Sequence):
            raise SweepError(
                f"reduce.section = {self.sections!r} is invalid: must be an array of tables, "
                "[[reduce.section]]"
            )
        set_(self, "sections", tuple(Section.from_table(table, f"reduce.section[{i}]")
                                     for i, table in enumerate(self.sections)))
        if isinstance(self.keep, str) or not isinstance(self.keep, Sequence) or (
                not self.keep and not self.sections):
            raise SweepError(
                f"reduce.keep = {self.keep!r} is invalid: must be a non-empty list of reductions"
                " (it may be empty when there are [[reduce.section]] tables)"
            )
        set_(self, "keep", tuple(self.keep))
        set_(self, "lyapunov", self._lyapunov_settings())
        set_(self, "reductions", resolve(self.keep, self.lyapunov))
        self._check_names()
        check_memory(
            _POINT_BYTES * self.n_points,
            f"a sweep of {self.n_points} points ({' x '.join(map(str, self.shape))})",
            "use fewer values per axis, or split the sweep",
        )
        if self.sections:
            # Padded values of every point, as open_sweep loads them.
            check_memory(
                8 * self.n_points * sum(s.max_points for s in self.sections),
                f"the sections' values of {self.n_points} points "
                f"(max_points = {', '.join(str(s.max_points) for s in self.sections)})",
                "lower max_points, or use fewer points",
            )
        set_(self, "cases", tuple(self._point_case(i) for i in range(self.n_points)))
        check_simulation(max(self.cases, key=simulation_bytes))
        self._check_cases()
        # Keep the values as validated (e.g. 6 -> 6.0) so that equal sweeps have equal
        # definitions however their values were spelt.
        strides = strides_of(self.shape) if self.mode == "grid" else (1,) * len(axes)
        validated = {
            key: tuple(_plain(self.cases[j * stride].get(key)) for j in range(len(values)))
            for (key, values), stride in zip(axes.items(), strides, strict=True)
        }
        set_(self, "axes", validated)
        if self.mode == "grid":
            for key, values in validated.items():
                text = [json.dumps(_unsigned_zero(v), sort_keys=True) for v in values]
                repeated = next((v for v in text if text.count(v) > 1), None)
                if repeated is not None:
                    raise SweepError(
                        f"axes.'{key}' repeats the value {repeated}: grid axes must have "
                        "distinct values"
                    )

        if any(r.name == "max_growth_rate" for r in self.reductions):
            for i, case in enumerate(self.cases):
                if case.speed.profile != "constant":
                    raise SweepError(
                        f"reduce.keep: 'max_growth_rate' needs a constant disc speed, but point "
                        f"{i} ({self._describe(i)}) has speed.profile = '{case.speed.profile}'"
                    )

    def _lyapunov_settings(self) -> LyapunovSettings | None:
        """The settings of ``largest_lyapunov``, validated, defaults from the sections."""
        raw = self.lyapunov
        kept = any(name in self.keep for name in LYAPUNOV_REDUCTIONS)
        if raw is not None and not kept:
            raise SweepError(
                "reduce.largest_lyapunov sets the reduction 'largest_lyapunov', which "
                "reduce.keep does not list: add it to keep, or remove the table"
            )
        if not kept:
            return None
        if raw is None:
            raw = {}
        elif isinstance(raw, LyapunovSettings):
            raw = asdict(raw)
        elif not isinstance(raw, Mapping):
            raise SweepError(f"reduce.largest_lyapunov = {raw!r} is invalid: must be a table "
                             f"with {', '.join(_LYAPUNOV_KEYS)}")
        where = "reduce.largest_lyapunov"
        valid = [f"{where}.{k}" for k in _LYAPUNOV_KEYS]
        for key in raw:
            if key not in _LYAPUNOV_KEYS:
                raise SweepError(f"unknown key '{where}.{key}'{nearest(f'{where}.{key}', valid)}")
        values: dict[str, float | None] = {}
        for key, rule, ok in (("transient", ">= 0", lambda v: v >= 0),
                              ("duration", "> 0", lambda v: v > 0),
                              ("interval", "> 0", lambda v: v > 0)):
            value = raw.get(key)
            if value is None:
                continue
            if (isinstance(value, bool) or not isinstance(value, int | float)
                    or not math.isfinite(value) or not ok(value)):
                raise SweepError(f"{where}.{key} = {value!r} is invalid: must be a number "
                                 f"{rule} [s]")
            values[key] = float(value)
        if "transient" not in values and self.sections:
            values["transient"] = max(s.after for s in self.sections)
        return LyapunovSettings(**values)

    def _check_names(self) -> None:
        """No two stored variables share a name."""
        seen = {r.name: f"reduction '{r.spec}'" for r in self.reductions}
        seen |= {name: "the sweep's own variable" for name in _RESERVED}
        for section in self.sections:
            for name in (section.name, section.count_name, section.dim):
                if name in seen:
                    raise SweepError(
                        f"{section.where} would be stored as '{name}', as {seen[name]} is: "
                        f"give it another name ({section.where}.name)"
                    )
                seen[name] = section.where

    def _check_cases(self) -> None:
        """Sections and Lyapunov settings that every point's case allows."""
        from fivdisc.analysis.exponents import DEFAULT_INTERVAL, MAX_INTERVALS

        for i, case in enumerate(self.cases):
            for section in self.sections:
                problem = section.problem(case)
                if problem is not None:
                    raise SweepError(f"point {i} ({self._describe(i)}): {problem}")
            if self.lyapunov is None:
                continue
            transient, duration = self.lyapunov.window(case)
            where = "reduce.largest_lyapunov"
            if duration <= 0:
                raise SweepError(
                    f"point {i} ({self._describe(i)}): {where}.transient = {transient:g} is "
                    f"invalid: must be < simulation.duration = {case.simulation.duration:g} s "
                    f"(or set {where}.duration)"
                )
            interval = self.lyapunov.interval or min(DEFAULT_INTERVAL, duration)
            # The tangent vector is re-orthonormalised over the transient too (alignment).
            if (transient + duration) / interval > MAX_INTERVALS:
                raise SweepError(
                    f"point {i} ({self._describe(i)}): {where}.interval = {interval:g} s over "
                    f"a transient and measurement of {transient + duration:g} s is "
                    f"{(transient + duration) / interval:.3g} re-orthonormalisations, more "
                    f"than {MAX_INTERVALS:g}: lengthen the interval or shorten the transient "
                    "or the duration"
                )
            if self.lyapunov.interval is not None and self.lyapunov.interval > duration:
                raise SweepError(
                    f"point {i} ({self._describe(i)}): {where}.interval = "
                    f"{self.lyapunov.interval:g} is invalid: must be <= the measurement's "
                    f"duration, {duration:g} s"
                )

    # --- points --------------------------------------------------------------------------

    @property
    def shape(self) -> tuple[int, ...]:
        """Points along each axis (grid), or ``(n_points,)`` (zip)."""
        lengths = tuple(len(v) for v in self.axes.values())
        return lengths if self.mode == "grid" else lengths[:1]

    @property
    def n_points(self) -> int:
        """Number of points."""
        return math.prod(self.shape)

    def updates(self, index: int) -> dict[str, Any]:
        """Axis key -> value at point `index`."""
        if self.mode == "zip":
            return {key: values[index] for key, values in self.axes.items()}
        position = np.unravel_index(index, self.shape)
        return {
            key: values[int(i)]
            for (key, values), i in zip(self.axes.items(), position, strict=True)
        }

    def _describe(self, index: int) -> str:
        return ", ".join(f"{k} = {json.dumps(v)}" for k, v in self.updates(index).items())

    def _point_case(self, index: int) -> Case:
        try:
            case = self.base.replace(self.updates(index))
            if self.link:
                case = case.replace({t: case.get(o) for t, o in self.link.items()})
        except CaseError as exc:
            raise CaseError(f"point {index} ({self._describe(index)}): {exc}") from None
        return case

    def __iter__(self) -> Iterator[Case]:
        return iter(self.cases)

    # --- identity ------------------------------------------------------------------------

    @property
    def stop_on(self) -> tuple[str, ...]:
        """Event kinds that end a run early because every kept value is then decided
        (none with sections, which need the whole run)."""
        return () if self.sections else stop_events(self.reductions)

    @property
    def definition(self) -> str:
        """Canonical JSON text of the sweep: equal sweeps give equal text."""
        data = {
            "format": FORMAT,
            "base": self.base.model_dump(mode="json"),
            "mode": self.mode,
            "axes": [[key, _canonical(values)] for key, values in self.axes.items()],
            "link": [[t, o] for t, o in self.link.items()],
            "keep": list(self.keep),
        }
        # Only when present: the sweeps that have neither keep the hash they had before.
        if self.sections:
            data["sections"] = [s.to_dict() for s in self.sections]
        if self.lyapunov is not None:
            data["largest_lyapunov"] = asdict(self.lyapunov)
        return json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=False)

    @property
    def digest(self) -> str:
        """SHA-256 (hex) of :attr:`definition`."""
        return hashlib.sha256(self.definition.encode()).hexdigest()

    # --- reading -------------------------------------------------------------------------

    @classmethod
    def from_toml(
        cls, text: str, root: str | PathLike[str] | None = None, source: str | None = None
    ) -> Sweep:
        """Parse and validate a sweep from TOML text.

        Parameters
        ----------
        text
            The sweep file's content.
        root
            Directory a ``base`` file name is relative to (default: the working directory).
        source
            Name of the file, prefixed to error messages.
        """
        prefix = f"{source}: " if source else ""
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            if _BASE_CONFLICT.search(text):
                raise SweepError(
                    f"{prefix}base = \"FILE\" and a [base.TABLE] table cannot both be in a "
                    "TOML file (TOML gives the key 'base' one value: a file name or a table); "
                    "change keys of the base file in an [override] table instead, e.g. "
                    "[override.simulation] with duration = 2.0"
                ) from None
            raise SweepError(f"{prefix}invalid TOML: {exc}") from None
        try:
            kwargs = _file_fields(data, Path(root) if root is not None else Path.cwd())
        except (SweepError, CaseError) as exc:
            raise type(exc)(f"{prefix}{exc}") from None
        return cls(**kwargs, source=source)


def _file_fields(data: dict[str, Any], root: Path) -> dict[str, Any]:
    """Keyword arguments of :class:`Sweep` from a parsed sweep file."""
    for key in data:
        if key not in _FILE_KEYS:
            raise SweepError(f"unknown key '{key}'{nearest(key, _FILE_KEYS)}")
    raw_base = data.get("base", {})
    if isinstance(raw_base, str):
        path = root / raw_base
        try:
            base = load_case(path)
        except FileNotFoundError:
            raise SweepError(f"base = {raw_base!r} is invalid: no file {path}") from None
    elif isinstance(raw_base, dict):
        try:
            base = Case(**raw_base)
        except CaseError as exc:
            raise CaseError(f"base: {exc}") from None
    else:
        raise SweepError(f"base = {raw_base!r} is invalid: must be a case file name or a table")
    override = data.get("override", {})
    if not isinstance(override, dict):
        raise SweepError(f"override = {override!r} is invalid: must be a table of case keys, "
                         "e.g. [override.simulation] with duration = 2.0")
    if override:
        updates = dict(_dotted(override))
        for key in updates:
            if not is_case_key(key):
                raise SweepError(f"unknown key 'override.{key}': not a case key"
                                 f"{nearest(key, keys_like(key))}")
        try:
            base = base.replace(updates)
        except CaseError as exc:
            raise CaseError(f"override: {exc}") from None
    for table in ("axes", "link", "reduce"):
        if not isinstance(data.get(table, {}), dict):
            raise SweepError(f"{table} = {data[table]!r} is invalid: must be a table")
    reduce = data.get("reduce", {})
    for key in reduce:
        if key not in _REDUCE_KEYS:
            raise SweepError(f"unknown key 'reduce.{key}'"
                             f"{nearest(f'reduce.{key}', [f'reduce.{k}' for k in _REDUCE_KEYS])}")
    sections = reduce.get("section", [])
    if isinstance(sections, dict):
        raise SweepError("reduce.section is a single table: write it as an array of tables, "
                         "[[reduce.section]] (one per section)")
    if "keep" not in reduce and not sections:
        raise SweepError("reduce.keep is missing: list the reductions to store (or add "
                         "[[reduce.section]] tables)")
    return {
        "base": base,
        "mode": data.get("mode", "grid"),
        "axes": data.get("axes", {}),
        "link": data.get("link", {}),
        "keep": reduce.get("keep", []),
        "sections": sections,
        "lyapunov": reduce.get("largest_lyapunov"),
    }


def _dotted(table: Mapping[str, Any], prefix: str = "") -> Iterator[tuple[str, Any]]:
    """(dotted key, value) of every leaf of a nested table: ``{"simulation": {"duration":
    2.0}}`` and ``{"simulation.duration": 2.0}`` both give ``("simulation.duration", 2.0)``."""
    for key, value in table.items():
        if isinstance(value, Mapping):
            yield from _dotted(value, f"{prefix}{key}.")
        else:
            yield f"{prefix}{key}", value


def load_sweep(path: str | PathLike[str]) -> Sweep:
    """Read and validate a sweep file; a ``base`` file name is relative to it.

    Raises
    ------
    SweepError, CaseError
        Invalid sweep or case; the message starts with the file's path.
    FivdiscError
        The file is a directory, unreadable or not UTF-8 text; a point would not fit in
        memory (see :mod:`fivdisc.limits`).
    FileNotFoundError
        The sweep file does not exist.
    """
    path = Path(path)
    return Sweep.from_toml(read_text(path), root=path.parent, source=str(path))
