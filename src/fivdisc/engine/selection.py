"""Parts of a simulation dataset: what one slider saw.

Below :mod:`fivdisc.engine.result`, so that the analyses and plots of a dataset can select
from it without importing the result (and :meth:`fivdisc.Result.plot` can hand its
dataset to :mod:`fivdisc.plots`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["select_slider"]


def select_slider(ds: xr.Dataset, slider: int = 0) -> xr.Dataset:
    """The dataset as seen by one slider: per-slider variables at ``slider`` (the
    ``slider`` dimension dropped) and only that slider's events.

    Parameters
    ----------
    ds : xarray.Dataset
        A simulation dataset (a dataset without a ``slider`` dimension is returned as is).
    slider : int
        Slider index, from 0.

    Raises
    ------
    ValueError
        If ``slider`` is not an index of the dataset's sliders.
    """
    if "slider" not in ds.dims:
        return ds
    count = ds.sizes["slider"]
    if isinstance(slider, bool) or not isinstance(slider, int | np.integer) or not (
        0 <= slider < count
    ):
        raise ValueError(f"slider = {slider!r} is invalid: must be an index in [0, {count - 1}]"
                         f" (the run has {count} slider{'s' if count > 1 else ''})")
    out = ds.isel(slider=int(slider))
    if "event_slider" in ds and "event" in ds.dims:
        out = out.isel(event=np.flatnonzero(ds["event_slider"].values == slider))
    return out
