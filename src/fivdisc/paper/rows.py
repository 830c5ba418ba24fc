"""Comparison rows and drawing helpers that several of the paper's figures share."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from fivdisc.analysis import linear_stability
from fivdisc.case import Case
from fivdisc.paper import measure as ms
from fivdisc.paper.cases import PaperCase
from fivdisc.paper.runs import FMAX, STFT_SEGMENT, WINDOW, Row, Runs

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

# --- rows shared by several figures ------------------------------------------------------------


def separation_text(ds: xr.Dataset) -> str:
    sep = ms.separation(ds)
    if not sep["count"]:
        return f"no separation in {float(ds['time'].values[-1]):g} s"
    return (f"separates {sep['count']} times from t = {sep['first']:.2f} s to "
            f"{sep['last']:.2f} s ({100 * sep['fraction']:.0f} % of the time)")


def printed_text(ds: xr.Dataset) -> str:
    """Separation and divergence of a printed-sign run."""
    _, end = ms.run_end(ds)
    sep = ms.separation(ds)
    head = f"first separation at {sep['first']:.2f} s" if sep["count"] else "no separation"
    return f"{head}; {end}"


def printed_row(pc: PaperCase, runs: Runs) -> Row:
    """What the printed gyroscopic sign does to the figure's runs."""
    parts_ok, parts_printed = [], []
    for label, case in pc.runs.items():
        lead = f"{label}: " if label else ""
        parts_ok.append(lead + separation_text(runs.get(case, pc.start_from)))
        parts_printed.append(lead + printed_text(runs.printed(case, pc.start_from)))
    return Row(pc.figure, "separation and boundedness, skew vs printed gyroscopic sign",
               "(equations as printed: +2 l M Omega dC/dt in the D equation)",
               "; ".join(parts_ok), "; ".join(parts_printed))


def _divergence(first: xr.Dataset, second: xr.Dataset, span: float = 1.0) -> tuple[float, float]:
    """How far two runs of the same case drift apart in the slider angle.

    Returns
    -------
    largest, when
        Largest ``|phi_1 - phi_2|`` over the first `span` s relative to the largest
        ``|phi_1|`` there, and the time [s] the difference first exceeds 1e-3 of that
        peak (nan if never).
    """
    keep = first["time"].values <= span
    diff = np.abs(first["phi"].values[keep] - second["phi"].values[keep])
    peak = np.max(np.abs(first["phi"].values[keep]))
    over = np.flatnonzero(diff > 1e-3 * peak)
    when = float(first["time"].values[over[0]]) if over.size else float("nan")
    return float(np.max(diff) / peak), when


def omega_dot_row(pc: PaperCase, runs: Runs, label: str = "") -> Row:
    """Effect of the dOmega/dt terms (absent from the printed equations) on a run, next to
    the effect of a ten times tighter tolerance (the run's sensitivity)."""
    case = pc.runs[label]
    on = runs.get(case, pc.start_from)
    off = runs.get(case.replace({"simulation.omega_dot_terms": False}), pc.start_from)
    rtol = case.simulation.rtol
    tight = runs.get(case.replace({"simulation.rtol": rtol / 10.0}), pc.start_from)
    diff, when = _divergence(on, off)
    diff_tol, when_tol = _divergence(on, tight)
    counts = []
    for kind in ("stick", "separation"):
        n_on = int(np.sum(on["event_kind"].values == kind))
        n_off = int(np.sum(off["event_kind"].values == kind))
        counts.append(f"{kind} events {n_on} with, {n_off} without")
    lead = f"{label}: " if label else ""
    after = (f", above 1e-3 from t = {when:.2f} s" if np.isfinite(when) else "")
    after_tol = (f", above 1e-3 from t = {when_tol:.2f} s" if np.isfinite(when_tol) else "")
    return Row(pc.figure, "dOmega/dt terms of the disc equations, on vs off",
               "omitted in the printed Eqs. (33)-(41)",
               f"{lead}max |phi_on - phi_off| over the first 1 s = {diff:.1e} of max |phi|"
               f"{after} (rtol {rtol:g} vs {rtol / 10:g}: {diff_tol:.1e}{after_tol}); "
               "whole run: "
               f"{'; '.join(counts)}")


def _stability_text(case: Case) -> tuple[str, bool]:
    """Linear stability of a constant-speed case's sliding equilibrium, in words."""
    stab = linear_stability(case)
    word = "stable" if stab.stable else "unstable"
    return (f"{word}: largest growth rate {stab.max_growth_rate:.3g} 1/s "
            f"({stab.dominant[0]})"), stab.stable


def stability_row(figure: int, case: Case, paper: str,
                   quantity: str = "sliding equilibrium") -> Row:
    """Linear stability of `case` with the skew and the printed gyroscopic sign."""
    text, stable = _stability_text(case)
    printed, _ = _stability_text(case.replace({"simulation.printed_gyroscopic_sign": True}))
    return Row(figure, quantity, paper, text, printed, verdict_of(stable == (paper == "stable")))


def verdict_of(ok: bool, partly: bool = False) -> str:
    return "agrees" if ok else ("partly" if partly else "differs")


def analysis_window(ds: xr.Dataset, length: float = 10.0) -> tuple[float, float]:
    """The opening stationary stretch of a constant-speed run: from 1 s (after the
    start-up transient) for `length` s (0.1 Hz resolution), ending before the first
    separation."""
    sep = ms.separation(ds)
    end = min(1.0 + length, float(ds["time"].values[-1]))
    if sep["count"] and sep["first"] - 0.5 < end:
        end = sep["first"] - 0.5
    return 1.0, end


# Lyapunov exponents of a constant-speed run: three, over the analysis window.
_EXPONENTS = 3
_PAPER_LABEL = {8: "quasi-periodic", 13: "periodic"}


def lyapunov_row(pc: PaperCase, ds: xr.Dataset, t0: float, t1: float) -> Row:
    """The spectral label of phi over [t0, t1] against the Lyapunov exponents of the
    same stretch (QR method with the saltation matrices at every switch)."""
    from fivdisc.analysis.exponents import lyapunov
    from fivdisc.analysis.regimes import cross_check

    spectral = ms.periodicity(ds, "phi", None, t0, t1).kind
    spec = lyapunov(pc.case, n=_EXPONENTS, transient=t0, duration=t1 - t0)
    regime = cross_check(spectral, spec)
    paper = _PAPER_LABEL.get(pc.figure, "")
    verdict = (verdict_of(regime.lyapunov == paper, partly=regime.consistent) if paper else "")
    return Row(pc.figure, f"Lyapunov exponents ({_EXPONENTS}, {t0:g}-{t1:g} s) against the "
               "spectral label of phi", paper or "(not stated)",
               regime.summary + "; exponents " + ", ".join(f"{e:+.3g}" for e in spec.exponents)
               + " 1/s", verdict=verdict)


def per_window(ds: xr.Dataset, var: str, probe: int | None = None,
                width: float = WINDOW, until: float | None = None) -> list[tuple[float, float]]:
    """(window start [s], dominant frequency [Hz]) per window of `width` s, up to `until`."""
    end = float(ds["time"].values[-1]) if until is None else until
    starts = np.arange(0.0, end - width + 1e-9, width)
    return [(float(t0), ms.dominant(ds, var, probe, t0, t0 + width)) for t0 in starts]


def window_text(values: list[tuple[float, float]], width: float = WINDOW) -> str:
    return ", ".join(f"{t0:g}-{t0 + width:g} s: {f:.1f}" for t0, f in values) + " Hz"


def spectrogram(run: xr.Dataset, var: str, probe: int | None, ax: Axes) -> None:
    """Time-frequency plot of one variable, with a short colour-bar label."""
    from fivdisc.plots.result import plot_spectrogram

    plot_spectrogram(run, var, probe=probe, segment=STFT_SEGMENT, fmax=FMAX, ax=ax)
    # plot_spectrogram adds the colour bar last; its long name would overlap the panels.
    unit = "rad" if var == "phi" else "m"
    ax.figure.axes[-1].set_ylabel(f"STFT magnitude of {var} [{unit}]")


def suptitle_of(fig: Figure, data: xr.DataTree) -> None:
    fig.suptitle(f"Fig. {data.attrs['figure']}: {data.attrs['figure_title']}", fontsize="medium")


def reference(case: Case) -> Case:
    """The constant-speed case a variable-speed case is compared with: the same at its
    initial speed (2 pi or 6 pi rad/s)."""
    speed = case.speed
    value = speed.value if speed.profile == "constant" else speed.initial
    return case.replace({"speed": {"profile": "constant", "value": value}})



def variance_row(pc: PaperCase, r_dec: np.ndarray, r_ref: np.ndarray, name: str) -> Row:
    """How often the strongest line moves, decelerating vs constant speed."""
    dec, ref = ms.ridge_changes(r_dec), ms.ridge_changes(r_ref)
    return Row(pc.figure, f"time-variance: share of 0.5 s STFT slices where the strongest line "
               f"of {name} moves by more than 2 Hz, decelerating vs constant speed",
               "more time-variant than at constant speed",
               f"{100 * dec:.0f} % vs {100 * ref:.0f} %", verdict=verdict_of(dec > ref))


