"""The health of a sweep store: what verifies, what is damaged, and the repairs a resumed
sweep makes from the sweep definition."""

from __future__ import annotations

import json
import math
import shutil
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from fivdisc.errors import SweepError
from fivdisc.sweep.spec import Sweep
from fivdisc.sweep.store.checksum import checksums
from fivdisc.sweep.store.chunks import readable_points, written_points
from fivdisc.sweep.store.layout import (
    CODECS,
    Layout,
    consolidate,
    layout_of,
    open_array,
    read_attrs,
    structure_of,
    template_files,
    write_files,
)
from fivdisc.sweep.store.lock import holder_of


def attribute_damage(attrs: dict[str, Any], layout: Layout) -> list[str]:
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


def open_arrays(path: Path, layout: Layout) -> tuple[dict[str, Any], list[str]]:
    """The store's data arrays by name, and the names of the arrays (coordinates too) whose
    metadata is missing, damaged or not what the layout says, or whose coordinate values
    are not the sweep's."""
    arrays: dict[str, Any] = {}
    broken: list[str] = []
    for name, (shape, chunks, dtype) in layout.arrays.items():
        try:
            array = open_array(path, name)
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
    unflagged
        Complete points whose ``done`` flag is lost (its chunk or the variable deleted):
        their values verify by their checksums, and a rerun writes the flags again.
    """

    path: Path
    complete: np.ndarray
    damaged: np.ndarray
    failed: np.ndarray
    broken: tuple[str, ...]
    holder: str | None
    unflagged: np.ndarray | None = None

    @property
    def healthy(self) -> bool:
        """No damaged point, no broken variable and no lost flag (points may still be
        missing)."""
        return (not self.damaged.any() and not self.broken
                and (self.unflagged is None or not self.unflagged.any()))


def inspect_store(path: Path, attrs: dict[str, Any], undecodable: list[str] | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str], np.ndarray]:
    """(complete, damaged, failed, broken variables, unflagged) of a store; see
    :class:`StoreHealth`. The masks are flat, one entry per point. The chunk files that
    do not decode are appended to `undecodable`."""
    layout = layout_of(attrs)
    arrays, broken = open_arrays(path, layout)
    broken += attribute_damage(attrs, layout)
    grid = layout.grid
    n = math.prod(grid)
    if "done" in arrays:
        done, done_readable = readable_points(arrays["done"], grid, None, undecodable)
        done = np.asarray(done, dtype=bool)
        flagged = written_points(arrays["done"], grid) & done_readable
    else:
        done, done_readable = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
        flagged = np.zeros(n, dtype=bool)
    # A point's flag is read where its chunk of `done` is there and decodes; where that
    # chunk is lost (or `done` itself), a point whose checksum was written is a
    # candidate too: its values verify by the checksum alone, which covers them all.
    # Otherwise only the values of points marked done matter: the others are incomplete.
    if "checksum" in arrays:
        sums, sums_ok = readable_points(arrays["checksum"], grid, ~flagged, undecodable)
        candidates = (done & flagged) | (~flagged & sums_ok & (sums != 0))
    else:
        candidates = done & flagged
    readable = np.ones(n, dtype=bool)
    columns = {}
    for name in [*layout.variables, "checksum"]:
        if name in arrays:
            columns[name], ok = readable_points(arrays[name], grid, candidates, undecodable)
            readable &= ok
        else:
            readable[:] = False
    complete = candidates & readable
    points = np.flatnonzero(complete)
    if points.size:  # every variable readable
        complete[points] = columns["checksum"][points] == checksums(
            attrs["sweep_hash"], points.tolist(),
            [columns[name][points] for name in layout.variables])
    damaged = ~complete & ((done & flagged) | ~done_readable)
    failed = complete & (columns["error"] != "") if "error" in columns else np.zeros(n, bool)
    return complete, damaged, failed, broken, complete & ~(done & flagged)


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
    return inspect_store(path, read_attrs(path))[0]


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
    complete, damaged, failed, broken, unflagged = inspect_store(path, read_attrs(path))
    return StoreHealth(path, complete, damaged, failed, tuple(broken), holder_of(path),
                       unflagged)


def rebuild_group(path: Path, sweep: Sweep, damage: str) -> dict[str, Any]:
    """Rebuild the group's metadata of a store from `sweep`, if the store's coordinates and
    point flags are those of `sweep` (the points then verify by their checksums, which
    cover the sweep's hash); one line saying what to delete if not. Returns the rebuilt
    attributes."""
    files = template_files(sweep)
    attrs = json.loads(files["zarr.json"])["attributes"]
    layout = layout_of(attrs)
    _, broken = open_arrays(path, layout)
    # Arrays that are there and are not the sweep's (a missing one is rebuilt by repair;
    # the points then verify by their checksums or are recomputed).
    foreign = [name for name in broken if (name in layout.coords or name in ("done", "checksum"))
               and (path / name / "zarr.json").is_file()]
    if foreign:
        raise SweepError(
            f"{damage.split('; ')[0]}, and it cannot be rebuilt from this sweep: its "
            f"{', '.join(foreign)} are not this sweep's; delete {path} to start over"
        )
    write_files(path, files, [""])
    consolidate(path)
    return attrs


def repair(path: Path, sweep: Sweep, attrs: dict[str, Any]) -> None:
    """Restore from `sweep` what a rerun can: the metadata of arrays whose metadata is
    missing, damaged or not the sweep's (their chunk files are kept; points whose values
    do not read back to their checksums are recomputed), coordinates whose values are
    not the sweep's, and group attributes that do not match the sweep's definition."""
    layout = layout_of(attrs)
    _, broken = open_arrays(path, layout)
    group = bool(attribute_damage(attrs, layout))
    files = template_files(sweep)
    coded = []  # arrays whose codecs alone differ from the sweep's
    for name in layout.arrays:
        meta = path / name / "zarr.json"
        stored = meta.read_bytes() if meta.is_file() else None
        expected = files[f"{name}/zarr.json"]
        if name not in broken and structure_of(stored) != structure_of(expected):
            broken.append(name)
        elif name not in broken and (structure_of(stored, CODECS)
                                     != structure_of(expected, CODECS)):
            coded.append(name)
    if coded:
        _restore_codecs(path, attrs, files, coded)
    if not broken and not group:
        if coded:
            consolidate(path)
        return
    for name in broken:
        if name in layout.coords:  # its values are rewritten whole
            shutil.rmtree(path / name, ignore_errors=True)
    write_files(path, files, [*broken, ""] if group else broken)
    consolidate(path)


def _restore_codecs(path: Path, attrs: dict[str, Any], files: dict[str, bytes],
                    names: list[str]) -> None:
    """Give the arrays `names` the sweep's codecs if more points verify with them than
    with the codecs their metadata names (a changed codec makes every chunk undecodable;
    chunks written by another version of Zarr may need the stored ones)."""
    kept = {name: (path / name / "zarr.json").read_bytes() for name in names}
    before = int(inspect_store(path, attrs)[0].sum())
    write_files(path, files, names)
    if int(inspect_store(path, attrs)[0].sum()) < before:
        for name, content in kept.items():
            write_files(path, {f"{name}/zarr.json": content}, [name])
