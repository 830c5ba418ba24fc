"""Sweep results in a Zarr store, written point by point, verified and safe to resume.

Layout (one Zarr v3 group, written through xarray, with consolidated metadata so that
``xarray.open_zarr`` opens it directly)::

    dims        <axis key>, ...                a grid sweep: one per axis, named after its
                                               key (e.g. speed.initial), in the sweep's order
                point                          a zip sweep: one entry per point
    coords      <axis key>                     the axis values, with units and long_name
                                               (JSON text if the values are not numbers,
                                               booleans or text); along point for a zip sweep
    data vars   <reduction name>               one per kept reduction (bool or float64)
                <section name>                 one per section: (<dims>..., <name>_index)
                                               float64, one point's values NaN padded to
                                               the section's max_points
                <section name>_count           how many of them are valid (int32)
                error                          "" or why the point failed
                checksum                       hash of the sweep, the point's index, values
                                               and error (0: nothing written)
                done                           the point's values are written
    attrs       CF global attributes (Conventions, title, source, history, references),
                fivdisc_kind = "sweep", sweep_definition, sweep_hash (canonical JSON of the
                sweep and its SHA-256), sweep_mode, sweep_axes, sweep_shape,
                sweep_variables (the checksummed ones, in order), sweep_sections (JSON:
                every section's settings), fivdisc_version, store_format (format 3 is
                this layout without sections and sweep_sections; it is read as such)

Points are numbered in C order over the axes (the first axis varies slowest). Every data
variable has chunks of one point (a section's: all values of one point), so writing a
point touches only its own chunk files (each replaced atomically by Zarr's local
store). Values, ``error`` and ``checksum`` are written before ``done``. A point is
complete only if its ``done`` chunk says so and its values read back to its checksum:
Zarr reads a lost chunk file as the fill value, so without the checksum a deleted chunk
would pass for data.

One coordinator writes a store at a time: :func:`store_lock` holds a lock file next
to the store (``STORE.lock``, through ``filelock``) and records its holder in
``STORE.lock.owner``. A store is created complete (metadata and coordinates) under a
temporary name and renamed into place; temporary stores left by a killed coordinator
are removed by the next. A variable whose metadata is lost or damaged is rebuilt empty
when the sweep is resumed, and its points recomputed. fivdisc itself reads every
variable's own metadata, never the consolidated copy, so that damage is seen.
"""

from __future__ import annotations

import datetime
import hashlib
import json
import math
import os
import shutil
import socket
import struct
import sys
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from importlib.metadata import version
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from fivdisc.errors import SweepError
from fivdisc.files import write_atomic
from fivdisc.sweep.spec import Sweep

__all__ = [
    "PointOutcome",
    "StoreHealth",
    "SweepStore",
    "open_sweep",
    "read_mask",
    "store_lock",
    "verify_store",
]

DIM = "point"
#: Version of the layout above; stores of another version are refused.
STORE_FORMAT = 4
# Format 3 is format 4 without sections (and without the sweep_sections attribute).
_READABLE_FORMATS = (3, STORE_FORMAT)
_STRING = np.dtypes.StringDType()
_BRIEF_CHARS = 160


@dataclass(frozen=True)
class PointOutcome:
    """What one point produced.

    Attributes
    ----------
    index
        The point's index.
    values
        Stored name -> value of every kept reduction, and per section its values
        (``(max_points,)``, NaN padded) and their count; None if the point failed.
    error
        "" for success, else why the point failed.
    """

    index: int
    values: dict[str, Any] | None
    error: str = ""


def _require_zarr() -> Any:
    from fivdisc.extras import require

    require("distributed", "sweep stores")
    import zarr

    return zarr


def _open_group(path: Path) -> Any:
    """The store's Zarr group, read from every array's own metadata (not the consolidated
    copy, which would hide damaged or lost metadata)."""
    return _require_zarr().open_group(path, mode="r", use_consolidated=False)


def _consolidate(path: Path) -> None:
    """Write the consolidated metadata that lets ``xarray.open_zarr`` open the store at once.

    zarr warns that consolidated metadata is not part of the Zarr v3 specification; it is
    an extension zarr-python and xarray read, and fivdisc does not rely on it.
    """
    zarr = _require_zarr()
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Consolidated metadata", category=UserWarning)
        zarr.consolidate_metadata(str(path))


def dims_of(sweep: Sweep) -> tuple[str, ...]:
    """The store's dimensions: the axis keys of a grid sweep, ``("point",)`` for a zip."""
    return tuple(sweep.axes) if sweep.mode == "grid" else (DIM,)


def checksummed(sweep: Sweep) -> list[str]:
    """The variables a point's checksum covers, in order: the reductions, each section's
    values and count, then ``error``."""
    names = [r.name for r in sweep.reductions]
    for section in sweep.sections:
        names += [section.name, section.count_name]
    return [*names, "error"]


def _variable_dims(sweep: Sweep) -> dict[str, tuple[str, ...]]:
    """Dimensions of every data variable (the sweep's, and a section's own last)."""
    dims = dims_of(sweep)
    names = {name: dims for name in [*checksummed(sweep), "checksum", "done"]}
    names |= {s.name: (*dims, s.dim) for s in sweep.sections}
    return names


def _coordinate(values: Sequence[Any]) -> np.ndarray:
    """Axis values as an array: numbers, booleans or text as such, anything else as JSON."""
    if all(isinstance(v, bool) for v in values):
        return np.array(values, dtype=bool)
    if all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
        return np.array(values)
    if all(isinstance(v, str) for v in values):
        return np.array(values, dtype=_STRING)
    return np.array([json.dumps(v) for v in values], dtype=_STRING)


def _template(sweep: Sweep) -> xr.Dataset:
    """The empty store: coordinates filled, data variables lazy (only metadata is written)."""
    import dask.array as da

    from fivdisc.conventions import global_attrs, key_attrs

    dims, shape = dims_of(sweep), sweep.shape
    chunks = (1,) * len(shape)
    data = {
        r.name: (
            dims,
            da.full(shape, r.fill, dtype=r.dtype, chunks=chunks),
            {"units": r.units or "1", "long_name": r.long_name, "reduction": r.spec},
        )
        for r in sweep.reductions
    }
    for s in sweep.sections:
        data[s.name] = (
            (*dims, s.dim),
            da.full((*shape, s.max_points), np.nan, chunks=(*chunks, s.max_points)),
            s.attrs(),
        )
        data[s.count_name] = (dims, da.zeros(shape, dtype=np.int32, chunks=chunks),
                              s.count_attrs())
    data["error"] = (
        dims,
        da.from_array(np.full(shape, "", dtype=_STRING), chunks=chunks),
        {"long_name": 'why the point failed ("" if it did not)'},
    )
    data["checksum"] = (
        dims,
        da.zeros(shape, dtype=np.uint64, chunks=chunks),
        {"units": "1",
         "long_name": "hash of the sweep, the point's index, values and error (0: none)"},
    )
    data["done"] = (
        dims,
        da.zeros(shape, dtype=bool, chunks=chunks),
        {"units": "1", "long_name": "the point's values are written"},
    )
    if sweep.mode == "grid":
        coords = {key: (key, _coordinate(values), key_attrs(key))
                  for key, values in sweep.axes.items()}
    else:
        coords = {DIM: (DIM, np.arange(sweep.n_points), {"units": "1",
                                                           "long_name": "sweep point"})}
        coords |= {key: (DIM, _coordinate(values), key_attrs(key))
                   for key, values in sweep.axes.items()}
    keys = " and ".join(sweep.axes)
    attrs = {
        **global_attrs(f"fivdisc sweep over {keys} ({sweep.mode}, {sweep.n_points} points)",
                       "fivdisc.sweep.run_sweep"),
        "fivdisc_kind": "sweep",
        "sweep_definition": sweep.definition,
        "sweep_hash": sweep.digest,
        "sweep_mode": sweep.mode,
        "sweep_axes": json.dumps(list(sweep.axes)),
        "sweep_shape": json.dumps(list(shape)),
        "sweep_variables": json.dumps(checksummed(sweep)),
        "sweep_sections": json.dumps([s.to_dict() for s in sweep.sections]),
        "fivdisc_version": version("fivdisc"),
        "store_format": STORE_FORMAT,
    }
    dataset = xr.Dataset(data, coords=coords, attrs=attrs)
    if sweep.mode == "zip":
        # Name the axis coordinates on every data variable, so that a variable rebuilt
        # alone (see _repair) still carries them.
        for var in dataset.data_vars.values():
            var.encoding["coordinates"] = " ".join(sweep.axes)
    return dataset


def _brief(exc: BaseException) -> str:
    """An exception as one short line."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= _BRIEF_CHARS else text[: _BRIEF_CHARS - 3] + "..."


def _checksum(digest: str, index: int, row: Sequence[Any]) -> int:
    """Checksum of one point: the sweep's digest, the index and the stored values, in order.

    Never 0, the fill value of the ``checksum`` variable (nothing written).
    """
    h = hashlib.blake2b(f"{digest}:{index}".encode(), digest_size=8)
    for value in row:
        if isinstance(value, np.ndarray):  # a section's values: one NaN for every NaN
            token = np.where(np.isnan(value), np.nan, value).astype("<f8").tobytes()
        elif isinstance(value, bool | np.bool_):
            token = b"T" if value else b"F"
        elif isinstance(value, float | np.floating):
            token = b"nan" if math.isnan(value) else struct.pack("<d", float(value))
        else:
            token = str(value).encode()
        h.update(len(token).to_bytes(4, "little") + token)
    return int.from_bytes(h.digest(), "little") or 1


def _read_attrs(path: Path) -> dict[str, Any]:
    """The group attributes of a sweep store; SweepError if `path` is not one."""
    _require_zarr()
    if not path.is_dir():
        raise SweepError(f"{path} is not a sweep store: no such directory")
    if not (path / "zarr.json").is_file():
        raise SweepError(f"{path} exists and is not a Zarr store (it has no zarr.json)")
    try:
        attrs = dict(_open_group(path).attrs)
    except Exception as exc:  # zarr raises several types for damaged metadata
        raise SweepError(
            f"{path} has damaged metadata ({path / 'zarr.json'}: {_brief(exc)}); delete the "
            "store to start over"
        ) from None
    if "sweep_hash" not in attrs:
        raise SweepError(f"{path} exists and is not a fivdisc sweep store")
    if attrs.get("store_format") not in _READABLE_FORMATS:
        raise SweepError(
            f"{path} was written by another version of fivdisc (store format "
            f"{attrs.get('store_format', 1)}, this version writes {STORE_FORMAT}); write to "
            "a new store, or delete this one to start over"
        )
    return attrs


def _differences(stored: str, current: str) -> list[str]:
    """Top-level fields in which two sweep definitions differ."""
    old, new = json.loads(stored), json.loads(current)
    return [key for key in sorted(set(old) | set(new)) if old.get(key) != new.get(key)]


def _readable(array: Any, grid: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
    """(values, readable) of a Zarr array of one-point chunks over the sweep's `grid`,
    chunk by chunk if need be, one row per point in C order (the order of the sweep's
    points): values ``(n_points,)``, or ``(n_points, max_points)`` for a section's.

    A chunk cut short or damaged by a crash raises on decoding; Zarr's error types
    vary with the codec, hence the broad except. Unreadable points get the fill value.
    """
    n = math.prod(grid)
    rows = (n, *array.shape[len(grid):])
    try:
        return np.reshape(array[...], rows), np.ones(n, dtype=bool)
    except Exception:
        values = np.full(array.shape, array.fill_value, dtype=array.dtype)
        ok = np.zeros(tuple(grid), dtype=bool)
        for index in np.ndindex(*grid):
            try:
                values[index] = array[index]
                ok[index] = True
            except Exception:
                continue
        return values.reshape(rows), ok.ravel()


def _arrays(path: Path, shapes: dict[str, tuple[int, ...]]) -> tuple[dict[str, Any], list[str]]:
    """The store's arrays by name, and the names whose metadata is missing, damaged or of
    another shape than `shapes` gives."""
    group = _open_group(path)
    arrays: dict[str, Any] = {}
    broken: list[str] = []
    for name, shape in shapes.items():
        try:
            array = group[name]
            ok = array.shape == shape
        except Exception:  # missing directory (KeyError), damaged JSON, bad metadata
            ok = False
        if ok:
            arrays[name] = array
        else:
            broken.append(name)
    return arrays, broken


@dataclass(frozen=True)
class StoreHealth:
    """What :func:`verify_store` found.

    Attributes
    ----------
    path
        The store.
    complete
        Per point: its ``done`` flag is set and its values read back to its checksum.
    damaged
        Per point: marked done (or its ``done`` chunk is unreadable), but not complete.
    failed
        Complete points whose run failed (a non-empty ``error``).
    broken
        Variables whose metadata is missing or damaged.
    holder
        Who holds the store's lock (a sweep writing it), or None.
    """

    path: Path
    complete: np.ndarray
    damaged: np.ndarray
    failed: np.ndarray
    broken: tuple[str, ...]
    holder: str | None

    @property
    def healthy(self) -> bool:
        """No damaged point and no broken variable (points may still be missing)."""
        return not self.damaged.any() and not self.broken


def _layout(attrs: dict[str, Any]) -> tuple[list[str], dict[str, tuple[int, ...]]]:
    """(checksummed variables: see :func:`checksummed`; every variable -> its shape)."""
    variables = json.loads(attrs["sweep_variables"])
    keys = json.loads(attrs["sweep_axes"])
    shape = tuple(json.loads(attrs["sweep_shape"]))
    shapes = {name: shape for name in [*variables, "checksum", "done"]}
    for section in json.loads(attrs.get("sweep_sections", "[]")):
        shapes[section["name"]] = (*shape, section["max_points"])
    if attrs["sweep_mode"] == "grid":
        shapes |= {key: (length,) for key, length in zip(keys, shape, strict=True)}
    else:
        shapes |= {name: shape for name in [DIM, *keys]}
    return variables, shapes


def _inspect(path: Path, attrs: dict[str, Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                          list[str]]:
    """(complete, damaged, failed, broken variables) of a store; see :class:`StoreHealth`.
    The masks are flat, one entry per point."""
    variables, shapes = _layout(attrs)
    arrays, broken = _arrays(path, shapes)
    grid = shapes["done"]
    n = math.prod(grid)
    if "done" in arrays:
        done, done_readable = _readable(arrays["done"], grid)
        done = np.asarray(done, dtype=bool)
    else:
        done, done_readable = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
    readable = np.ones(n, dtype=bool)
    columns = {}
    for name in [*variables, "checksum"]:
        if name in arrays:
            columns[name], ok = _readable(arrays[name], grid)
            readable &= ok
        else:
            readable[:] = False
    complete = done & done_readable & readable
    for i in np.flatnonzero(complete):
        row = [columns[name][i] for name in variables]
        complete[i] = int(columns["checksum"][i]) == _checksum(attrs["sweep_hash"], int(i), row)
    damaged = ~complete & (done | ~done_readable)
    failed = complete & (columns["error"] != "") if "error" in columns else np.zeros(n, bool)
    return complete, damaged, failed, broken


def read_mask(path: str | PathLike[str]) -> np.ndarray:
    """Which points of a sweep store are complete.

    A point is complete when its ``done`` chunk reads True and its values and error
    read back to its checksum; damaged or lost chunks count as not done.

    Parameters
    ----------
    path
        The store.

    Returns
    -------
    ndarray of bool
        One entry per point.

    Raises
    ------
    SweepError
        `path` is not a sweep store of this version.
    """
    path = Path(path)
    return _inspect(path, _read_attrs(path))[0]


def verify_store(path: str | PathLike[str]) -> StoreHealth:
    """Check every point and variable of a sweep store, without changing it.

    Parameters
    ----------
    path
        The store.

    Returns
    -------
    StoreHealth
        Complete, damaged and failed points, broken variables and the lock's holder.

    Raises
    ------
    SweepError
        `path` is not a sweep store of this version, or its group metadata is damaged.
    """
    path = Path(path)
    complete, damaged, failed, broken = _inspect(path, _read_attrs(path))
    return StoreHealth(path, complete, damaged, failed, tuple(broken), _holder(path))


# --- the lock --------------------------------------------------------------------------------


def _lock_path(path: Path) -> Path:
    return path.with_name(path.name + ".lock")


def _owner_path(path: Path) -> Path:
    return path.with_name(path.name + ".lock.owner")


def _describe_owner(path: Path) -> str:
    """The lock holder recorded next to the store, as text."""
    try:
        owner = json.loads(_owner_path(path).read_text(encoding="utf-8"))
        return (f"process {owner['pid']} on host {owner['host']} (running since "
                f"{owner['since']}: {owner['command']})")
    except (OSError, ValueError, KeyError, TypeError):
        return "another process (it recorded no details)"


def _holder(path: Path) -> str | None:
    """Who holds the store's lock now, or None."""
    from filelock import FileLock, Timeout

    if not _lock_path(path).exists():
        return None
    lock = FileLock(_lock_path(path), timeout=0)
    try:
        lock.acquire()
    except Timeout:
        return _describe_owner(path)
    lock.release()
    return None


@contextmanager
def store_lock(path: str | PathLike[str]) -> Iterator[None]:
    """Hold the lock of a sweep store: one coordinator writes a store at a time.

    The lock is a file next to the store (``STORE.lock``, held through ``filelock``; the
    operating system releases it when its process dies, however it dies), and the holder's
    process id, host, start time and command are written to ``STORE.lock.owner``.

    Raises
    ------
    SweepError
        Another process holds the lock; the message names it.
    """
    from filelock import FileLock, Timeout

    path = Path(path)
    lock = FileLock(_lock_path(path), timeout=0)
    try:
        lock.acquire()
    except Timeout:
        raise SweepError(
            f"{path} is in use by {_describe_owner(path)}: wait for that sweep to end or "
            "stop it, then rerun"
        ) from None
    try:
        owner = {
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "since": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M:%S UTC"),
            "command": " ".join(sys.argv),
        }
        write_atomic(_owner_path(path), lambda p: p.write_text(json.dumps(owner),
                                                               encoding="utf-8"))
        yield
    finally:
        _owner_path(path).unlink(missing_ok=True)
        lock.release()


class SweepStore:
    """The Zarr store of one sweep, opened for writing results.

    Use :meth:`open`, which creates the store or checks that an existing one holds
    the same sweep.

    Attributes
    ----------
    path
        The store's directory.
    sweep
        The sweep it holds.
    """

    def __init__(self, path: Path, sweep: Sweep) -> None:
        self.path = path
        self.sweep = sweep

    @classmethod
    def open(cls, path: str | PathLike[str], sweep: Sweep) -> SweepStore:
        """Create the store for `sweep`, or reopen it to resume; hold :func:`store_lock`.

        Temporary stores left next to `path` by a killed coordinator are removed, and
        variables whose metadata is lost or damaged are rebuilt empty (their points are
        then incomplete and get recomputed).

        Raises
        ------
        SweepError
            `path` exists but is not a sweep store, or holds a different sweep.
        """
        path = Path(path)
        _require_zarr()
        for stale in path.parent.glob(f"{path.name}.tmp-*"):
            shutil.rmtree(stale, ignore_errors=True)
        if path.exists():
            attrs = _read_attrs(path)
            if attrs["sweep_hash"] != sweep.digest:
                fields = ", ".join(_differences(attrs["sweep_definition"], sweep.definition))
                raise SweepError(
                    f"{path} holds a different sweep (its definition differs in: {fields}); "
                    "write to a new store, or delete this one to start over"
                )
            _repair(path, sweep, _arrays(path, _layout(attrs)[1])[1], attrs)
        else:
            _create(path, sweep)
        return cls(path, sweep)

    def completed(self) -> np.ndarray:
        """Which points are complete (see :func:`read_mask`)."""
        return read_mask(self.path)

    def errors(self, points: np.ndarray) -> dict[int, str]:
        """Point index -> error message of the failed ones among `points`."""
        errors, _ = _readable(_open_group(self.path)["error"], self.sweep.shape)
        return {int(i): str(errors[i]) for i in np.flatnonzero(points) if errors[i]}

    def write(self, outcomes: Sequence[PointOutcome]) -> None:
        """Store finished points: values and errors first, then their ``done`` flags.

        Points with consecutive indices along the last axis are written by one region
        write each.
        """
        shape = self.sweep.shape
        outcomes = sorted(outcomes, key=lambda o: o.index)
        runs: list[list[PointOutcome]] = []
        for outcome in outcomes:
            # A run stays within one row of the last axis, so that it is a region.
            if (runs and runs[-1][-1].index + 1 == outcome.index
                    and outcome.index % shape[-1] != 0):
                runs[-1].append(outcome)
            else:
                runs.append([outcome])
        names = checksummed(self.sweep)
        for run in runs:
            data = {
                r.name: np.array([r.fill if o.values is None else o.values[r.name] for o in run],
                                 dtype=r.dtype)
                for r in self.sweep.reductions
            }
            for s in self.sweep.sections:
                data[s.name] = np.array(
                    [s.empty() if o.values is None else o.values[s.name] for o in run],
                    dtype=np.float64).reshape(len(run), s.max_points)
                data[s.count_name] = np.array(
                    [0 if o.values is None else o.values[s.count_name] for o in run],
                    dtype=np.int32)
            data["error"] = np.array([o.error for o in run], dtype=_STRING)
            data["checksum"] = np.array(
                [_checksum(self.sweep.digest, o.index, [data[name][j] for name in names])
                 for j, o in enumerate(run)],
                dtype=np.uint64,
            )
            self._write_region(data, run)
        for run in runs:
            self._write_region({"done": np.ones(len(run), dtype=bool)}, run)

    def _write_region(self, columns: dict[str, np.ndarray], run: list[PointOutcome]) -> None:
        """Write values of the consecutive points of `run`, all in one row of the last axis."""
        dims, shape = dims_of(self.sweep), self.sweep.shape
        first = np.unravel_index(run[0].index, shape)
        region = {dim: slice(int(i), int(i) + 1) for dim, i in zip(dims[:-1], first[:-1],
                                                                    strict=True)}
        region[dims[-1]] = slice(int(first[-1]), int(first[-1]) + len(run))
        block = (1,) * (len(dims) - 1) + (len(run),)
        # A section's own dimension is written whole (region names only the sweep's).
        own = _variable_dims(self.sweep)
        data = xr.Dataset({name: (own[name], values.reshape(block + values.shape[1:]))
                           for name, values in columns.items()})
        data.to_zarr(self.path, region=region, mode="r+", consolidated=False)


def _encoding(sweep: Sweep, names: Sequence[str]) -> dict[str, dict[str, Any]]:
    """Chunks of one point: one value, or a section's values of one point."""
    ndim = len(sweep.shape)
    lengths = {s.name: s.max_points for s in sweep.sections}
    return {name: {"chunks": (1,) * ndim + ((lengths[name],) if name in lengths else ())}
            for name in names}


def _create(path: Path, sweep: Sweep) -> None:
    """Write the empty store under a temporary name and rename it into place."""
    tmp = path.with_name(f"{path.name}.tmp-{os.getpid()}")
    template = _template(sweep)
    try:
        template.to_zarr(
            tmp, mode="w-", compute=False, consolidated=False, zarr_format=3,
            encoding=_encoding(sweep, list(template.data_vars)),
        )
        _consolidate(tmp)
        tmp.rename(path)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def _repair(path: Path, sweep: Sweep, broken: Sequence[str], attrs: dict[str, Any]) -> None:
    """Rebuild variables whose metadata is missing or damaged: coordinates from the sweep,
    data variables empty; the group keeps its attributes `attrs`."""
    if not broken:
        return
    template = _template(sweep)
    for name in broken:
        shutil.rmtree(path / name, ignore_errors=True)
    rebuilt = template[[n for n in broken if n in template.data_vars]]
    rebuilt = rebuilt.drop_vars([c for c in rebuilt.coords if c not in broken])
    for name in broken:
        if name in template.coords and name not in rebuilt:
            rebuilt[name] = template[name].variable
    rebuilt.attrs = attrs  # the group's, rewritten unchanged
    # Data variables are lazy, so only their metadata is written; coordinates are numpy
    # arrays, whose values compute=False writes too.
    rebuilt.to_zarr(
        path, mode="a", compute=False, consolidated=False, zarr_format=3,
        encoding=_encoding(sweep, [n for n in broken if n in template.data_vars]),
    )
    _consolidate(path)


def open_sweep(path: str | PathLike[str]) -> xr.Dataset:
    """Load a sweep store into memory: a grid sweep on its axes (one dimension per swept
    key, with the axis values, units and long_name), a zip sweep along ``point``.

    ``done`` is True only for verified points (see :func:`read_mask`); unreadable chunks
    read as their variable's fill value, and the values of points that are not done are
    not to be trusted.

    Raises
    ------
    SweepError
        `path` is not a sweep store, or a variable is missing or has damaged metadata
        (rerun the sweep to rebuild it and recompute its points).
    """
    path = Path(path)
    attrs = _read_attrs(path)
    complete, _, _, broken = _inspect(path, attrs)
    if broken:
        raise SweepError(
            f"{path} is damaged: variable(s) {', '.join(broken)} are missing or unreadable; "
            "rerun the sweep to rebuild them and recompute their points"
        )
    # chunks=None: lazily indexed arrays read by Zarr itself, not dask (whose default
    # scheduler may be a cluster client of this process). consolidated=False: each
    # variable's own metadata, as checked above.
    data = xr.open_zarr(path, consolidated=False, chunks=None)
    shapes = _layout(attrs)[1]
    for name in list(data.data_vars):
        try:
            data[name].load()
        except Exception:  # damaged chunks: the codec's error type varies
            values, _ = _readable(_arrays(path, {name: shapes[name]})[0][name],
                                  shapes["done"])
            data[name] = data[name].copy(data=values.reshape(shapes[name]))
    try:
        data = data.load()
    except Exception as exc:  # a damaged coordinate chunk
        raise SweepError(
            f"{path} has unreadable coordinates ({_brief(exc)}); rerun the sweep to rebuild them"
        ) from None
    data["done"] = data["done"].copy(data=complete.reshape(shapes["done"]))
    return data
