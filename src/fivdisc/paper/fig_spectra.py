"""Figs. 8-17 of the paper: slider and disc spectra at constant and decelerating
speed, early and late windows (Fig. 12) and phase portraits (Fig. 17).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from fivdisc.analysis import linear_stability
from fivdisc.paper import measure as ms
from fivdisc.paper.cases import PaperCase
from fivdisc.paper.rows import (
    analysis_window,
    lyapunov_row,
    omega_dot_row,
    per_window,
    printed_row,
    reference,
    separation_text,
    spectrogram,
    stability_row,
    suptitle_of,
    variance_row,
    verdict_of,
    window_text,
)
from fivdisc.paper.runs import FMAX, FREQ_TOL, WINDOW, Row, Runs, labels_of, pack, unpack

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def _constant_rows(pc: PaperCase, ds: xr.Dataset, var: str, probe: int | None) -> list[Row]:
    """Stationarity, periodicity and common lines of a constant-speed run."""
    t0, t1 = analysis_window(ds)
    verdict = ms.periodicity(ds, var, probe, t0, t1)
    mine = ms.lines(ds, var, probe, t0, t1, n=20, rel=0.01)
    other_var, other_probe = ("w", 1) if var == "phi" else ("phi", None)
    other = ms.lines(ds, other_var, other_probe, t0, t1, n=20, rel=0.01)
    tol = 2.0 * mine.resolution
    common = ms.common_frequencies(mine, other, tol)
    sep = ms.separation(ds)
    until = sep["first"] if sep["count"] else None
    stages = per_window(ds, var, probe, until=until)
    spread = np.ptp([f for _, f in stages]) if stages else np.nan
    name = "slider angle phi" if var == "phi" else "disc w at (r0, 1 rad)"
    window = f"{t0:g}-{t1:g} s"
    table = [Row(pc.figure, f"stationarity: strongest line of {name} per 5 s",
                 "unchanged throughout the process",
                 f"{window_text(stages)} (spread {spread:.2f} Hz)",
                 verdict=verdict_of(spread < FREQ_TOL))]
    if pc.figure in (8, 9):
        has = [any(abs(c - f) < FREQ_TOL for c in common) for f in (181.0, 290.5)]
        table += [
            Row(pc.figure, f"{name}, {window}", "quasi-periodic", verdict.summary,
                verdict=verdict_of(verdict.kind == "quasi-periodic")),
            Row(pc.figure, f"lines common to phi and w (at least 1 % of the strongest), {window}",
                "f1 = 181 Hz and f2 = 290.5 Hz", ms.hz(common),
                verdict=verdict_of(all(has), partly=any(has))),
        ]
    else:
        f0 = verdict.fundamental
        text = verdict.summary
        if np.isfinite(f0):
            multiples = ms.lines(ds, var, probe, t0, t1).frequencies / f0
            text += f"; strong lines at {', '.join(f'{m:.3f}' for m in multiples)} f0"
        table.append(Row(pc.figure, f"{name}, {window}",
                         "periodic: f0 = 206 Hz and its superharmonics n f0", text,
                         verdict=verdict_of(verdict.kind == "periodic"
                                          and abs(f0 - 206.0) < FREQ_TOL,
                                          partly=verdict.kind == "periodic")))
        if var == "w":
            f_phi = ms.periodicity(ds, "phi", None, t0, t1).fundamental
            peaks = ms.lines(ds, var, probe, t0, t1)
            ratios = peaks.frequencies / f_phi
            whole = np.abs(ratios - np.round(ratios)) < 0.01
            table.append(Row(pc.figure, "disc lines (at least 5 % of the strongest) as multiples "
                             "of the slider's f0",
                             "the same fundamental f0 (periodic at the same frequency)",
                             ", ".join(f"{r:.3f} f0 ({100 * a / peaks.amplitudes[0]:.0f} %)"
                                       for r, a in zip(ratios, peaks.amplitudes, strict=True))
                             + f", f0 = {f_phi:.2f} Hz; the others are free disc modes (no "
                             "structural damping)",
                             verdict=verdict_of(whole.all(), partly=whole[0])))
    table.append(Row(pc.figure, "separation at constant speed", "none (section 3.2, Fig. 24)",
                     separation_text(ds), verdict=verdict_of(sep["count"] == 0)))
    return table


def _decelerating_rows(pc: PaperCase, ds: xr.Dataset, ref: xr.Dataset, var: str,
                       probe: int | None) -> list[Row]:
    """Time-variance, the early stage against constant speed, and the final stage."""
    name = "slider angle phi" if var == "phi" else "disc w at (r0, 1 rad)"
    early_dec = ms.dominant(ds, var, probe, 1.0, 6.0)
    early_ref = ms.dominant(ref, var, probe, 1.0, 6.0)
    end = float(ds["time"].values[-1])
    late = ms.dominant(ds, var, probe, end - WINDOW, end)
    n_early = ms.line_count(ds, var, 1.0, 5.0, probe)
    n_late = ms.line_count(ds, var, end - 4.0, end, probe)
    _, r_dec = ms.ridge(ds, var, probe)
    _, r_ref = ms.ridge(ref, var, probe)
    return [
        Row(pc.figure, f"strongest line of {name} per 5 s", "time-variant",
            window_text(per_window(ds, var, probe))),
        variance_row(pc, r_dec, r_ref, name),
        Row(pc.figure, "early stage (1-6 s), strongest line vs constant speed",
            "similar to constant speed",
            f"{early_dec:.1f} Hz vs {early_ref:.1f} Hz",
            verdict=verdict_of(abs(early_dec - early_ref) < FREQ_TOL)),
        Row(pc.figure, f"final stage ({end - WINDOW:g}-{end:g} s), strongest line",
            "lower-frequency components arise", f"{late:.1f} Hz (early: {early_dec:.1f} Hz)",
            verdict=verdict_of(late < 0.95 * early_dec)),
        Row(pc.figure, "lines of at least 5 % of the strongest, first 1-5 s vs last 4 s",
            "fuzzy and dense in the final stage", f"{n_early} vs {n_late}",
            verdict=verdict_of(n_late > n_early)),
    ]
def spectra_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    ds = runs.get(pc.case)
    slider = pc.figure in (8, 10, 13, 15)
    var, probe = ("phi", None) if slider else ("w", 1)
    if pc.case.speed.profile == "constant":
        table = []
        if slider:
            table.append(stability_row(pc.figure, pc.case, "unstable"))
            if pc.figure == 8:
                stab = linear_stability(pc.case)
                eigen = stab.to_dataframe()
                freq = dict(zip(eigen["coordinate"], eigen["frequency_hz"], strict=True))
                table.append(Row(pc.figure, "linear eigenfrequencies C01 and D02",
                                 "f1 = 181 Hz, f2 = 290.5 Hz",
                                 f"{freq['C01']:.2f} Hz, {freq['D02']:.2f} Hz",
                                 verdict=verdict_of(abs(freq["C01"] - 181.0) < FREQ_TOL
                                                  and abs(freq["D02"] - 290.5) < FREQ_TOL)))
        table += _constant_rows(pc, ds, var, probe)
        if pc.figure in (8, 13):
            table.append(lyapunov_row(pc, ds, *analysis_window(ds)))
    else:
        table = _decelerating_rows(pc, ds, runs.get(reference(pc.case)), var, probe)
        if pc.figure == 15:
            table += _segment_rows(pc, ds)
        table += [Row(pc.figure, "separation", "not mentioned", separation_text(ds)),
                  omega_dot_row(pc, runs)]
    table.append(printed_row(pc, runs))
    data = pack(pc, {"main": ds}, ("phi", "phi_dot") if slider else ("w",))
    data.attrs["profile"] = pc.case.speed.profile
    data.attrs["analysis_window"] = list(analysis_window(ds))
    return data, table


def _segment_rows(pc: PaperCase, ds: xr.Dataset) -> list[Row]:
    """The six segments of Fig. 15: the strongest line of phi at their ends and middle."""
    times, freqs = ms.ridge(ds, "phi")
    leave = ms.plateau_end(times, freqs)
    table = [Row(pc.figure, "end of the opening periodic regime",
                 "first segment 0-10 s, second 10-15 s",
                 f"the strongest line leaves {np.median(freqs[: freqs.size // 4]):.0f} Hz at "
                 f"t = {leave:.1f} s and then glides down as the disc slows",
                 verdict=verdict_of(10.0 <= leave <= 15.0))]
    previous = None
    for t0, t1 in pc.windows:
        inside = (times >= t0) & (times <= t1)
        f = freqs[inside]
        stick = float(np.mean(ds["phase"].values[(ds["time"].values >= t0)
                                                 & (ds["time"].values <= t1)] == 1))
        median = float(np.median(f))
        distinct = previous is None or abs(median - previous) > 0.03 * previous
        moves = abs(f[-1] - f[0]) > 0.03 * f[0]
        table.append(Row(pc.figure, f"segment {t0:g}-{t1:g} s", "a distinct frequency composition",
                         f"strongest line {f[0]:.0f} -> {f[-1]:.0f} Hz (median {median:.0f} Hz, "
                         f"0.5 s STFT); sticking {100 * stick:.0f} % of the time",
                         verdict=verdict_of(distinct, partly=moves)))
        previous = median
    return table


def spectra_plot(data: xr.Dataset) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.plots.result import plot_spectrum, plot_timeseries

    run = unpack(data, "main")
    figure = int(data.attrs["figure"])
    slider = figure in (8, 10, 13, 15)
    constant = data.attrs["profile"] == "constant"
    if slider:
        fig = Figure(figsize=(10, 7), layout="constrained")
        ax_a, ax_b = fig.subplots(2, 1)
        plot_timeseries(run, "phi_dot", ax=ax_a)
        spectrogram(run, "phi", None, ax_b)
        ax_a.set_title("(a) circumferential angular velocity of the slider", fontsize="medium")
        ax_b.set_title("(b) time-frequency plot of the circumferential angle", fontsize="medium")
    else:
        fig = Figure(figsize=(10, 10 if constant else 7), layout="constrained")
        axes = fig.subplots(3 if constant else 2, 1)
        plot_timeseries(run, "w", probe=1, ax=axes[0])
        axes[0].set_ylabel("w [m]")
        spectrogram(run, "w", 1, axes[1])
        axes[0].set_title("(a) transverse displacement of the disc at r = r0, theta = 1 rad",
                          fontsize="medium")
        axes[1].set_title("(b) time-frequency plot", fontsize="medium")
        if constant:
            t0, t1 = (float(t) for t in np.atleast_1d(data.attrs["analysis_window"]))
            plot_spectrum(run, "w", probe=1, window=(t0, t1), fmax=FMAX, ax=axes[2])
            # plot_spectrum's title ends with the periodicity verdict
            verdict = axes[2].get_title().split("\n")[-1]
            axes[2].set_title(f"(b') amplitude spectrum, {t0:g}-{t1:g} s\n{verdict}",
                              fontsize="small")
    suptitle_of(fig, data)
    return fig


# --- Fig. 12: early and late windows; Fig. 17: phase portraits ---------------------------------


def _motion_text(ds: xr.Dataset, t0: float, t1: float) -> tuple[str, float, bool]:
    """The slider's motion in a window, its fundamental (or strongest) frequency [Hz], and
    whether it sticks."""
    inside = (ds["time"].values >= t0) & (ds["time"].values <= t1)
    stick = float(np.mean(ds["phase"].values[inside] == 1))
    kind = ms.periodicity(ds, "phi", None, t0, t1)
    freq = kind.fundamental if kind.kind == "periodic" else ms.dominant(ds, "phi", None, t0, t1)
    motion = "stick-slip" if stick > 0 else "pure slip"
    return (f"{motion}, sticking {100 * stick:.0f} % of the time; phi {kind.summary}", freq,
            stick > 0)


def _window(ds: xr.Dataset, t0: float, t1: float) -> xr.Dataset:
    """The samples and events of a run within ``[t0, t1]`` [s]."""
    times = ds["event_time"].values
    return ds.sel(time=slice(t0, t1)).isel(event=(times >= t0) & (times <= t1))


def windows_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    ds = runs.get(pc.case)
    table, freqs, sticks = [], [], []
    for t0, t1 in pc.windows:
        text, freq, sticks_here = _motion_text(ds, t0, t1)
        freqs.append(freq)
        sticks.append(sticks_here)
        table.append(Row(pc.figure, f"{t0:g}-{t1:g} s", "(time histories)", text))
    if pc.figure == 12:
        a, b = freqs
        table.append(Row(pc.figure, "frequency of the slider's motion, early vs late span",
                         "varies during the process", f"{a:.1f} Hz vs {b:.1f} Hz",
                         verdict=verdict_of(abs(a - b) > 0.03 * a)))
    else:
        # Lines closer than the 10 Hz resolution of a 0.1 s window are not told apart.
        distinct = len({round(f / 10.0) for f in freqs if np.isfinite(f)})
        table.append(Row(pc.figure, "stick-slip and its period in the six spans",
                         "stick-slip with different periods in the six spans",
                         f"stick-slip in {sum(sticks)} of 6 spans; fundamental (or strongest) "
                         f"frequency {ms.hz(freqs)}: {distinct} distinct at 10 Hz resolution",
                         verdict=verdict_of(all(sticks) and distinct == 6,
                                          partly=any(sticks) and distinct > 1)))
    parts = [_window(ds, t0, t1) for t0, t1 in pc.windows]
    data = pack(pc, {f"w{i}": p for i, p in enumerate(parts)},
                 ("phi", "phi_dot", "friction_force", "disc_speed"))
    return data, table


def windows_plot(data: xr.Dataset) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.plots.result import plot_friction, plot_phase_portrait, plot_timeseries

    labels = labels_of(data)
    letters = "abcdefghijkl"
    if int(data.attrs["figure"]) == 12:
        fig = Figure(figsize=(10, 6.5), layout="constrained")
        axes = fig.subplots(2, len(labels))
        for i, label in enumerate(labels):
            run = unpack(data, label)
            plot_timeseries(run, "phi_dot", ax=axes[0, i])
            plot_timeseries(run, "friction_force", ax=axes[1, i])
            axes[1, i].set_ylabel("friction force [N]")
            axes[0, i].set_title(f"({letters[i]}) slider angular velocity", fontsize="medium")
            axes[1, i].set_title(f"({letters[i + 2]}) friction force", fontsize="medium")
    else:
        fig = Figure(figsize=(10, 16), layout="constrained")
        axes = fig.subplots(len(labels), 2)
        for i, label in enumerate(labels):
            run = unpack(data, label)
            t0, t1 = float(run["time"].values[0]), float(run["time"].values[-1])
            plot_phase_portrait(run, ax=axes[i, 0])
            plot_friction(run, ax=axes[i, 1])
            axes[i, 1].set_ylabel("friction force [N]")
            axes[i, 0].set_title(f"({letters[2 * i]}) {t0:g} < t < {t1:g} s", fontsize="medium")
            axes[i, 1].set_title(f"({letters[2 * i + 1]}) {t0:g} < t < {t1:g} s",
                                 fontsize="medium")
    suptitle_of(fig, data)
    return fig


