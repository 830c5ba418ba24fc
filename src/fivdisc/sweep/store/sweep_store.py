"""Sweep results in a Zarr store, written point by point, verified and safe to resume.

The layout, its checks and repairs are in the modules beside this one; the format is
described in the documentation's page "Sweep files" (section "What a sweep
writes")."""

from __future__ import annotations

import contextlib
import os
import shutil
from collections.abc import Sequence
from os import PathLike
from pathlib import Path

import numpy as np
import xarray as xr

from fivdisc.errors import SweepError
from fivdisc.sweep.point import PointOutcome
from fivdisc.sweep.spec import Sweep
from fivdisc.sweep.store.checksum import checksummed, checksums
from fivdisc.sweep.store.chunks import readable_points
from fivdisc.sweep.store.health import (
    StoreHealth,
    inspect_store,
    open_arrays,
    read_mask,
    rebuild_group,
    repair,
    verify_store,
)
from fivdisc.sweep.store.layout import (
    STORE_FORMAT,
    STRING,
    DamagedGroup,
    create_store,
    differences,
    dims_of,
    layout_of,
    open_array,
    read_attrs,
    require_zarr,
    variable_dims,
)
from fivdisc.sweep.store.lock import store_lock

__all__ = [
    "PointOutcome",
    "StoreHealth",
    "SweepStore",
    "open_sweep",
    "read_mask",
    "store_lock",
    "verify_store",
]


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
        require_zarr()
        if not path.exists():
            create_store(path, sweep)
            return cls(path, sweep)
        try:
            attrs = read_attrs(path)
        except DamagedGroup as exc:
            attrs = rebuild_group(path, sweep, str(exc))
        if attrs["sweep_hash"] != sweep.digest:
            fields = ", ".join(differences(attrs["sweep_definition"], sweep.definition))
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
        repair(path, sweep, attrs)
        return cls(path, sweep)

    def completed(self) -> np.ndarray:
        """Which points are complete (see :func:`read_mask`). In a store that is written,
        chunk files that do not decode are removed: their points are not complete, and
        writing one of them again would read the rest of its chunk first."""
        undecodable: list[str] = []
        complete, *_, unflagged = inspect_store(self.path, read_attrs(self.path),
                                                None if self.refusal else undecodable)
        for file in undecodable:
            if os.path.isdir(file) and not os.path.islink(file):
                shutil.rmtree(file, ignore_errors=True)
            else:
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(file)
        if not self.refusal:
            # Points that verify by their checksums where their done flags were lost (a
            # deleted done/ or chunk of it): their flags are written again.
            lost = np.flatnonzero(unflagged)
            for run in self._runs([PointOutcome(int(i), None) for i in lost]):
                self._write_region({"done": np.ones(len(run), dtype=bool)}, run)
        return complete

    def errors(self, points: np.ndarray) -> dict[int, str]:
        """Point index -> error message of the failed ones among `points`."""
        errors, _ = readable_points(open_array(self.path, "error"), self.sweep.shape, points)
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
        runs = self._runs(outcomes)
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
            data["error"] = np.array([o.error for o in run], dtype=STRING)
            data["checksum"] = checksums(self.sweep.digest, [o.index for o in run],
                                          [data[name] for name in names])
            self._write_region(data, run)
        for run in runs:
            self._write_region({"done": np.ones(len(run), dtype=bool)}, run)

    def _runs(self, outcomes: Sequence[PointOutcome]) -> list[list[PointOutcome]]:
        """`outcomes` in runs of consecutive points, each within one row of the last axis
        (so that it is a region)."""
        shape = self.sweep.shape
        runs: list[list[PointOutcome]] = []
        for outcome in sorted(outcomes, key=lambda o: o.index):
            if (runs and runs[-1][-1].index + 1 == outcome.index
                    and outcome.index % shape[-1] != 0):
                runs[-1].append(outcome)
            else:
                runs.append([outcome])
        return runs

    def _write_region(self, columns: dict[str, np.ndarray], run: list[PointOutcome]) -> None:
        """Write values of the consecutive points of `run`, all in one row of the last axis."""
        dims, shape = dims_of(self.sweep), self.sweep.shape
        first = np.unravel_index(run[0].index, shape)
        region = {dim: slice(int(i), int(i) + 1) for dim, i in zip(dims[:-1], first[:-1],
                                                                    strict=True)}
        region[dims[-1]] = slice(int(first[-1]), int(first[-1]) + len(run))
        block = (1,) * (len(dims) - 1) + (len(run),)
        # A section's own dimension is written whole (region names only the sweep's).
        own = variable_dims(self.sweep)
        data = xr.Dataset({name: (own[name], values.reshape(block + values.shape[1:]))
                           for name, values in columns.items()})
        data.to_zarr(self.path, region=region, mode="r+", consolidated=False)


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
    attrs = read_attrs(path)
    complete, _, _, broken, _ = inspect_store(path, attrs)
    if broken:
        raise SweepError(
            f"{path} is damaged: variable(s) {', '.join(broken)} are missing or unreadable; "
            "rerun the sweep to rebuild them and recompute their points"
        )
    # chunks=None: lazily indexed arrays, replaced by the values read here (quicker than
    # through Zarr, see readable_points). consolidated=False: each variable's own metadata, as
    # checked above.
    data = xr.open_zarr(path, consolidated=False, chunks=None)
    layout = layout_of(attrs)
    arrays, _ = open_arrays(path, layout)
    for name in [n for n in data.data_vars if n in arrays]:
        values, _ = readable_points(arrays[name], layout.grid)
        data[name] = data[name].copy(data=values.reshape(layout.arrays[name][0]))
    data = data.load()
    data["done"] = data["done"].copy(data=complete.reshape(layout.grid))
    return data
