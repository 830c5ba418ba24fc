"""A run's variables as numpy arrays, before they become an :class:`xarray.Dataset`.

A simulation builds its result as a :class:`Record`: the data variables and coordinates
with their dimensions and attributes, and the run's attributes. The result's summary
reads it as it would the dataset, and ``fivdisc simulate`` writes it to netCDF without
importing xarray (with pandas and the array libraries xarray probes for, about a second
of processor time per process: more than the Fig. 10 run's integration). The dataset
is built on first use (:meth:`Record.to_xarray`), and the file :meth:`Record.to_netcdf`
writes is the one :meth:`xarray.Dataset.to_netcdf` writes for that dataset with its
default encoding, so that either reads back identical.
"""

from __future__ import annotations

from dataclasses import dataclass
from os import PathLike
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import xarray as xr


@dataclass(frozen=True)
class Column:
    """One variable of a :class:`Record`: what ``dataset[name]`` gives, without xarray.

    Attributes
    ----------
    dims : tuple of str
        Its dimensions.
    values : ndarray
        Its values.
    attrs : dict
        Its attributes (``units``, ``long_name``, ...).
    """

    dims: tuple[str, ...]
    values: np.ndarray
    attrs: dict[str, Any]


class Record:
    """Data variables and coordinates as :class:`Column` objects, and global attributes.

    It answers the few questions a result's summary asks of a dataset (``record[name]
    .values``, ``name in record``, ``record.sizes``, ``record.attrs``) the way
    :class:`xarray.Dataset` does.

    Parameters
    ----------
    data_vars, coords : dict
        Name -> (dims, values, attrs); a dimension's coordinate has that dimension's name.
    attrs : dict
        Global attributes.
    """

    def __init__(self, data_vars: dict[str, tuple], coords: dict[str, tuple],
                 attrs: dict[str, Any]) -> None:
        def columns(items: dict[str, tuple]) -> dict[str, Column]:
            out = {}
            for name, (dims, values, var_attrs) in items.items():
                dims = (dims,) if isinstance(dims, str) else tuple(dims)
                out[name] = Column(dims, np.asarray(values), dict(var_attrs))
            return out

        self.data_vars = columns(data_vars)
        self.coords = columns(coords)
        self.attrs = dict(attrs)

    def __getitem__(self, name: str) -> Column:
        return self.data_vars[name] if name in self.data_vars else self.coords[name]

    def __contains__(self, name: object) -> bool:
        return name in self.data_vars or name in self.coords

    @property
    def sizes(self) -> dict[str, int]:
        """Dimension name -> length."""
        out: dict[str, int] = {}
        for column in (*self.coords.values(), *self.data_vars.values()):
            out.update(zip(column.dims, column.values.shape, strict=True))
        return out

    def copy(self) -> Record:
        """The same record with its own global attributes (the arrays are shared)."""
        new = Record({}, {}, self.attrs)
        new.data_vars, new.coords = dict(self.data_vars), dict(self.coords)
        return new

    def to_xarray(self) -> xr.Dataset:
        """The record as an :class:`xarray.Dataset`."""
        import xarray as xr

        def variables(columns: dict[str, Column]) -> dict[str, xr.Variable]:
            return {name: xr.Variable(c.dims, c.values, attrs=c.attrs)
                    for name, c in columns.items()}

        return xr.Dataset(variables(self.data_vars), coords=variables(self.coords),
                          attrs=self.attrs)

    def to_netcdf(self, path: str | PathLike[str]) -> None:
        """Write the record as a netCDF-4 file, encoded as xarray encodes the dataset.

        Notes
        -----
        xarray's default encoding, which this follows (the tests compare the two files):
        floating-point variables get ``_FillValue = NaN``; text is stored as
        variable-length strings (an empty object array as doubles: fivdisc keeps its text in
        numpy string arrays, whose type xarray knows even when empty); a data variable's
        ``coordinates`` attribute names, sorted, the non-dimension coordinates whose
        dimensions it has, and any such coordinate no variable names goes in the global
        ``coordinates`` attribute.
        """
        import netCDF4

        non_dim = {name for name, c in self.coords.items() if c.dims != (name,)}
        named: set[str] = set()
        attributes: dict[str, dict[str, Any]] = {}
        for name, column in self.data_vars.items():
            mine = sorted(c for c in non_dim if set(self.coords[c].dims) <= set(column.dims))
            attributes[name] = {**column.attrs, **({"coordinates": " ".join(mine)} if mine
                                                   else {})}
            named.update(mine)
        unnamed = sorted(non_dim - named)
        with netCDF4.Dataset(path, "w", format="NETCDF4") as root:
            for dim, size in self.sizes.items():
                root.createDimension(dim, size)
            for name, column in (*self.data_vars.items(), *self.coords.items()):
                values = column.values
                if values.dtype.kind == "O" and values.size == 0:
                    # Without a value to infer text from, xarray stores doubles.
                    var = root.createVariable(name, np.float64, column.dims)
                elif values.dtype.kind in "OU":
                    var = root.createVariable(name, str, column.dims)
                    values = values.astype(object)
                else:
                    fill = np.nan if values.dtype.kind == "f" else None
                    var = root.createVariable(name, values.dtype, column.dims, fill_value=fill)
                for key, value in attributes.get(name, column.attrs).items():
                    _set_attribute(var, key, value)
                if values.size:
                    var[...] = values
            for key, value in self.attrs.items():
                _set_attribute(root, key, value)
            if unnamed:
                root.setncattr("coordinates", " ".join(unnamed))


def _set_attribute(target: Any, key: str, value: Any) -> None:
    """Set a netCDF attribute as xarray's netCDF4 backend does (lists of text as strings)."""
    if isinstance(value, list | tuple) and value and all(isinstance(v, str) for v in value):
        target.setncattr_string(key, value)
    else:
        target.setncattr(key, value)
