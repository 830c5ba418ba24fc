"""Sweep results in a Zarr store, written point by point and safe to resume.

Layout (one Zarr v3 group, written through xarray)::

    dims        point                          one per sweep point, C order over the axes
    coords      point                          index
                <axis key>, e.g. speed.initial axis value at each point (JSON text if
                                               the values are not numbers, booleans or text)
    data vars   <reduction name>               one per kept reduction (bool or float64)
                error                          "" or why the point failed
                done                           the point's values are written
    attrs       sweep_definition, sweep_hash   canonical JSON of the sweep and its SHA-256
                sweep_mode, sweep_axes, sweep_shape, sweep_variables, fivdisc_version

Every data variable has chunks of one point, so writing a point touches only its
own chunk files (each replaced atomically by Zarr's local store). Values and
``error`` are written before ``done``; a point counts as complete only if its
``done`` chunk says so and every one of its chunks can be read. A store is created
complete (metadata and coordinates) under a temporary name and renamed into place.
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Sequence
from dataclasses import dataclass
from importlib.metadata import version
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from fivdisc.case import unit_of
from fivdisc.sweep.reductions import SweepError
from fivdisc.sweep.spec import Sweep, strides_of

__all__ = ["PointOutcome", "SweepStore", "as_grid", "open_sweep", "read_mask"]

DIM = "point"
_STRING = np.dtypes.StringDType()


@dataclass(frozen=True)
class PointOutcome:
    """What one point produced.

    Attributes
    ----------
    index
        The point's index.
    values
        Stored name -> value of every kept reduction; None if the point failed.
    error
        "" for success, else why the point failed.
    """

    index: int
    values: dict[str, bool | float] | None
    error: str = ""


def _require_zarr() -> Any:
    try:
        import dask.array  # noqa: F401  (the empty store's template is lazy)
        import zarr
    except ImportError as exc:
        raise SweepError(
            f"sweep stores need zarr and dask ({exc}); install them with "
            "`pip install fivdisc[distributed]`"
        ) from None
    return zarr


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

    n = sweep.n_points
    data = {
        r.name: (
            DIM,
            da.full(n, r.fill, dtype=r.dtype, chunks=1),
            {"units": r.units, "long_name": r.long_name, "reduction": r.spec},
        )
        for r in sweep.reductions
    }
    data["error"] = (
        DIM,
        da.from_array(np.full(n, "", dtype=_STRING), chunks=1),
        {"long_name": 'why the point failed ("" if it did not)'},
    )
    data["done"] = (
        DIM,
        da.zeros(n, dtype=bool, chunks=1),
        {"long_name": "the point's values are written"},
    )
    updates = [sweep.updates(i) for i in range(n)]
    coords = {DIM: (DIM, np.arange(n), {"long_name": "sweep point (C order over the axes)"})}
    for key in sweep.axes:
        attrs = {"long_name": f"case key {key}"}
        if unit := unit_of(key):
            attrs["units"] = unit
        coords[key] = (DIM, _coordinate([u[key] for u in updates]), attrs)
    attrs = {
        "title": "fivdisc sweep",
        "sweep_definition": sweep.definition,
        "sweep_hash": sweep.digest,
        "sweep_mode": sweep.mode,
        "sweep_axes": json.dumps(list(sweep.axes)),
        "sweep_shape": json.dumps(list(sweep.shape)),
        "sweep_variables": json.dumps([*(r.name for r in sweep.reductions), "error"]),
        "fivdisc_version": version("fivdisc"),
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _read_attrs(path: Path) -> dict[str, Any]:
    """The group attributes of a sweep store; SweepError if `path` is not one."""
    zarr = _require_zarr()
    try:
        attrs = dict(zarr.open_group(path, mode="r").attrs)
    except Exception as exc:  # zarr raises several types for "not a group here"
        raise SweepError(f"{path} exists and is not a Zarr store ({exc})") from None
    if "sweep_hash" not in attrs:
        raise SweepError(f"{path} exists and is not a fivdisc sweep store")
    return attrs


def _differences(stored: str, current: str) -> list[str]:
    """Top-level fields in which two sweep definitions differ."""
    old, new = json.loads(stored), json.loads(current)
    return [key for key in sorted(set(old) | set(new)) if old.get(key) != new.get(key)]


def _readable(array: Any) -> tuple[np.ndarray, np.ndarray]:
    """(values, readable) of a one-dimensional Zarr array, chunk by chunk if need be.

    A chunk cut short or damaged by a crash raises on decoding; Zarr's error types
    vary with the codec, hence the broad except. Unreadable points get the fill value.
    """
    try:
        return array[:], np.ones(array.shape, dtype=bool)
    except Exception:
        values = np.full(array.shape, array.fill_value, dtype=array.dtype)
        ok = np.zeros(array.shape, dtype=bool)
        for i in range(array.shape[0]):
            try:
                values[i] = array[i]
                ok[i] = True
            except Exception:
                continue
        return values, ok


def read_mask(path: str | PathLike[str]) -> np.ndarray:
    """Which points of a sweep store are complete.

    A point is complete when its ``done`` chunk reads True and every chunk of its
    values and error can be read; damaged chunks count as not done.

    Parameters
    ----------
    path
        The store.

    Returns
    -------
    ndarray of bool
        One entry per point.
    """
    path = Path(path)
    attrs = _read_attrs(path)
    group = _require_zarr().open_group(path, mode="r")
    done, readable = _readable(group["done"])
    mask = np.asarray(done, dtype=bool) & readable
    for name in json.loads(attrs["sweep_variables"]):
        mask &= _readable(group[name])[1]
    return mask


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
        """Create the store for `sweep`, or reopen it to resume.

        Raises
        ------
        SweepError
            `path` exists but is not a sweep store, or holds a different sweep.
        """
        path = Path(path)
        _require_zarr()
        if path.exists():
            attrs = _read_attrs(path)
            if attrs["sweep_hash"] != sweep.digest:
                fields = ", ".join(_differences(attrs["sweep_definition"], sweep.definition))
                raise SweepError(
                    f"{path} holds a different sweep (its definition differs in: {fields}); "
                    "write to a new store, or delete this one to start over"
                )
        else:
            _create(path, sweep)
        return cls(path, sweep)

    def completed(self) -> np.ndarray:
        """Which points are complete (see :func:`read_mask`)."""
        return read_mask(self.path)

    def errors(self, points: np.ndarray) -> dict[int, str]:
        """Point index -> error message of the failed ones among `points`."""
        group = _require_zarr().open_group(self.path, mode="r")
        errors, _ = _readable(group["error"])
        return {int(i): str(errors[i]) for i in np.flatnonzero(points) if errors[i]}

    def write(self, outcomes: Sequence[PointOutcome]) -> None:
        """Store finished points: values and errors first, then their ``done`` flags.

        Points with consecutive indices are written by one region write each.
        """
        outcomes = sorted(outcomes, key=lambda o: o.index)
        runs: list[list[PointOutcome]] = []
        for outcome in outcomes:
            if runs and runs[-1][-1].index + 1 == outcome.index:
                runs[-1].append(outcome)
            else:
                runs.append([outcome])
        for run in runs:
            data = {
                r.name: (
                    DIM,
                    np.array(
                        [r.fill if o.values is None else o.values[r.name] for o in run],
                        dtype=r.dtype,
                    ),
                )
                for r in self.sweep.reductions
            }
            data["error"] = (DIM, np.array([o.error for o in run], dtype=_STRING))
            self._write_region(xr.Dataset(data), run)
        for run in runs:
            self._write_region(xr.Dataset({"done": (DIM, np.ones(len(run), dtype=bool))}), run)

    def _write_region(self, data: xr.Dataset, run: list[PointOutcome]) -> None:
        region = {DIM: slice(run[0].index, run[-1].index + 1)}
        data.to_zarr(self.path, region=region, mode="r+", consolidated=False)


def _create(path: Path, sweep: Sweep) -> None:
    """Write the empty store under a temporary name and rename it into place."""
    tmp = path.with_name(f"{path.name}.tmp-{os.getpid()}")
    encoding = {
        name: {"chunks": (1,)} for name in (*(r.name for r in sweep.reductions), "error", "done")
    }
    try:
        _template(sweep).to_zarr(
            tmp, mode="w-", compute=False, consolidated=False, zarr_format=3, encoding=encoding
        )
        tmp.rename(path)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def open_sweep(path: str | PathLike[str]) -> xr.Dataset:
    """Load a sweep store into memory, one entry per point.

    Raises
    ------
    SweepError
        `path` is not a sweep store, or some chunk cannot be read (rerun the sweep
        to recompute the damaged points).
    """
    path = Path(path)
    _read_attrs(path)
    try:
        return xr.open_zarr(path, consolidated=False).load()
    except Exception as exc:  # damaged chunks: the codec's error type varies
        raise SweepError(
            f"{path} has unreadable chunks ({exc}); rerun the sweep to recompute them"
        ) from None


def as_grid(data: xr.Dataset) -> xr.Dataset:
    """A grid sweep's dataset with its points laid out on the axes.

    Parameters
    ----------
    data
        A grid sweep as returned by :func:`open_sweep`.

    Returns
    -------
    xarray.Dataset
        Every variable along ``point`` is reshaped to the axes' dimensions, named
        by the axis keys and indexed by the axis values.

    Raises
    ------
    SweepError
        The sweep is not a grid.
    """
    if data.attrs.get("sweep_mode") != "grid":
        raise SweepError(
            f"sweep_mode = {data.attrs.get('sweep_mode')!r} is invalid for as_grid: must be 'grid'"
        )
    keys = json.loads(data.attrs["sweep_axes"])
    shape = tuple(json.loads(data.attrs["sweep_shape"]))
    # The axis values along each dimension are those of the points where the other
    # axes are at their first value, i.e. strides through the C-ordered points.
    strides = strides_of(shape)
    coords = {
        key: (key, data[key].values[: stride * length : stride], data[key].attrs)
        for key, length, stride in zip(keys, shape, strides, strict=True)
    }
    variables = {
        name: (keys, var.values.reshape(shape), var.attrs)
        for name, var in data.data_vars.items()
        if var.dims == (DIM,)
    }
    return xr.Dataset(variables, coords=coords, attrs=data.attrs)
