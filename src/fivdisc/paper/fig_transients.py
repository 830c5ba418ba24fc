"""Figs. 4-7 of the paper: decay to the equilibrium, and the variable-speed transients."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from fivdisc.analysis import linear_stability, sliding_equilibrium
from fivdisc.paper import measure as ms
from fivdisc.paper.cases import PaperCase
from fivdisc.paper.rows import (
    omega_dot_row,
    printed_row,
    separation_text,
    stability_row,
    suptitle_of,
    verdict_of,
)
from fivdisc.paper.runs import Row, Runs, pack, unpack

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def decay_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    ds = runs.get(pc.case)
    stab = linear_stability(pc.case)
    eq = sliding_equilibrium(pc.case)
    t = ds["time"].values
    dev = np.abs(ds["phi"].values - eq.phi[0])
    initial = float(dev[0])
    after = float(np.max(dev[(t >= 1.0) & (t <= 1.1)]))
    final = float(np.max(dev[t >= t[-1] - 0.5]))
    _, w_range = ms.envelope(ds, "w", 0, width=0.5)
    eigen = stab.to_dataframe()
    slowest = eigen[eigen["coordinate"] != "phi"].iloc[0]
    table = [
        stability_row(pc.figure, pc.case, "stable"),
        Row(pc.figure, "slider: decay of |phi - phi_eq|", "decays fast to the equilibrium",
            f"{initial:.1e} rad at t = 0, {after:.1e} rad at 1 s, {final:.1e} rad in the last "
            "0.5 s", verdict=verdict_of(after < 0.01 * initial)),
        Row(pc.figure, "disc at (r0, 0): decay of w",
            "decays fast to the equilibrium",
            f"peak-to-peak {w_range[0]:.2g} m in the first 0.5 s, {w_range[-1]:.2g} m in the "
            f"last: slow, the least damped disc mode ({slowest['coordinate']}, "
            f"{slowest['frequency_hz']:.1f} Hz) decays at {slowest['growth_rate']:.3g} 1/s "
            "(the disc has no structural damping)",
            verdict=verdict_of(w_range[-1] < 0.01 * w_range[0], partly=True)),
        printed_row(pc, runs),
    ]
    return pack(pc, {"main": ds}, ("phi_dot", "w")), table


def _critical_speed(pc: PaperCase) -> tuple[float, float]:
    """Disc speed [rad/s] where the frozen-speed sliding equilibrium changes stability,
    and the time [s] the profile reaches it; nan if no change within the run."""
    speed = pc.case.speed
    t_end = pc.case.simulation.duration
    if speed.profile == "decelerating":
        omegas = np.linspace(speed.initial, speed.initial * (1 - t_end / speed.duration) + 0.1, 60)
    else:
        omegas = np.linspace(speed.initial, speed.initial + speed.rate * t_end, 60)
    base = pc.case.replace({"speed": {"profile": "constant", "value": float(omegas[0])},
                            "simulation.initial_state": "rest"})
    growth = np.array([linear_stability(base.replace({"speed.value": float(o)})).max_growth_rate
                       for o in omegas])
    change = np.flatnonzero(np.diff(np.sign(growth)) != 0)
    if change.size == 0:
        return float("nan"), float("nan")
    i = change[0]
    crit = float(omegas[i] + (omegas[i + 1] - omegas[i]) * growth[i] / (growth[i] - growth[i + 1]))
    if speed.profile == "decelerating":
        return crit, float((1.0 - crit / speed.initial) * speed.duration)
    return crit, float((crit - speed.initial) / speed.rate)


def transient_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    ds = runs.get(pc.case, pc.start_from)
    centres, ranges = ms.envelope(ds, "phi_dot", width=0.1)
    # The first window holds the perturbation, which the slider's damping removes fast.
    i_min = 1 + int(np.argmin(ranges[1:]))
    t_min, r_min = centres[i_min], ranges[i_min]
    # The largest range after the minimum: at the very end the disc stops and the slider
    # sticks, so the last window is small again.
    i_max = i_min + int(np.argmax(ranges[i_min:]))
    growth = ranges[i_max] / r_min
    omega_min = float(ds["disc_speed"].sel(time=t_min, method="nearest"))
    crit, t_crit = _critical_speed(pc)
    side = "below" if pc.case.speed.profile == "decelerating" else "above"
    stick = ds["event_time"].values[ds["event_kind"].values == "stick"]
    table = [
        Row(pc.figure, "envelope of the slider's angular velocity",
            "decays at first, then grows",
            f"peak-to-peak over 0.1 s: {ranges[0]:.2g} rad/s at first, minimum {r_min:.2g} "
            f"rad/s at {t_min:.2f} s (Omega = {omega_min:.2f} rad/s), then x{growth:.3g} to "
            f"{ranges[i_max]:.2g} rad/s at {centres[i_max]:.2f} s",
            verdict=verdict_of(ranges[0] > 3.0 * r_min and growth > 10.0)),
        Row(pc.figure, "frozen-speed linear stability along the profile",
            "explains the growth (negative friction slope / moving load)",
            f"sliding equilibrium unstable {side} Omega = {crit:.2f} rad/s, reached at "
            f"t = {t_crit:.1f} s" if np.isfinite(crit) else "no change of stability"),
    ]
    if pc.figure == 5:
        table.append(Row(pc.figure, "stick-slip in the final stage", "induced",
                         f"first stick at t = {stick[0]:.2f} s, {stick.size} sticks" if stick.size
                         else "no stick", verdict=verdict_of(stick.size > 0)))
    else:
        table.append(Row(pc.figure, "separation", "not mentioned", separation_text(ds)))
    table += [omega_dot_row(pc, runs), printed_row(pc, runs)]
    return pack(pc, {"main": ds}, ("phi_dot", "w")), table


def two_panel_plot(data: xr.Dataset) -> Figure:
    """(a) the slider's angular velocity, (b) the disc at (r0, 0)."""
    from matplotlib.figure import Figure

    from fivdisc.plots.result import plot_timeseries

    run = unpack(data, "main")
    fig = Figure(figsize=(9, 6), layout="constrained")
    ax_a, ax_b = fig.subplots(2, 1, sharex=True)
    plot_timeseries(run, "phi_dot", ax=ax_a)
    plot_timeseries(run, "w", probe=0, ax=ax_b)
    ax_b.set_ylabel("w [m]")
    ax_a.set_title("(a) circumferential angular velocity of the slider", fontsize="medium")
    ax_b.set_title("(b) transverse displacement of the disc at r = r0, theta = 0",
                   fontsize="medium")
    suptitle_of(fig, data)
    return fig


