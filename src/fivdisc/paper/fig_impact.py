"""Fig. 28 of the paper: impact."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from fivdisc.paper import measure as ms
from fivdisc.paper.cases import PaperCase
from fivdisc.paper.rows import printed_text, separation_text, suptitle_of, verdict_of
from fivdisc.paper.runs import Row, Runs, pack, unpack

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def impact_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    packed = {}
    amplitude = {}
    table = []
    for label, case in pc.runs.items():
        ds = runs.get(case)
        bad = runs.printed(case)
        packed[label], packed[f"{label}_printed"] = ds, bad
        sep = ms.separation(ds)
        after = ds["time"].values >= (sep["first"] if sep["count"] else 0.0)
        w = ds["w"].values[after, 0]
        amplitude[label] = (float(np.max(np.abs(w))), float(np.sqrt(np.mean(w**2))))
        what = "with impact" if case.simulation.impact else "without impact"
        table.append(Row(pc.figure, f"{label} ({what}): separation", "happens",
                         separation_text(ds), printed_text(bad), verdict_of(sep["count"] > 0)))
    (max_a, rms_a), (max_b, rms_b) = amplitude["a"], amplitude["b"]
    table.append(Row(pc.figure, "w at (r0, 0) after the first separation: max |w|, RMS, "
                     "with vs without impact", "much weaker with impact",
                     f"max {max_a:.2e} vs {max_b:.2e} m (x{max_b / max_a:.2f}); RMS {rms_a:.2e} "
                     f"vs {rms_b:.2e} m (x{rms_b / rms_a:.2f})",
                     verdict=verdict_of(max_b > 1.5 * max_a, partly=max_b > max_a)))
    return pack(pc, packed, ("w",)), table


def impact_plot(data: xr.Dataset) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.plots.result import plot_timeseries

    fig = Figure(figsize=(11, 7), layout="constrained")
    axes = fig.subplots(2, 2)
    for i, label in enumerate(("a", "b")):
        run = unpack(data, label)
        plot_timeseries(run, "w", probe=0, ax=axes[0, i])
        axes[0, i].set_ylabel("w at (r0, 0) [m]")
        axes[0, i].set_title(f"({label}) {'with' if i == 0 else 'without'} impact, fivdisc",
                             fontsize="medium")
        bad = unpack(data, f"{label}_printed")
        ax = axes[1, i]
        # Drawn until the displacement leaves the model's range (it grows without bound).
        w = bad["w"].values[:, 0]
        out = np.flatnonzero(~(np.abs(w) <= ms.DIVERGED))
        end = out[0] + 1 if out.size else w.size
        ax.plot(bad["time"].values[:end], w[:end], lw=0.8)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("w at (r0, 0) [m]")
        ax.set_title(f"({label}) {'with' if i == 0 else 'without'} impact, printed "
                     f"gyroscopic sign: {ms.run_end(bad)[1]}", fontsize="small")
    suptitle_of(fig, data)
    return fig
