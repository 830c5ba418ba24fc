"""The layout of a sweep store: dimensions, variables, chunks and group attributes, all
derived from the sweep definition, and the files that make a new or rebuilt store.

The format is described in the documentation's page "Sweep files" (section "What a
sweep writes")."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from importlib.metadata import version
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from fivdisc.errors import SweepError
from fivdisc.files import write_atomic
from fivdisc.sweep.reductions import BUILTIN, stored
from fivdisc.sweep.spec import Sweep
from fivdisc.sweep.store.checksum import checksummed
from fivdisc.sweep.store.lock import temporary_path

DIM = "point"
#: Version of the layout above; stores of another version are refused.
STORE_FORMAT = 5
# Formats 3 and 4 kept one point per chunk (3: without sections and the sweep_sections
# attribute); they are read and verified, not resumed.
READABLE_FORMATS = (3, 4, STORE_FORMAT)
# A chunk holds up to this many points, and no more than BLOCK_BYTES of a section's
# values: a store's check opens one file per chunk (a file open costs about as much as
# decoding a thousand values), a damaged chunk loses its points, and writing a point
# rewrites its chunks whole.
BLOCK_POINTS = 1024
BLOCK_BYTES = 1 << 20
STRING = np.dtypes.StringDType()
_BRIEF_CHARS = 160


def require_zarr() -> Any:
    from fivdisc.extras import require

    require("distributed", "sweep stores")
    import zarr

    return zarr


def open_group(path: Path) -> Any:
    """The store's Zarr group, read from every array's own metadata (not the consolidated
    copy, which would hide damaged or lost metadata)."""
    return require_zarr().open_group(path, mode="r", use_consolidated=False)


def open_array(path: Path, name: str) -> Any:
    """One array of the store, from its own metadata (readable when the group's is not)."""
    return require_zarr().open_array(path / name, mode="r", zarr_format=3)


def consolidate(path: Path) -> None:
    """Write the consolidated metadata that lets ``xarray.open_zarr`` open the store at once.

    zarr warns that consolidated metadata is not part of the Zarr v3 specification; it is
    an extension zarr-python and xarray read, and fivdisc does not rely on it.
    """
    zarr = require_zarr()
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Consolidated metadata", category=UserWarning)
        zarr.consolidate_metadata(str(path))


def dims_of(sweep: Sweep) -> tuple[str, ...]:
    """The store's dimensions: the axis keys of a grid sweep, ``("point",)`` for a zip."""
    return tuple(sweep.axes) if sweep.mode == "grid" else (DIM,)


def point_chunks(shape: Sequence[int], max_points: Sequence[int] = ()) -> tuple[int, ...]:
    """The chunk shape over a sweep's points: whole trailing axes while they fit in
    ``BLOCK_POINTS`` points (fewer if a section's values, `max_points` per point, would
    exceed ``BLOCK_BYTES``), then a slice of the next axis; so that a chunk is a run
    of consecutive points in C order, the order they are computed in."""
    room = min(BLOCK_POINTS, max(1, BLOCK_BYTES // (8 * max([1, *max_points]))))
    chunks = []
    for n in reversed(shape):
        chunks.append(max(1, min(n, room)))
        room = max(1, room // chunks[-1])
    return tuple(reversed(chunks))


def variable_dims(sweep: Sweep) -> dict[str, tuple[str, ...]]:
    """Dimensions of every data variable (the sweep's, and a section's own last)."""
    dims = dims_of(sweep)
    names = {name: dims for name in [*checksummed(sweep), "checksum", "done"]}
    names |= {s.name: (*dims, s.dim) for s in sweep.sections}
    return names


def coordinate_values(values: Sequence[Any]) -> np.ndarray:
    """Axis values as an array: numbers, booleans or text as such, anything else as JSON."""
    if all(isinstance(v, bool) for v in values):
        return np.array(values, dtype=bool)
    if all(isinstance(v, int | float) and not isinstance(v, bool) for v in values):
        return np.array(values)
    if all(isinstance(v, str) for v in values):
        return np.array(values, dtype=STRING)
    return np.array([json.dumps(v) for v in values], dtype=STRING)


def dataset_template(sweep: Sweep) -> xr.Dataset:
    """The empty store: coordinates filled, data variables lazy (only metadata is written)."""
    import dask.array as da

    from fivdisc.engine.conventions import global_attrs, key_attrs

    dims, shape = dims_of(sweep), sweep.shape
    # One dask chunk per variable: only metadata is written (compute=False), and a graph
    # of one task per chunk costs seconds per 10,000 chunks; Zarr's chunks are set by
    # encoding_of.
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
        da.from_array(np.full(shape, "", dtype=STRING), chunks=chunks),
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
        coords = {key: (key, coordinate_values(values), key_attrs(key))
                  for key, values in sweep.axes.items()}
    else:
        coords = {DIM: (DIM, np.arange(sweep.n_points), {"units": "1",
                                                           "long_name": "sweep point"})}
        coords |= {key: (DIM, coordinate_values(values), key_attrs(key))
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
        # alone (see repair) still carries them.
        for var in dataset.data_vars.values():
            var.encoding["coordinates"] = " ".join(sweep.axes)
    return dataset


class DamagedGroup(SweepError):
    """The group's own metadata (``STORE/zarr.json``) is unreadable or its sweep definition
    does not match its hash; a rerun of the sweep rebuilds it."""


def read_attrs(path: Path) -> dict[str, Any]:
    """The group attributes of a sweep store; SweepError if `path` is not one.

    The sweep definition is checked against its SHA-256: everything else about the
    store's layout is derived from it (see :func:`layout_of`)."""
    require_zarr()
    if not path.is_dir():
        raise SweepError(f"{path} is not a sweep store: no such directory")
    rerun = ("rerun the sweep that wrote it to rebuild it from the sweep file, or delete "
             "the store to start over")
    if not (path / "zarr.json").is_file():
        if any((path / name / "zarr.json").is_file() for name in ("done", "checksum")):
            raise DamagedGroup(  # a sweep store's arrays, its group's metadata lost
                f"{path} has damaged metadata ({path / 'zarr.json'} is missing); {rerun}")
        raise SweepError(f"{path} exists and is not a Zarr store (it has no zarr.json)")
    try:
        attrs = dict(open_group(path).attrs)
    except Exception as exc:  # zarr raises several types for damaged metadata
        raise DamagedGroup(
            f"{path} has damaged metadata ({path / 'zarr.json'}: {brief(exc)}); {rerun}"
        ) from None
    if "sweep_hash" not in attrs and attrs.get("fivdisc_kind") != "sweep":
        if not all((path / name / "zarr.json").is_file() for name in ("done", "checksum")):
            raise SweepError(f"{path} exists and is not a fivdisc sweep store")
        raise DamagedGroup(  # a sweep store's arrays, its group's attributes lost
            f"{path} has damaged metadata ({path / 'zarr.json'}: no sweep attributes); {rerun}"
        )
    if attrs.get("store_format") not in READABLE_FORMATS:
        raise SweepError(
            f"{path} was written by another version of fivdisc (store format "
            f"{attrs.get('store_format', 1)}, this version writes {STORE_FORMAT}); write to "
            "a new store, or delete this one to start over"
        )
    definition, digest = attrs.get("sweep_definition"), attrs.get("sweep_hash")
    if not (isinstance(definition, str) and isinstance(digest, str)
            and hashlib.sha256(definition.encode()).hexdigest() == digest):
        raise DamagedGroup(
            f"{path} has damaged metadata ({path / 'zarr.json'}: its sweep_definition does "
            f"not match its sweep_hash); {rerun}"
        )
    return attrs


def differences(stored: str, current: str) -> list[str]:
    """Top-level fields in which two sweep definitions differ."""
    old, new = json.loads(stored), json.loads(current)
    return [key for key in sorted(set(old) | set(new)) if old.get(key) != new.get(key)]


@dataclass(frozen=True)
class Layout:
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


def layout_of(attrs: dict[str, Any]) -> Layout:
    """The layout of a store, from its (hash-checked) sweep definition."""
    definition = json.loads(attrs["sweep_definition"])
    mode = definition["mode"]
    axes = {key: values for key, values in definition["axes"]}
    sections = definition.get("sections", [])
    shape = (tuple(len(v) for v in axes.values()) if mode == "grid"
             else (len(next(iter(axes.values()))),))
    names = {spec.partition(":")[2] or spec: spec for spec in stored(definition["keep"])}
    block = (point_chunks(shape, [s["max_points"] for s in sections])
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
    arrays |= {"error": (shape, block, STRING), "checksum": (shape, block, np.dtype("uint64")),
               "done": (shape, block, np.dtype(bool))}
    if mode == "grid":
        coords = {key: coordinate_values(values) for key, values in axes.items()}
    else:
        coords = {DIM: np.arange(shape[0])} | {k: coordinate_values(v) for k, v in axes.items()}
    arrays |= {name: (values.shape, None, None) for name, values in coords.items()}
    layout_attrs = {
        "sweep_mode": mode,
        "sweep_axes": list(axes),
        "sweep_shape": list(shape),
        "sweep_variables": variables,
        "sweep_sections": sections,
    }
    return Layout(variables, arrays, coords, layout_attrs)


def encoding_of(sweep: Sweep, names: Sequence[str]) -> dict[str, dict[str, Any]]:
    """Chunks of a block of points (see :func:`point_chunks`): their values, or a
    section's values of those points."""
    lengths = {s.name: s.max_points for s in sweep.sections}
    block = point_chunks(sweep.shape, list(lengths.values()))
    return {name: {"chunks": block + ((lengths[name],) if name in lengths else ())}
            for name in names}


def create_store(path: Path, sweep: Sweep) -> None:
    """Write the empty store under the temporary name :func:`store_lock` records, and
    rename it into place (where a symbolic link `path` leads)."""
    path = path.resolve()
    tmp = temporary_path(path, os.getpid())
    template = dataset_template(sweep)
    try:
        template.to_zarr(
            tmp, mode="w-", compute=False, consolidated=False, zarr_format=3,
            encoding=encoding_of(sweep, list(template.data_vars)),
        )
        consolidate(tmp)
        tmp.rename(path)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def template_files(sweep: Sweep) -> dict[str, bytes]:
    """The files of the empty store of `sweep` (metadata, and the coordinates' values), by
    path in the store, as :func:`create_store` writes them."""
    zarr = require_zarr()
    files: dict[str, Any] = {}
    template = dataset_template(sweep)
    template.to_zarr(
        zarr.storage.MemoryStore(files), mode="w-", compute=False, consolidated=False,
        zarr_format=3, encoding=encoding_of(sweep, list(template.data_vars)),
    )
    return {key: buffer.to_bytes() for key, buffer in files.items()}


# Array metadata a rerun restores from the sweep if it differs. The codecs are restored
# only where the sweep's verify more points than the stored ones (see health.repair):
# chunks written by another version of Zarr may use other codecs, and decode only with
# those.
STRUCTURE = ("shape", "data_type", "chunk_grid", "chunk_key_encoding", "fill_value",
              "dimension_names", "node_type")
CODECS = ("codecs",)


def structure_of(text: bytes | None, keys: Sequence[str] = STRUCTURE
                 ) -> dict[str, Any] | None:
    """The entries `keys` of an array's metadata (its ``zarr.json``), None if it is not
    a JSON object."""
    try:
        meta = json.loads(text or b"")
    except ValueError:
        return None
    return {key: meta.get(key) for key in keys} if isinstance(meta, dict) else None


def write_files(path: Path, files: dict[str, bytes], names: Sequence[str]) -> None:
    """Write the template's files of the arrays `names` (and of the group, for "") into
    the store, each atomically, leaving the arrays' other chunk files as they are."""
    for key, content in files.items():
        head = key.rpartition("/")[0].split("/c/")[0].removesuffix("/c")
        if head in names:
            target = path / key
            target.parent.mkdir(parents=True, exist_ok=True)
            write_atomic(target, lambda p, c=content: p.write_bytes(c))


def brief(exc: BaseException) -> str:
    """An exception as one short line."""
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= _BRIEF_CHARS else text[: _BRIEF_CHARS - 3] + "..."

