"""Figs. 18-26 of the paper: normal forces (18, 19, 24) and responses (20-23, 25, 26)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import xarray as xr

from fivdisc.paper import measure as ms
from fivdisc.paper.cases import FIGURES, PaperCase
from fivdisc.paper.rows import (
    lyapunov_row,
    omega_dot_row,
    per_window,
    printed_text,
    reference,
    separation_text,
    spectrogram,
    suptitle_of,
    variance_row,
    verdict_of,
    window_text,
)
from fivdisc.paper.runs import FREQ_TOL, WINDOW, Row, Runs, labels_of, pack, unpack

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def normal_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    table = []
    packed = {}
    for label, case in pc.runs.items():
        ds = runs.get(case)
        bad = runs.printed(case)
        packed[label], packed[f"{label}_printed"] = ds, bad
        sep = ms.separation(ds)
        sep_bad = ms.separation(bad)
        printed = printed_text(bad)
        lead = f"{label}: "
        if pc.figure == 18:
            table.append(Row(pc.figure, lead + "separation", "happens",
                             separation_text(ds), printed, verdict_of(sep["count"] > 0)))
        elif pc.figure == 19:
            end = float(ds["time"].values[-1])
            late = 2.0 * end / 3.0
            if label == "a":
                spread = sep["count"] > 0 and sep["first"] < 5.0 and sep["last"] > end - 5.0
                table.append(Row(pc.figure, lead + "separation", "throughout the whole process",
                                 separation_text(ds), printed, verdict_of(spread)))
            else:
                quiet = sep["count"] > 0 and sep["last"] < late
                table.append(Row(pc.figure, lead + "separation",
                                 f"happens, but not in the late stage (after {late:.0f} s)",
                                 separation_text(ds), printed,
                                 verdict_of(quiet, partly=sep["count"] == 0)))
        else:
            ref_case = reference(case)
            ref = runs.get(ref_case)
            omega = (case.speed.initial + case.speed.rate * sep["first"]
                     if sep["count"] else float("nan"))
            omega_bad = (case.speed.initial + case.speed.rate * sep_bad["first"]
                         if sep_bad["count"] else float("nan"))
            table.append(Row(pc.figure, lead + "separation", "happens as the disc speeds up",
                             f"{separation_text(ds)}; first at Omega = {omega:.2f} rad/s",
                             f"{printed}; first at Omega = {omega_bad:.2f} rad/s",
                             verdict_of(sep["count"] > 0)))
            ref_sep = ms.separation(ref)
            table.append(Row(pc.figure, lead + "separation at constant 2 pi rad/s (Figs. 8, 13)",
                             "none", separation_text(ref), printed_text(runs.printed(ref_case)),
                             verdict_of(ref_sep["count"] == 0)))
        if pc.figure != 18:
            table.append(omega_dot_row(pc, runs, label))
    return pack(pc, packed, ("normal_force", "w")), table


def normal_plot(data: xr.Dataset) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.plots.result import plot_normal_force

    panels = [label for label in labels_of(data) if not label.endswith("_printed")]
    fig = Figure(figsize=(12, 3.2 * len(panels) * 2), layout="constrained")
    axes = fig.subplots(2 * len(panels), 2)
    for i, label in enumerate(panels):
        for j, key in enumerate((label, f"{label}_printed")):
            run = unpack(data, key)
            sign = "printed gyroscopic sign" if j else "fivdisc (skew gyroscopic terms)"
            ax = axes[2 * i, j]
            # One shaded band per separation (plot_normal_force) is too slow for thousands.
            time = run["time"].values
            ax.plot(time, run["normal_force"].values, lw=0.5)
            ax.fill_between(time, 0, 1, where=run["phase"].values == 2, color="C1", alpha=0.3,
                            lw=0, transform=ax.get_xaxis_transform(), label="separation")
            ax.set_xlabel("time [s]")
            ax.set_ylabel("normal contact force [N]")
            ax.set_title(f"({label}) {sign}", fontsize="medium")
            sep = ms.separation(run)
            zoom = axes[2 * i + 1, j]
            if sep["count"]:
                t0 = sep["first"] - 0.02
                plot_normal_force(run, window=(max(t0, 0.0), t0 + 0.1), ax=zoom)
                zoom.set_title(f"({label}) zoom at the first separation", fontsize="small")
            else:
                zoom.set_axis_off()
                zoom.text(0.5, 0.5, "no separation", ha="center", va="center",
                          transform=zoom.transAxes)
    suptitle_of(fig, data)
    return fig


def _counterpart(pc: PaperCase) -> PaperCase:
    """The constant-speed figure a decelerating one is compared with (22 <-> 20, 23 <-> 21)."""
    return FIGURES[{22: 20, 23: 21}[pc.figure]]


def responses_compute(pc: PaperCase, runs: Runs) -> tuple[xr.Dataset, list[Row]]:
    ds = runs.get(pc.case)
    sep = ms.separation(ds)
    table = [Row(pc.figure, "separation", "happens", separation_text(ds),
                 printed_text(runs.printed(pc.case)), verdict_of(sep["count"] > 0))]
    end = float(ds["time"].values[-1])
    profile = pc.case.speed.profile
    if profile == "constant":
        for var, probe in (("phi", None), ("w", 1)):
            table.append(Row(pc.figure, f"strongest line of {var} per 5 s", "(time-frequency plot)",
                             window_text(per_window(ds, var, probe))))
        if pc.figure in (20, 21):
            table.append(lyapunov_row(pc, ds, 1.0, min(11.0, end)))
    elif profile == "decelerating":
        ref = runs.get(_counterpart(pc).case)
        _, r_dec = ms.ridge(ds, "phi")
        _, r_ref = ms.ridge(ref, "phi")
        table.append(variance_row(pc, r_dec, r_ref, "slider angle phi"))
        early = ms.dominant(ds, "phi", None, 1.0, 6.0)
        late = ms.dominant(ds, "phi", None, end - WINDOW, end)
        n_early = ms.line_count(ds, "phi", 1.0, 5.0)
        n_late = ms.line_count(ds, "phi", end - 4.0, end)
        lower = late < 0.95 * early and n_late > n_early
        expected = pc.figure == 23
        table += [
            Row(pc.figure, "strongest line of phi per 5 s", "(time-frequency plot)",
                window_text(per_window(ds, "phi"))),
            Row(pc.figure, "final stage: lower and denser lines (strongest line; lines of "
                "at least 5 %, first 1-5 s vs last 4 s)",
                "yes" if expected else "not seen",
                f"{early:.1f} -> {late:.1f} Hz; {n_early} vs {n_late} lines",
                verdict=verdict_of(lower == expected)),
            Row(pc.figure, "separation in the late stage",
                "none" if expected else "separation throughout",
                f"last separation starts at {sep['last']:.2f} s" if sep["count"]
                else "no separation"),
            omega_dot_row(pc, runs),
        ]
    else:
        if sep["count"]:
            t_sep = sep["first"]
            before = ms.dominant(ds, "phi", None, max(0.0, t_sep - 2.0), t_sep)
            after = ms.dominant(ds, "phi", None, t_sep, min(end, t_sep + 2.0))
            w_before = ms.dominant(ds, "w", 1, max(0.0, t_sep - 2.0), t_sep)
            w_after = ms.dominant(ds, "w", 1, t_sep, min(end, t_sep + 2.0))
            shift = abs(after - before) > FREQ_TOL or abs(w_after - w_before) > FREQ_TOL
            table.append(Row(pc.figure, "strongest lines 2 s before vs after the first separation",
                             "separation shifts the spectra",
                             f"phi {before:.1f} -> {after:.1f} Hz, w {w_before:.1f} -> "
                             f"{w_after:.1f} Hz", verdict=verdict_of(shift)))
        table.append(omega_dot_row(pc, runs))
    return pack(pc, {"main": ds}, ("phi", "phi_dot", "w")), table


def responses_plot(data: xr.Dataset) -> Figure:
    from matplotlib.figure import Figure

    from fivdisc.plots.result import plot_timeseries

    run = unpack(data, "main")
    fig = Figure(figsize=(12, 7), layout="constrained")
    axes = fig.subplots(2, 2)
    plot_timeseries(run, "phi_dot", ax=axes[0, 0])
    spectrogram(run, "phi", None, axes[0, 1])
    plot_timeseries(run, "w", probe=1, ax=axes[1, 0])
    axes[1, 0].set_ylabel("w [m]")
    spectrogram(run, "w", 1, axes[1, 1])
    for ax, text in zip(axes.ravel(), ("(a) slider angular velocity", "(b) slider angle: STFT",
                                       "(c) disc at (r0, 1 rad)", "(d) disc: STFT"), strict=True):
        ax.set_title(text, fontsize="medium")
    suptitle_of(fig, data)
    return fig


