"""Reproduce the paper: every figure, its data, and a report of paper vs fivdisc.

``reproduce(outdir=...)`` writes, per figure, ``figNN.png`` and ``figNN.nc`` (the
data behind it, see :func:`fivdisc.paper.figures.compute`), then ``REPORT.md`` and
a self-contained ``REPORT.html``. Files are written to a temporary name and renamed,
so an interrupted run leaves no half-written file. A figure whose PNG and netCDF
exist, whose data match the checksum stored in the netCDF file and whose stored
parameters equal the current ones is reused, so a rerun
after an interruption (or with more figures) only computes what is missing.

Figures that show the same simulations (8 and 9, 10 and 11, ...) are computed
together; groups run in a pool of processes. Fig. 27's sweeps run first on their
own pool, with their Zarr stores kept in ``outdir`` so that they resume too.
"""

from __future__ import annotations

import datetime
import os
import time
from collections.abc import Iterable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from importlib.metadata import version
from multiprocessing import get_context
from os import PathLike
from pathlib import Path

import numpy as np
import xarray as xr

from fivdisc.errors import FivdiscError
from fivdisc.files import check_netcdf, write_atomic, write_netcdf
from fivdisc.paper.cases import CITATION, FIGURES
from fivdisc.paper.figures import RECIPE, Row, Runs, compute, plot, rows
from fivdisc.paper.report import figure_blocks, render_html, render_markdown, summary_blocks

__all__ = ["ReproduceReport", "parse_figures", "reproduce"]

#: Figures computed by parameter sweeps (they need the ``distributed`` extra).
SWEEP_FIGURES = (27,)
# Largest float stored as float32; larger values (diverging printed-sign runs) stay float64.
_FLOAT32_MAX = 1e30


@dataclass(frozen=True)
class ReproduceReport:
    """What a call of :func:`reproduce` did.

    Attributes
    ----------
    outdir
        The output directory.
    computed
        Figures computed by this call.
    reused
        Figures found up to date and reused.
    wall_time
        Duration of the call [s].
    """

    outdir: Path
    computed: tuple[int, ...]
    reused: tuple[int, ...]
    wall_time: float


def parse_figures(text: str, option: str = "--figures") -> list[int]:
    """Figure numbers from ``"3,8,27"`` (ranges such as ``"8-12"`` allowed).

    Raises
    ------
    FivdiscError
        A part that is not a number or range, or a figure the paper does not simulate;
        the message names `option`, the value and the allowed figures.
    """
    allowed = f"allowed: {min(FIGURES)}-{max(FIGURES)}"
    numbers: list[int] = []
    for part in text.split(","):
        bounds = part.strip().split("-")
        try:
            low, high = int(bounds[0]), int(bounds[-1])
        except ValueError:
            raise FivdiscError(f"{option} = {text!r} is invalid: {part.strip()!r} is not a "
                               f"figure number ({allowed})") from None
        if len(bounds) > 2 or low > high:
            raise FivdiscError(f"{option} = {text!r} is invalid: {part.strip()!r} is not a "
                               f"range ({allowed})")
        numbers += range(low, high + 1)
    return check_figures(numbers, option, text)


def check_figures(figures: Iterable[int], option: str = "figures",
                  shown: str | None = None) -> list[int]:
    """Sorted, distinct figure numbers; a FivdiscError names any the paper does not simulate."""
    numbers = sorted(set(figures))
    bad = [n for n in numbers if n not in FIGURES]
    if bad or not numbers:
        value = shown if shown is not None else str(list(figures))
        what = (f"{', '.join(map(str, bad))} {'is' if len(bad) == 1 else 'are'} not "
                "simulated in the paper" if bad else "no figure given")
        raise FivdiscError(f"{option} = {value!r} is invalid: {what} (allowed: "
                           f"{min(FIGURES)}-{max(FIGURES)})")
    return numbers


def reproduce(figures: Iterable[int] | None = None,
              outdir: str | PathLike[str] = "paper-figures", force: bool = False,
              progress: bool = True, workers: int | None = None) -> ReproduceReport:
    """Compute and draw the paper's figures and write the comparison report.

    Parameters
    ----------
    figures
        Figure numbers (3-28); None: all of them.
    outdir
        Output directory (created if missing).
    force
        Recompute figures even when up to date.
    progress
        Show a progress bar over the figures (and Fig. 27's sweeps).
    workers
        Processes used (default: at most 2, the CPUs available); 1 computes in
        this process.

    Returns
    -------
    ReproduceReport

    Raises
    ------
    FivdiscError
        Unknown figure numbers or a bad `workers`.
    """
    start = time.perf_counter()
    numbers = check_figures(list(FIGURES if figures is None else figures))
    if workers is None:
        workers = min(2, os.cpu_count() or 1)
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise FivdiscError(f"workers = {workers!r} is invalid: must be an integer >= 1")
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    todo = [n for n in numbers if force or not _up_to_date(out, n)]
    reused = tuple(n for n in numbers if n not in todo)
    seconds: dict[int, float] = {}

    from tqdm import tqdm

    with tqdm(total=len(numbers), initial=len(reused), unit="fig", desc="figures",
              disable=not progress, dynamic_ncols=True) as bar:
        for number in (n for n in todo if n in SWEEP_FIGURES):
            bar.set_postfix_str(f"fig {number} (sweep)")
            runs = Runs(sweep_dir=out, sweep_workers=workers, progress=progress)
            seconds |= _make([number], str(out), runs)
            bar.update(1)
        groups = _groups([n for n in todo if n not in SWEEP_FIGURES])
        if workers == 1 or len(groups) <= 1:
            for group in groups:
                bar.set_postfix_str("figs " + ",".join(map(str, group)))
                seconds |= _make(group, str(out))
                bar.update(len(group))
        else:
            bar.set_postfix_str(f"{len(groups)} groups on {workers} processes")
            # spawn, not fork: a forked child would inherit the parent's threads (tqdm's).
            with ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn")) as pool:
                futures = {pool.submit(_make, group, str(out)): group for group in groups}
                for future in as_completed(futures):
                    seconds |= future.result()
                    bar.update(len(futures[future]))
    wall = time.perf_counter() - start
    _write_report(out, tuple(todo), reused, wall)
    return ReproduceReport(out, tuple(todo), reused, time.perf_counter() - start)


def _groups(numbers: list[int]) -> list[list[int]]:
    """Figures that share a simulation, together (largest groups first)."""
    groups: list[list[int]] = []
    keys: list[set] = []
    for number in numbers:
        pc = FIGURES[number]
        own = {(case, pc.start_from) for case in pc.runs.values()}
        joined = [i for i, k in enumerate(keys) if k & own]
        group, key = [number], set(own)
        for i in reversed(joined):
            group = groups.pop(i) + group
            key |= keys.pop(i)
        groups.append(sorted(group))
        keys.append(key)
    return sorted(groups, key=len, reverse=True)


def _make(numbers: list[int], outdir: str, runs: Runs | None = None) -> dict[int, float]:
    """Compute, draw and store some figures; returns their compute times [s]."""
    runs = runs if runs is not None else Runs()
    out = Path(outdir)
    seconds = {}
    for number in numbers:
        start = time.perf_counter()
        data = compute(number, runs)
        figure = plot(data)
        stem = FIGURES[number].stem
        # The PNG goes first: a netCDF file on disk means its figure is complete.
        write_atomic(out / f"{stem}.png", lambda p, f=figure: f.savefig(p, dpi=110, format="png"))
        seconds[number] = time.perf_counter() - start
        data.attrs["seconds"] = seconds[number]
        data.attrs["fivdisc_version"] = version("fivdisc")
        write_netcdf(out / f"{stem}.nc", lambda p, d=data: d.to_netcdf(p, encoding=_encoding(d)))
    return seconds


def _encoding(data: xr.DataTree) -> dict[str, dict]:
    """Compressed storage, group by group; float32 for time histories that fit it."""
    encoding: dict[str, dict] = {}
    for node in data.subtree:
        group = {}
        for name, var in node.data_vars.items():
            if var.dtype.kind != "f":
                continue
            spec = {"zlib": True, "complevel": 4}
            finite = var.values[np.isfinite(var.values)]
            if name != "event_time" and (finite.size == 0
                                         or np.max(np.abs(finite)) < _FLOAT32_MAX):
                spec["dtype"] = "float32"
            group[name] = spec
        if group:
            encoding[node.path] = group
    return encoding


def _stored_attrs(path: Path) -> dict | None:
    """Attributes of a stored figure dataset; None if it is missing, unreadable, without a
    checksum or not matching it (its figure is then computed again)."""
    if not path.exists():
        return None
    try:
        if not check_netcdf(path):
            return None
        with xr.open_dataset(path) as data:
            return dict(data.attrs)
    except (OSError, ValueError, FivdiscError):
        return None


def _up_to_date(out: Path, number: int) -> bool:
    pc = FIGURES[number]
    attrs = _stored_attrs(out / f"{pc.stem}.nc")
    return (attrs is not None and (out / f"{pc.stem}.png").exists()
            and attrs.get("parameters") == pc.parameters() and attrs.get("recipe") == RECIPE)


def _write_report(out: Path, computed: tuple[int, ...], reused: tuple[int, ...],
                  wall: float) -> None:
    """REPORT.md and REPORT.html over every up-to-date figure in `out`."""
    present = [n for n in FIGURES if _up_to_date(out, n)]
    stored = {n: _stored_attrs(out / f"{FIGURES[n].stem}.nc") for n in present}
    table: dict[int, list[Row]] = {n: rows(xr.Dataset(attrs=stored[n])) for n in present}
    now = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC")
    intro = [
        f"Paper: {CITATION}.",
        f"fivdisc {version('fivdisc')}, {now}. This run computed "
        f"{len(computed)} figure(s) ({', '.join(map(str, computed)) or 'none'}) and reused "
        f"{len(reused)}; wall time {wall:.0f} s.",
        "Columns: 'paper' is what the paper states or shows; 'fivdisc' is what fivdisc "
        "measures with its model (docs/model.md: skew gyroscopic terms, dOmega/dt terms "
        "kept); 'printed sign' is fivdisc with the printed paper's "
        "+2 l M Omega dC/dt term in the D equations (simulation.printed_gyroscopic_sign), "
        "where measured. 'verdict' compares the 'fivdisc' column with the paper; '-' marks "
        "a measurement without a paper value to compare with. See docs/deviations.md.",
    ]
    missing = [n for n in FIGURES if n not in present]
    blocks = summary_blocks("Reproduction of the paper by fivdisc", intro, table, missing)
    for n in present:
        attrs = stored[n]
        blocks += figure_blocks(n, str(attrs["title"]), str(attrs["caption"]),
                                str(attrs["choices"]), f"{FIGURES[n].stem}.png", table[n],
                                float(attrs.get("seconds", np.nan)))
    write_atomic(out / "REPORT.md",
            lambda p: p.write_text(render_markdown(blocks), encoding="utf-8"))
    write_atomic(out / "REPORT.html",
            lambda p: p.write_text(render_html(blocks, out), encoding="utf-8"))
