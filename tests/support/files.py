"""Files as users handle them."""

from __future__ import annotations

from pathlib import Path


def through_xarray(path: Path, copy: Path) -> Path:
    """What a user does to look at a file and keep it: open it with xarray, write a copy."""
    import xarray as xr

    with xr.open_dataset(path) as ds:
        ds.load().to_netcdf(copy)
    return copy
