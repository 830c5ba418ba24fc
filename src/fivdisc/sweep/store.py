"""Sweep results in a Zarr store, written point by point, verified and safe to resume.

Layout (one Zarr v3 group, written through xarray, with consolidated metadata so that
``xarray.open_zarr`` opens it directly)::

    dims        <axis key>, ...                a grid sweep: one per axis, named after its
                                               key (e.g. speed.initial), in the sweep's order
                point                          a zip sweep: one entry per point
    coords      <axis key>                     the axis values, with units and long_name
                                               (JSON text if the values are not numbers,
                                               booleans or text); along point for a zip sweep
    data vars   <reduction name>               one per kept reduction (bool or float64),
                                               and its companions (largest_lyapunov's
                                               largest_lyapunov_inconclusive)
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
                every section's settings), fivdisc_version, store_format (5; formats 3
                and 4 are read and verified, not resumed: see below)

Points are numbered in C order over the axes (the first axis varies slowest). Every data
variable has chunks of a block of consecutive points (see :func:`_point_chunks`: up to
1024 points; a section's: all values of those points), so that a check opens one file
per block and variable, not per point. Writing points rewrites the chunks that hold them
(Zarr reads the rest of the chunk, and its local store replaces the file atomically), so
an interrupted write leaves every chunk old or new. Values, ``error`` and ``checksum``
are written before ``done``. A point is complete only if its ``done`` flag says so and
its values read back to its checksum: Zarr reads a lost chunk file as the fill value, so
without the checksum a deleted chunk would pass for data. A chunk that no longer decodes
is removed when the sweep is resumed (:meth:`SweepStore.completed`): its points are
recomputed, and Zarr could not write a point into it.

Formats 3 and 4 held one point per chunk (3: without sections and ``sweep_sections``);
they are read and verified, never repaired or written (a sweep writing into them would
mix two layouts): :meth:`SweepStore.open` opens them as they are, with a
:attr:`~SweepStore.refusal` that :meth:`SweepStore.write` and
:func:`~fivdisc.sweep.run_sweep` raise when a point is missing.

One coordinator writes a store at a time: :func:`store_lock` holds a lock file next
to the store (``STORE.lock``, next to where a symbolic link leads, through ``filelock``)
and records its holder in ``STORE.lock.owner``. A store is created complete (metadata
and coordinates) under a temporary name (recorded in ``STORE.lock.owner``) and renamed
into place; the next coordinator removes the temporary store of a killed one, and no
other file.

Everything about the layout (shape, variables, their types and chunks, the coordinates'
values, the group attributes that describe them) is derived from the sweep definition,
itself checked against its SHA-256 (``sweep_hash``, which every point's checksum covers):
:func:`verify_store` reports any difference. Resuming the sweep restores from the sweep
what differs: the group's metadata (if the store's coordinates and flags are the
sweep's), the metadata of an array (its chunk files are kept, and the points whose values
no longer read back to their checksums are recomputed), or a coordinate's values. fivdisc
itself reads every variable's own metadata, never the consolidated copy, so that damage
is seen.
"""

from __future__ import annotations

import contextlib
import datetime
import hashlib
import json
import math
import os
import shutil
import socket
import sys
import warnings
from collections.abc import Callable, Iterator, Sequence
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
from fivdisc.sweep.reductions import BUILTIN, stored
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
STORE_FORMAT = 5
# Formats 3 and 4 kept one point per chunk (3: without sections and the sweep_sections
# attribute); they are read and verified, not resumed.
_READABLE_FORMATS = (3, 4, STORE_FORMAT)
# A chunk holds up to this many points, and no more than _BLOCK_BYTES of a section's
# values: a store's check opens one file per chunk (a file open costs about as much as
# decoding a thousand values), a damaged chunk loses its points, and writing a point
# rewrites its chunks whole.
_BLOCK_POINTS = 1024
_BLOCK_BYTES = 1 << 20
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


def _open_array(path: Path, name: str) -> Any:
    """One array of the store, from its own metadata (readable when the group's is not)."""
    return _require_zarr().open_array(path / name, mode="r", zarr_format=3)


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


def _point_chunks(shape: Sequence[int], max_points: Sequence[int] = ()) -> tuple[int, ...]:
    """The chunk shape over a sweep's points: whole trailing axes while they fit in
    ``_BLOCK_POINTS`` points (fewer if a section's values, `max_points` per point, would
    exceed ``_BLOCK_BYTES``), then a slice of the next axis; so that a chunk is a run
    of consecutive points in C order, the order they are computed in."""
    room = min(_BLOCK_POINTS, max(1, _BLOCK_BYTES // (8 * max([1, *max_points]))))
    chunks = []
    for n in reversed(shape):
        chunks.append(max(1, min(n, room)))
        room = max(1, room // chunks[-1])
    return tuple(reversed(chunks))


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
    # One dask chunk per variable: only metadata is written (compute=False), and a graph
    # of one task per chunk costs seconds per 10,000 chunks; Zarr's chunks are set by
    # _encoding.
    chunks = shape
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
            da.full((*shape, s.max_points), np.nan, chunks=(*shape, s.max_points)),
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


def _framed(token: bytes) -> bytes:
    return len(token).to_bytes(4, "little") + token


_NAN = _framed(b"nan")
_BOOLS = np.array([_framed(b"F"), _framed(b"T")], dtype=object)


def _tokens(column: np.ndarray) -> list[bytes]:
    """What the checksum hashes of every value of a column, its length ahead (see
    :func:`_checksums`): a boolean as T or F, a float as its little-endian bytes (nan for
    NaN), a section's values as their little-endian bytes (one NaN for every NaN), anything
    else as its text."""
    n = len(column)
    if column.dtype == bool:
        return _BOOLS[column.astype(np.intp)].tolist()
    if column.dtype.kind == "f":
        values = column.reshape(n, -1)
        nan = np.isnan(values)
        size = 8 * values.shape[1]
        framed = np.empty((n, 4 + size), dtype=np.uint8)
        framed[:, :4] = np.frombuffer(size.to_bytes(4, "little"), dtype=np.uint8)
        framed[:, 4:] = np.where(nan, np.nan, values).astype("<f8").view(np.uint8)
        tokens = framed.view(f"V{4 + size}").ravel().tolist()
        if column.ndim == 1:  # a reduction's value: NaN as nan
            for i in np.flatnonzero(nan[:, 0]):
                tokens[i] = _NAN
        return tokens
    return [_framed(str(value).encode()) for value in column.tolist()]


def _checksums(digest: str, indices: Sequence[int], columns: Sequence[np.ndarray]
               ) -> np.ndarray:
    """Checksums of points: per point, the BLAKE2b (8 bytes) of the sweep's digest, its
    index and its stored values, in order (`columns`: one per checksummed variable, one
    row per point of `indices`).

    Never 0, the fill value of the ``checksum`` variable (nothing written). Computed a
    column at a time (the values' bytes in one NumPy operation), then one hash per point.
    """
    blake2b = hashlib.blake2b
    sums = np.empty(len(indices), dtype=np.uint64)
    for k, (index, *row) in enumerate(zip(indices, *map(_tokens, columns), strict=True)):
        head = f"{digest}:{index}".encode()
        sums[k] = int.from_bytes(blake2b(head + b"".join(row), digest_size=8).digest(),
                                 "little") or 1
    return sums


class _DamagedGroup(SweepError):
    """The group's own metadata (``STORE/zarr.json``) is unreadable or its sweep definition
    does not match its hash; a rerun of the sweep rebuilds it."""


def _read_attrs(path: Path) -> dict[str, Any]:
    """The group attributes of a sweep store; SweepError if `path` is not one.

    The sweep definition is checked against its SHA-256: everything else about the
    store's layout is derived from it (see :func:`_layout`)."""
    _require_zarr()
    if not path.is_dir():
        raise SweepError(f"{path} is not a sweep store: no such directory")
    if not (path / "zarr.json").is_file():
        raise SweepError(f"{path} exists and is not a Zarr store (it has no zarr.json)")
    rerun = ("rerun the sweep that wrote it to rebuild it from the sweep file, or delete "
             "the store to start over")
    try:
        attrs = dict(_open_group(path).attrs)
    except Exception as exc:  # zarr raises several types for damaged metadata
        raise _DamagedGroup(
            f"{path} has damaged metadata ({path / 'zarr.json'}: {_brief(exc)}); {rerun}"
        ) from None
    if "sweep_hash" not in attrs and attrs.get("fivdisc_kind") != "sweep":
        if not all((path / name / "zarr.json").is_file() for name in ("done", "checksum")):
            raise SweepError(f"{path} exists and is not a fivdisc sweep store")
        raise _DamagedGroup(  # a sweep store's arrays, its group's attributes lost
            f"{path} has damaged metadata ({path / 'zarr.json'}: no sweep attributes); {rerun}"
        )
    if attrs.get("store_format") not in _READABLE_FORMATS:
        raise SweepError(
            f"{path} was written by another version of fivdisc (store format "
            f"{attrs.get('store_format', 1)}, this version writes {STORE_FORMAT}); write to "
            "a new store, or delete this one to start over"
        )
    definition, digest = attrs.get("sweep_definition"), attrs.get("sweep_hash")
    if not (isinstance(definition, str) and isinstance(digest, str)
            and hashlib.sha256(definition.encode()).hexdigest() == digest):
        raise _DamagedGroup(
            f"{path} has damaged metadata ({path / 'zarr.json'}: its sweep_definition does "
            f"not match its sweep_hash); {rerun}"
        )
    return attrs


def _differences(stored: str, current: str) -> list[str]:
    """Top-level fields in which two sweep definitions differ."""
    old, new = json.loads(stored), json.loads(current)
    return [key for key in sorted(set(old) | set(new)) if old.get(key) != new.get(key)]


@dataclass(frozen=True)
class _Layout:
    """What a store holds, derived from its sweep definition alone.

    Attributes
    ----------
    variables
        The checksummed variables, in order (see :func:`checksummed`).
    arrays
        Every array (data variables and coordinates) -> (shape, chunk shape, dtype);
        dtype None for a coordinate.
    coords
        Every coordinate -> its values.
    attrs
        The group attributes that describe the layout -> their values (as JSON data).
    """

    variables: list[str]
    arrays: dict[str, tuple[tuple[int, ...], tuple[int, ...] | None, np.dtype | None]]
    coords: dict[str, np.ndarray]
    attrs: dict[str, Any]

    @property
    def grid(self) -> tuple[int, ...]:
        return self.arrays["done"][0]


def _layout(attrs: dict[str, Any]) -> _Layout:
    """The layout of a store, from its (hash-checked) sweep definition."""
    definition = json.loads(attrs["sweep_definition"])
    mode = definition["mode"]
    axes = {key: values for key, values in definition["axes"]}
    sections = definition.get("sections", [])
    shape = (tuple(len(v) for v in axes.values()) if mode == "grid"
             else (len(next(iter(axes.values()))),))
    names = {spec.partition(":")[2] or spec: spec for spec in stored(definition["keep"])}
    block = (_point_chunks(shape, [s["max_points"] for s in sections])
            if attrs.get("store_format") == STORE_FORMAT else (1,) * len(shape))
    arrays: dict[str, tuple[tuple[int, ...], tuple[int, ...] | None, np.dtype | None]] = {
        name: (shape, block, np.dtype(BUILTIN[spec].dtype if spec in BUILTIN else "float64"))
        for name, spec in names.items()
    }
    variables = list(names)
    for section in sections:
        name, points = section["name"], section["max_points"]
        arrays[name] = ((*shape, points), (*block, points), np.dtype("float64"))
        arrays[f"{name}_count"] = (shape, block, np.dtype("int32"))
        variables += [name, f"{name}_count"]
    variables.append("error")
    arrays |= {"error": (shape, block, _STRING), "checksum": (shape, block, np.dtype("uint64")),
               "done": (shape, block, np.dtype(bool))}
    if mode == "grid":
        coords = {key: _coordinate(values) for key, values in axes.items()}
    else:
        coords = {DIM: np.arange(shape[0])} | {k: _coordinate(v) for k, v in axes.items()}
    arrays |= {name: (values.shape, None, None) for name, values in coords.items()}
    layout_attrs = {
        "sweep_mode": mode,
        "sweep_axes": list(axes),
        "sweep_shape": list(shape),
        "sweep_variables": variables,
        "sweep_sections": sections,
    }
    return _Layout(variables, arrays, coords, layout_attrs)


def _attribute_damage(attrs: dict[str, Any], layout: _Layout) -> list[str]:
    """The group attributes describing the layout that do not match the sweep definition."""
    damaged = []
    for name, expected in layout.attrs.items():
        value = attrs.get(name, "[]" if name == "sweep_sections" else None)
        try:
            ok = (value if name == "sweep_mode" else json.loads(value)) == expected
        except (TypeError, ValueError):  # not JSON text
            ok = False
        if not ok:
            damaged.append(f"{name} (group attribute)")
    return damaged


def _arrays(path: Path, layout: _Layout) -> tuple[dict[str, Any], list[str]]:
    """The store's data arrays by name, and the names of the arrays (coordinates too) whose
    metadata is missing, damaged or not what the layout says, or whose coordinate values
    are not the sweep's."""
    arrays: dict[str, Any] = {}
    broken: list[str] = []
    for name, (shape, chunks, dtype) in layout.arrays.items():
        try:
            array = _open_array(path, name)
            ok = array.shape == shape
            if name in layout.coords:
                ok = ok and array[...].tolist() == layout.coords[name].tolist()
            else:
                ok = ok and array.chunks == chunks and array.dtype == dtype
        except Exception:  # missing (KeyError), damaged JSON or chunks: the type varies
            ok = False
        if ok and name not in layout.coords:
            arrays[name] = array
        elif not ok:
            broken.append(name)
    return arrays, broken


def _decoder(array: Any) -> Callable[[list[bytes]], np.ndarray] | None:
    """A decoder of chunk files of `array` (their bytes -> their values, one row per
    chunk), for the codecs fivdisc's stores use (a ``bytes`` or ``vlen-utf8`` codec, then
    optionally ``zstd``); None for any other. A chunk that does not decode to one chunk's
    values raises (ValueError or a codec's error)."""
    from numcodecs import VLenUTF8
    from numcodecs.zstd import decompress

    meta = array.metadata.to_dict()
    codecs = [(c["name"], c.get("configuration", {})) for c in meta["codecs"]]
    if meta["chunk_key_encoding"] != {"name": "default", "configuration": {"separator": "/"}}:
        return None
    if [name for name, _ in codecs[1:]] not in ([], ["zstd"]):
        return None
    unzip = decompress if len(codecs) == 2 else bytes
    kind, config = codecs[0]
    chunk = tuple(array.chunks)
    size = math.prod(chunk)
    if kind == "bytes" and array.dtype != _STRING:
        order = "<" if config.get("endian", "little") == "little" else ">"
        dtype = array.dtype.newbyteorder(order)
        nbytes = size * dtype.itemsize

        def numbers(raws: list[bytes]) -> np.ndarray:
            parts = [unzip(raw) for raw in raws]
            if any(len(part) != nbytes for part in parts):
                raise ValueError("a chunk of the wrong size")
            values = np.frombuffer(b"".join(parts), dtype=dtype).astype(array.dtype)
            return values.reshape(len(raws), *chunk)

        return numbers
    if kind == "vlen-utf8" and array.dtype == _STRING:
        text = VLenUTF8()

        def strings(raws: list[bytes]) -> np.ndarray:
            values = [text.decode(unzip(raw)) for raw in raws]
            if any(v.size != size for v in values):
                raise ValueError("a chunk of the wrong size")
            flat = np.concatenate(values) if values else np.empty(0, dtype=object)
            return np.asarray(flat, dtype=_STRING).reshape(len(raws), *chunk)

        return strings
    return None


def _chunk_files(directory: str, depth: int) -> list[tuple[tuple[int, ...], str]]:
    """(chunk index, file) of every chunk file under an array's ``c`` directory (a
    directory in a file's place is listed too: it fails to read)."""
    level: list[tuple[tuple[int, ...], str]] = [((), directory)]
    for _ in range(depth):
        deeper = []
        for head, path in level:
            try:
                names = os.listdir(path)
            except OSError:  # no chunk written yet, or a file in a directory's place
                continue
            deeper += [((*head, int(name)), f"{path}/{name}") for name in names
                       if name.isdigit()]
        level = deeper
    return level


_READ = 1 << 16  # bytes per read: most chunks are smaller, larger ones are read on


def _read(file: str) -> bytes | None:
    """The bytes of a chunk file (b"" if it cannot be read), None if it is gone.

    Through the operating system's calls: a third of the cost of a Python file object for
    the files of a few bytes a store is made of."""
    try:
        fd = os.open(file, os.O_RDONLY)
    except FileNotFoundError:
        return None
    except OSError:
        return b""
    try:
        parts = [os.read(fd, _READ)]
        while len(parts[-1]) == _READ:
            parts.append(os.read(fd, _READ))
        return b"".join(parts)
    except OSError:
        return b""
    finally:
        os.close(fd)


def _decode_distinct(decode: Callable[[list[bytes]], np.ndarray], raws: list[bytes]
                     ) -> tuple[np.ndarray, np.ndarray]:
    """(rows, index) of chunk files' bytes: every distinct content decoded once (in a
    store of one point per chunk, a flag, an empty error or a repeated value is the same
    few bytes at every point), and per
    chunk the row of its values in `rows`, -1 for a chunk that does not decode."""
    distinct = dict.fromkeys(raws)
    contents = list(distinct)
    try:
        rows = decode(contents)
        valid = np.ones(len(contents), dtype=bool)
    except Exception:  # one chunk or more is damaged: find which (the type varies)
        decoded, valid = [], np.zeros(len(contents), dtype=bool)
        for k, raw in enumerate(contents):
            try:
                decoded.append(decode([raw]))
                valid[k] = True
            except Exception:
                pass
        rows = np.concatenate(decoded) if decoded else np.empty(0)
    code = np.full(len(contents), -1, dtype=np.intp)
    code[valid] = np.arange(int(valid.sum()))
    for k, raw in enumerate(contents):
        distinct[raw] = code[k]
    return rows, np.array([distinct[raw] for raw in raws], dtype=np.intp)


def _blocks(mask: np.ndarray, grid: Sequence[int], block: Sequence[int]) -> np.ndarray:
    """Per chunk of shape `block` over `grid` (C order), whether any point of `mask` (flat,
    one entry per point) lies in it."""
    counts = [-(-n // b) for n, b in zip(grid, block, strict=True)]
    padded = np.zeros([c * b for c, b in zip(counts, block, strict=True)], dtype=bool)
    padded[tuple(slice(0, n) for n in grid)] = mask.reshape(grid)
    split = padded.reshape([x for cb in zip(counts, block, strict=True) for x in cb])
    return split.any(axis=tuple(range(1, 2 * len(grid), 2))).ravel()


def _points(per_chunk: np.ndarray, grid: Sequence[int], block: Sequence[int]) -> np.ndarray:
    """Per point (flat, C order), the entry of its chunk: `per_chunk` has one row per
    chunk of shape `block` over `grid` (C order), the chunk's values in that row's
    leading ``block`` axes (anything after them is kept)."""
    counts = [-(-n // b) for n, b in zip(grid, block, strict=True)]
    k = len(grid)
    tail = per_chunk.shape[1 + k:]
    spread = per_chunk.reshape(*counts, *block, *tail)
    # (c0, ..., b0, ...) -> (c0, b0, c1, b1, ...): the padded grid in C order
    order = [x for pair in zip(range(k), range(k, 2 * k), strict=True) for x in pair]
    padded = spread.transpose(*order, *range(2 * k, 2 * k + len(tail)))
    padded = padded.reshape(*[c * b for c, b in zip(counts, block, strict=True)], *tail)
    return padded[tuple(slice(0, n) for n in grid)].reshape(math.prod(grid), *tail)


def _readable(array: Any, grid: Sequence[int], points: np.ndarray | None = None,
              undecodable: list[str] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(values, readable) of a Zarr array over the sweep's `grid` (chunked by blocks of
    points, see :func:`_point_chunks`, or one point per chunk in formats 3 and 4), one row
    per point in C order (the order of the sweep's points): values ``(n_points,)``, or
    ``(n_points, max_points)`` for a section's. Only the chunks holding a point flagged
    in `points` (default: all) are read; the other points get the fill value. The chunk
    files that do not decode are appended to `undecodable`.

    Chunk files are listed and decoded here rather than read through Zarr, which costs
    about half a millisecond per chunk (its store reads one file per asynchronous task,
    and a chunk never written costs as much): the checks of a 300 x 300 sweep of one
    point per chunk took over a minute (see ``benchmarks/bench_store.py``). Only the
    chunk files listed are opened, and each distinct content is decoded once. Arrays of
    other codecs are read through Zarr. A chunk cut short or damaged fails to decode (the
    error type varies with the codec, hence the broad excepts); its points are unreadable.
    """
    n = math.prod(grid)
    tail = array.shape[len(grid):]
    values = np.full((n, *tail), array.fill_value, dtype=array.dtype)
    ok = np.ones(n, dtype=bool)
    wanted = np.ones(n, dtype=bool) if points is None else points
    decode = _decoder(array)
    if decode is None:
        for i in np.flatnonzero(wanted):
            try:
                values[i] = array[np.unravel_index(i, grid)]
            except Exception:
                ok[i] = False
        return values, ok
    chunk = tuple(array.chunks)
    block = chunk[:len(grid)]
    counts = tuple(-(-g // b) for g, b in zip(grid, block, strict=True))
    directory = os.path.join(str(array.store_path.store.root), array.path, "c")
    listed = _chunk_files(directory, array.ndim)
    chunks = np.array([c for c, _ in listed], dtype=np.int64).reshape(-1, array.ndim)
    # Chunks of this array's shape only (a section's values: one chunk along its own axis).
    own = (chunks[:, len(grid):] == 0).all(axis=1) & (chunks[:, :len(grid)] < counts).all(axis=1)
    at = np.flatnonzero(own)
    index = np.ravel_multi_index(tuple(chunks[at, :len(grid)].T), counts)
    # Every chunk is read when the undecodable ones are sought (they are removed before
    # a resumed sweep writes into them).
    keep = (np.ones(len(index), dtype=bool) if undecodable is not None
            else _blocks(wanted, grid, block)[index])
    found, files, raws = [], [], []
    for i, k in zip(index[keep].tolist(), at[keep].tolist(), strict=True):
        raw = _read(listed[k][1])
        if raw is not None:  # None: removed since listed, read as the fill value
            found.append(i)
            files.append(listed[k][1])
            raws.append(raw)
    rows, row = _decode_distinct(decode, raws)
    found = np.array(found, dtype=np.intp)
    good = row >= 0
    if undecodable is not None:
        undecodable += [file for file, g in zip(files, good.tolist(), strict=True) if not g]
    per_chunk = np.full((math.prod(counts), *chunk), array.fill_value, dtype=array.dtype)
    if good.any():
        per_chunk[found[good]] = rows[row[good]]
    readable = np.ones(math.prod(counts), dtype=bool)
    readable[found[~good]] = False
    values[wanted] = _points(per_chunk, grid, block)[wanted]
    ok = _points(np.broadcast_to(readable.reshape(-1, *(1,) * len(block)),
                                 (len(readable), *block)), grid, block).copy()
    return values, ok


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
        Variables and coordinates whose metadata is missing or damaged, coordinates whose
        values are not the sweep's, and group attributes that do not match the sweep
        definition (named ``NAME (group attribute)``).
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


def _inspect(path: Path, attrs: dict[str, Any], undecodable: list[str] | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str]]:
    """(complete, damaged, failed, broken variables) of a store; see :class:`StoreHealth`.
    The masks are flat, one entry per point. The chunk files that do not decode are
    appended to `undecodable`."""
    layout = _layout(attrs)
    arrays, broken = _arrays(path, layout)
    broken += _attribute_damage(attrs, layout)
    grid = layout.grid
    n = math.prod(grid)
    if "done" in arrays:
        done, done_readable = _readable(arrays["done"], grid, None, undecodable)
        done = np.asarray(done, dtype=bool)
    else:
        done, done_readable = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
    # Only the values of points marked done matter: the others are incomplete anyway.
    readable = np.ones(n, dtype=bool)
    columns = {}
    for name in [*layout.variables, "checksum"]:
        if name in arrays:
            columns[name], ok = _readable(arrays[name], grid, done & done_readable,
                                          undecodable)
            readable &= ok
        else:
            readable[:] = False
    complete = done & done_readable & readable
    points = np.flatnonzero(complete)
    if points.size:  # every variable readable
        complete[points] = columns["checksum"][points] == _checksums(
            attrs["sweep_hash"], points.tolist(),
            [columns[name][points] for name in layout.variables])
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


def _temporary(path: Path, pid: int) -> Path:
    """Where the coordinator of process `pid` creates the store before renaming it into
    place; recorded in the lock's owner record, so that only it is ever removed."""
    return path.with_name(f"{path.name}.tmp-fivdisc-{pid}")


def _owner(path: Path) -> dict[str, Any] | None:
    """The lock holder's record next to the store, or None if there is none or it is damaged."""
    try:
        owner = json.loads(_owner_path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return owner if isinstance(owner, dict) else None


def _describe_owner(path: Path) -> str:
    """The lock holder recorded next to the store, as text."""
    try:
        owner = _owner(path) or {}
        return (f"process {owner['pid']} on host {owner['host']} (running since "
                f"{owner['since']}: {owner['command']})")
    except (KeyError, TypeError):
        return "another process (it recorded no details)"


def _remove_stale_temporary(path: Path) -> None:
    """Remove the temporary store a dead holder of the lock recorded, and nothing else.

    Called with the lock held: an owner record still there belongs to a holder that
    died (a live holder keeps the lock); the name is checked against the one its
    process id gives, so that a damaged record cannot point elsewhere."""
    owner = _owner(path)
    if owner is None or not isinstance(owner.get("pid"), int):
        return
    stale = _temporary(path, owner["pid"])
    if owner.get("temporary") == stale.name and stale.is_dir() and not stale.is_symlink():
        shutil.rmtree(stale, ignore_errors=True)


def _holder(path: Path) -> str | None:
    """Who holds the store's lock now, or None."""
    from filelock import FileLock, Timeout

    path = path.resolve()
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

    The lock is a file next to the store, where a symbolic link to it leads
    (``STORE.lock``, held through ``filelock``; the operating system releases it when its
    process dies, however it dies), and the holder's process id, host, start time,
    command and temporary store (:meth:`SweepStore.open` creates a store under that name)
    are written to ``STORE.lock.owner``. A temporary store recorded there by a holder
    that died is removed.

    Raises
    ------
    SweepError
        Another process holds the lock; the message names it.
    """
    from filelock import FileLock, Timeout

    given, path = Path(path), Path(path).resolve()
    lock = FileLock(_lock_path(path), timeout=0)
    try:
        lock.acquire()
    except Timeout:
        raise SweepError(
            f"{given} is in use by {_describe_owner(path)}: wait for that sweep to end or "
            "stop it, then rerun"
        ) from None
    try:
        _remove_stale_temporary(path)
        owner = {
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "since": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M:%S UTC"),
            "command": " ".join(sys.argv),
            "temporary": _temporary(path, os.getpid()).name,
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
    refusal
        Why points cannot be written into it, in one line ("" if they can): a store of
        an earlier format is read, not written.
    """

    def __init__(self, path: Path, sweep: Sweep, refusal: str = "") -> None:
        self.path = path
        self.sweep = sweep
        self.refusal = refusal

    @classmethod
    def open(cls, path: str | PathLike[str], sweep: Sweep) -> SweepStore:
        """Create the store for `sweep`, or reopen it to resume; hold :func:`store_lock`.

        Variables whose metadata is lost or damaged are rebuilt empty (their points are
        then incomplete and get recomputed). A store of an earlier format (one point per
        chunk) is opened as it is, to be read: its :attr:`refusal` says why it is not
        written.

        Raises
        ------
        SweepError
            `path` exists but is not a sweep store, or holds a different sweep.
        """
        path = Path(path)
        _require_zarr()
        if not path.exists():
            _create(path, sweep)
            return cls(path, sweep)
        try:
            attrs = _read_attrs(path)
        except _DamagedGroup as exc:
            attrs = _rebuild_group(path, sweep, str(exc))
        if attrs["sweep_hash"] != sweep.digest:
            fields = ", ".join(_differences(attrs["sweep_definition"], sweep.definition))
            raise SweepError(
                f"{path} holds a different sweep (its definition differs in: {fields}); "
                "write to a new store, or delete this one to start over"
            )
        if attrs["store_format"] != STORE_FORMAT:
            # Repairing or writing it from this sweep's layout would mix two layouts.
            return cls(path, sweep, (
                f"{path} holds one point per chunk (store format {attrs['store_format']}); "
                f"this version reads it but resumes only stores of format {STORE_FORMAT}: "
                "rerun the sweep into a new store"))
        _repair(path, sweep, attrs)
        return cls(path, sweep)

    def completed(self) -> np.ndarray:
        """Which points are complete (see :func:`read_mask`). In a store that is written,
        chunk files that do not decode are removed: their points are not complete, and
        writing one of them again would read the rest of its chunk first."""
        undecodable: list[str] = []
        complete = _inspect(self.path, _read_attrs(self.path),
                            None if self.refusal else undecodable)[0]
        for file in undecodable:
            if os.path.isdir(file) and not os.path.islink(file):
                shutil.rmtree(file, ignore_errors=True)
            else:
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(file)
        return complete

    def errors(self, points: np.ndarray) -> dict[int, str]:
        """Point index -> error message of the failed ones among `points`."""
        errors, _ = _readable(_open_array(self.path, "error"), self.sweep.shape, points)
        return {int(i): str(errors[i]) for i in np.flatnonzero(points) if errors[i]}

    def write(self, outcomes: Sequence[PointOutcome]) -> None:
        """Store finished points: values and errors first, then their ``done`` flags.

        Points with consecutive indices along the last axis are written by one region
        write each.

        Raises
        ------
        SweepError
            The store is not written (see :attr:`refusal`).
        """
        if self.refusal:
            raise SweepError(self.refusal)
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
            data["checksum"] = _checksums(self.sweep.digest, [o.index for o in run],
                                          [data[name] for name in names])
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
    """Chunks of a block of points (see :func:`_point_chunks`): their values, or a
    section's values of those points."""
    lengths = {s.name: s.max_points for s in sweep.sections}
    block = _point_chunks(sweep.shape, list(lengths.values()))
    return {name: {"chunks": block + ((lengths[name],) if name in lengths else ())}
            for name in names}


def _create(path: Path, sweep: Sweep) -> None:
    """Write the empty store under the temporary name :func:`store_lock` records, and
    rename it into place (where a symbolic link `path` leads)."""
    path = path.resolve()
    tmp = _temporary(path, os.getpid())
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


def _template_files(sweep: Sweep) -> dict[str, bytes]:
    """The files of the empty store of `sweep` (metadata, and the coordinates' values), by
    path in the store, as :func:`_create` writes them."""
    zarr = _require_zarr()
    files: dict[str, Any] = {}
    template = _template(sweep)
    template.to_zarr(
        zarr.storage.MemoryStore(files), mode="w-", compute=False, consolidated=False,
        zarr_format=3, encoding=_encoding(sweep, list(template.data_vars)),
    )
    return {key: buffer.to_bytes() for key, buffer in files.items()}


# Array metadata a rerun restores from the sweep if it differs (the codecs are left: chunks
# written with other codecs fail to decode, and their points are recomputed).
_STRUCTURE = ("shape", "data_type", "chunk_grid", "chunk_key_encoding", "fill_value",
              "dimension_names", "node_type")


def _structure(text: bytes | None) -> dict[str, Any] | None:
    try:
        meta = json.loads(text or b"")
    except ValueError:
        return None
    return {key: meta.get(key) for key in _STRUCTURE} if isinstance(meta, dict) else None


def _write_files(path: Path, files: dict[str, bytes], names: Sequence[str]) -> None:
    """Write the template's files of the arrays `names` (and of the group, for "") into
    the store, each atomically, leaving the arrays' other chunk files as they are."""
    for key, content in files.items():
        head = key.rpartition("/")[0].split("/c/")[0].removesuffix("/c")
        if head in names:
            target = path / key
            target.parent.mkdir(parents=True, exist_ok=True)
            write_atomic(target, lambda p, c=content: p.write_bytes(c))


def _rebuild_group(path: Path, sweep: Sweep, damage: str) -> dict[str, Any]:
    """Rebuild the group's metadata of a store from `sweep`, if the store's coordinates and
    point flags are those of `sweep` (the points then verify by their checksums, which
    cover the sweep's hash); one line saying what to delete if not. Returns the rebuilt
    attributes."""
    files = _template_files(sweep)
    attrs = json.loads(files["zarr.json"])["attributes"]
    layout = _layout(attrs)
    _, broken = _arrays(path, layout)
    foreign = [name for name in broken if name in layout.coords or name in ("done", "checksum")]
    if foreign:
        raise SweepError(
            f"{damage.split('; ')[0]}, and it cannot be rebuilt from this sweep: its "
            f"{', '.join(foreign)} are not this sweep's; delete {path} to start over"
        )
    _write_files(path, files, [""])
    _consolidate(path)
    return attrs


def _repair(path: Path, sweep: Sweep, attrs: dict[str, Any]) -> None:
    """Restore from `sweep` what a rerun can: the metadata of arrays whose metadata is
    missing, damaged or not the sweep's (their chunk files are kept; points whose values
    do not read back to their checksums are recomputed), coordinates whose values are
    not the sweep's, and group attributes that do not match the sweep's definition."""
    layout = _layout(attrs)
    _, broken = _arrays(path, layout)
    group = bool(_attribute_damage(attrs, layout))
    files = _template_files(sweep)
    for name in layout.arrays:
        meta = path / name / "zarr.json"
        stored = meta.read_bytes() if meta.is_file() else None
        if name not in broken and _structure(stored) != _structure(files[f"{name}/zarr.json"]):
            broken.append(name)
    if not broken and not group:
        return
    for name in broken:
        if name in layout.coords:  # its values are rewritten whole
            shutil.rmtree(path / name, ignore_errors=True)
    _write_files(path, files, [*broken, ""] if group else broken)
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
    # chunks=None: lazily indexed arrays, replaced by the values read here (quicker than
    # through Zarr, see _readable). consolidated=False: each variable's own metadata, as
    # checked above.
    data = xr.open_zarr(path, consolidated=False, chunks=None)
    layout = _layout(attrs)
    arrays, _ = _arrays(path, layout)
    for name in [n for n in data.data_vars if n in arrays]:
        values, _ = _readable(arrays[name], layout.grid)
        data[name] = data[name].copy(data=values.reshape(layout.arrays[name][0]))
    data = data.load()
    data["done"] = data["done"].copy(data=complete.reshape(layout.grid))
    return data
