"""Fig. 27 of the paper: the separation region."""

from __future__ import annotations

import tempfile
from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from fivdisc.paper.cases import PaperCase
from fivdisc.paper.rows import suptitle_of, verdict_of
from fivdisc.paper.runs import Row, Runs

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def separation_grid(pc: PaperCase, directory: str | PathLike[str], printed: bool,
                    workers: int | None = None, progress: bool = False) -> xr.Dataset:
    """Run (or resume) the separation sweep of Fig. 27, stored as Zarr in `directory`.

    Parameters
    ----------
    pc
        Fig. 27's parameters.
    directory
        Where the sweep's store goes, named after the sweep's digest so that a changed
        grid or case gets a store of its own; a complete store is reused.
    printed
        Use the printed paper's gyroscopic sign.
    workers
        Processes of the sweep's pool (default: the number of CPUs).
    progress
        Show the sweep's progress bar.

    Returns
    -------
    xarray.Dataset
        The sweep (:func:`fivdisc.sweep.open_sweep`) without its checksums:
        ``separated``, ``first_separation_time`` [s], ``error`` and ``done`` on
        (``speed.initial`` [rad/s], ``speed.duration`` [s]).
    """
    from fivdisc.sweep import open_sweep, run_sweep, separation_sweep

    base = pc.case.replace({"simulation.printed_gyroscopic_sign": printed})
    (_, xs), (_, ys) = pc.axes
    sweep = separation_sweep("decelerating", x=list(xs), y=list(ys), base=base)
    name = "printed" if printed else "skew"
    store = Path(directory) / f"fig27_{name}_{sweep.digest[:12]}.zarr"
    run_sweep(sweep, store, workers=workers, progress=progress)
    grid = open_sweep(store).drop_vars("checksum")
    # netCDF has no numpy StringDType: the messages as Python strings.
    grid["error"] = grid["error"].astype(object)
    grid.attrs["case_name"] = f"{pc.stem} ({name} gyroscopic sign)"
    return grid


def _map_text(grid: xr.Dataset) -> tuple[str, bool]:
    """Where a separation grid separates, and whether more speed and longer stops only add."""
    grid = grid.transpose("speed.initial", "speed.duration")
    sep = grid["separated"].values.astype(bool)
    xs, ys = grid["speed.initial"].values, grid["speed.duration"].values
    if not sep.any():
        return "no separation anywhere in the grid", False
    # Monotone: separation at (Omega_0, t_max) implies it at higher Omega_0 and longer t_max.
    up_x = np.all(~sep[:-1] | sep[1:])
    up_y = np.all(~sep[:, :-1] | sep[:, 1:])
    lowest = [f"{ys[j]:g} s: {xs[np.argmax(sep[:, j])]:g}" for j in range(ys.size)
              if sep[:, j].any()]
    text = (f"{sep.mean() * 100:.0f} % of the grid separates; lowest Omega_0 [rad/s] that "
            f"separates per t_max: {', '.join(lowest)}; region closed towards higher Omega_0: "
            f"{'yes' if up_x else 'no'}, towards longer t_max: {'yes' if up_y else 'no'}")
    return text, bool(up_x and up_y)


def sweep_compute(pc: PaperCase, runs: Runs) -> tuple[xr.DataTree, list[Row]]:
    grids = {}
    with tempfile.TemporaryDirectory() as tmp:
        for printed in (False, True):
            grids["printed" if printed else "skew"] = separation_grid(
                pc, runs.sweep_dir or tmp, printed, runs.sweep_workers, runs.progress)
    text, ok = _map_text(grids["skew"])
    text_bad, _ = _map_text(grids["printed"])
    failed = sum(int(np.sum(g["error"].values != "")) for g in grids.values())
    table = [Row(pc.figure, "separation region over (Omega_0, t_max)",
                 "more likely at high Omega_0 and long t_max", text, text_bad,
                 verdict_of(ok, partly=bool(grids["skew"]["separated"].values.any())))]
    if failed:
        table.append(Row(pc.figure, "failed sweep points", "", str(failed)))
    return xr.DataTree.from_dict(grids), table


def sweep_plot(data: xr.DataTree) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.plots.sweep import plot_separation_map

    fig = Figure(figsize=(11, 4.8), layout="constrained")
    for ax, key, title in zip(fig.subplots(1, 2), ("skew", "printed"),
                              ("fivdisc (skew gyroscopic terms)", "printed gyroscopic sign"),
                              strict=True):
        plot_separation_map(data[key].to_dataset(), ax=ax)
        ax.set_title(title, fontsize="medium")
    suptitle_of(fig, data)
    return fig


