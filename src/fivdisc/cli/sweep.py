"""``fivdisc sweep SWEEP.toml -o STORE.zarr``, ``fivdisc separation-map`` and
``fivdisc bifurcation``."""

from __future__ import annotations

import logging
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import click

from fivdisc.cli._case import CASE, default_output
from fivdisc.errors import FivdiscError

if TYPE_CHECKING:
    from fivdisc.sweep import Sweep, SweepReport

# Shell convention for a command ended by SIGINT (128 + 2).
_EXIT_INTERRUPTED = 130
# Damaged points listed by --verify.
_SHOWN_POINTS = 20

_scheduler_option = click.option(
    "--scheduler",
    metavar="ADDRESS",
    help="Run on an existing Dask distributed cluster (e.g. tcp://host:8786) "
    "instead of a local pool.",
)
_workers_option = click.option(
    "--workers",
    type=click.IntRange(min=1),
    help="Threads or processes of the local pool [default: number of CPUs].",
)
# The choices are run's POOLS, written out: importing the sweep engine here would slow
# every command's start.
_pool_option = click.option(
    "--pool",
    type=click.Choice(["thread", "process"]),
    help="The local pool: threads of this process, which start at once and integrate "
    "in parallel (the compiled core releases the GIL), or processes, which keep a point "
    "that crashes its process from ending the sweep [default: thread].",
)
_progress_option = click.option(
    "--progress/--no-progress",
    default=True,
    show_default=True,
    help="Show a progress bar (points, failures, time left).",
)


def _run(
    spec: Sweep, output: Path, scheduler: str | None, workers: int | None, progress: bool,
    pool: str | None = None,
) -> SweepReport:
    """Run a sweep into `output`, print what happened; exit 130 on Ctrl-C."""
    from fivdisc.sweep import run_sweep

    if scheduler is not None:
        _quiet_dask()
    try:
        report = run_sweep(spec, output, scheduler=scheduler, workers=workers,
                           progress=progress, pool=pool)
    except KeyboardInterrupt:
        # Imported here: it loads Zarr, which the first points of a sweep do not wait for.
        from fivdisc.sweep.store.health import read_mask

        try:
            done = int(read_mask(output).sum())
        except FivdiscError:  # interrupted before the store was created
            done = 0
        click.echo(
            f"interrupted: {done} of {spec.n_points} points are stored in {output}; "
            "rerun the same command to compute the rest",
            err=True,
        )
        sys.exit(_EXIT_INTERRUPTED)
    click.echo(
        f"{report.n_points} points: {report.already_done} already stored, "
        f"{report.computed} computed in {report.wall_time:.3g} s; wrote {report.store}"
    )
    if report.failed:
        index, message = min(report.failed.items())
        click.echo(
            f"{len(report.failed)} points failed (see the store's 'error' variable); "
            f"first: point {index}: {message}",
            err=True,
        )
    return report


def _quiet_dask() -> None:
    """Silence dask.distributed's logs: a lost scheduler is reported in one line (a
    SweepError), and the client's own log of it comes with tracebacks."""
    try:
        import distributed  # noqa: F401  (it sets its loggers' levels when imported)
    except ImportError:
        return  # run_sweep says how to install it
    for name in list(logging.root.manager.loggerDict):
        if name.split(".")[0] == "distributed":
            logging.getLogger(name).setLevel(logging.CRITICAL)


def _verify(store: Path) -> None:
    """Report the health of a sweep store; exit 1 if it is damaged."""
    import numpy as np

    from fivdisc.sweep import verify_store

    health = verify_store(store)
    n = health.complete.size
    incomplete = n - int(health.complete.sum()) - int(health.damaged.sum())
    click.echo(
        f"{store}: {n} points: {int(health.complete.sum())} complete and verified "
        f"({int(health.failed.sum())} of them failed runs), {incomplete} not computed, "
        f"{int(health.damaged.sum())} damaged"
    )
    if health.holder is not None:
        click.echo(f"being written by {health.holder}")
    if health.broken:
        click.echo(f"variables with missing or damaged metadata: {', '.join(health.broken)}")
    if health.unflagged is not None and health.unflagged.any():
        click.echo(f"{int(health.unflagged.sum())} complete points lost their done flags "
                   "(their values verify by their checksums; a rerun writes the flags again)")
    if health.damaged.any():
        shown = ", ".join(map(str, np.flatnonzero(health.damaged)[:_SHOWN_POINTS]))
        more = " ..." if health.damaged.sum() > _SHOWN_POINTS else ""
        click.echo(f"damaged points (values lost or not matching their checksums): {shown}{more}")
    if not health.healthy:
        click.echo(
            f"error: {store} is damaged; rerun the sweep that wrote it to rebuild and "
            "recompute what is damaged",
            err=True,
        )
        sys.exit(1)


@click.command()
@click.argument("sweep_file", required=False, type=CASE)
@click.option(
    "-o",
    "--output",
    type=click.Path(path_type=Path),
    help="Zarr store for the results [default: SWEEP_FILE with .zarr; for an example, "
    "NAME.zarr in the working directory]. An existing store of the same sweep is resumed.",
)
@click.option(
    "--verify",
    "verify_store",
    metavar="STORE",
    type=click.Path(file_okay=False, path_type=Path),
    help="Check every point of STORE against its checksum and report the store's health, "
    "instead of running a sweep; exits with 1 if the store is damaged.",
)
@_scheduler_option
@_workers_option
@_pool_option
@_progress_option
def sweep(
    sweep_file: Path | None,
    output: Path | None,
    verify_store: Path | None,
    scheduler: str | None,
    workers: int | None,
    pool: str | None,
    progress: bool,
) -> None:
    """Run the sweep of SWEEP_FILE and store one value per point and reduction.

    SWEEP_FILE is a TOML sweep file or the name of a packaged example, e.g.
    ``fivdisc sweep sweep_fig27 -o fig27.zarr``.

    Results are written as points finish, so an interrupted sweep (Ctrl-C, a killed
    process, a lost cluster) continues where it stopped when the same command is run
    again; points whose stored values no longer match their checksums are recomputed.
    A point whose run fails is stored with its error message, and the sweep goes on.
    One sweep at a time may write a store.
    """
    from fivdisc.extras import require
    from fivdisc.files import ZARR, check_output
    from fivdisc.sweep import load_sweep

    require("distributed", "fivdisc sweep")
    if verify_store is not None:
        if sweep_file is not None or output is not None or scheduler or workers or pool:
            raise click.UsageError("--verify STORE takes no sweep file and no other option")
        _verify(verify_store)
        return
    if sweep_file is None:
        raise click.UsageError("missing SWEEP_FILE (or --verify STORE)")
    spec = load_sweep(sweep_file)
    store = check_output(output or default_output(sweep_file, ".zarr"), "-o", ZARR,
                         inputs=[sweep_file], kind="directory")
    _run(spec, store, scheduler, workers, progress, pool)


@click.command("separation-map")
@click.option(
    "--profile",
    type=click.Choice(["decelerating", "accelerating"]),
    default="decelerating",
    show_default=True,
    help="Disc speed: decelerating to a stop, or accelerating.",
)
@click.option(
    "--x",
    "x_range",
    metavar="START:STOP:N",
    help="Initial disc speed axis [rad/s] [default: 2.0:20.0:40].",
)
@click.option(
    "--y",
    "y_range",
    metavar="START:STOP:N",
    help="Time to stop t_max [s] (decelerating) [default: 1.0:40.0:40], or acceleration c "
    "[rad/s^2] (accelerating) [default: 0.05:2.0:40].",
)
@click.option(
    "--base",
    type=CASE,
    help="Case file or packaged example the points start from [default: the paper's "
    "Fig. 27 case]; its speed table is replaced.",
)
@click.option(
    "--duration",
    type=float,
    help="Simulated time of accelerating runs [s] [default: 20]; decelerating runs last "
    "until the disc stops.",
)
@click.option(
    "-o",
    "--output",
    type=click.Path(path_type=Path),
    help="Zarr store [default: separation-PROFILE.zarr]; an existing one is resumed.",
)
@click.option(
    "--figure",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Image of the map (format from the suffix) [default: the store's name with .png].",
)
@_scheduler_option
@_workers_option
@_pool_option
@_progress_option
def separation_map(
    profile: str,
    x_range: str | None,
    y_range: str | None,
    base: Path | None,
    duration: float | None,
    output: Path | None,
    figure: Path | None,
    scheduler: str | None,
    workers: int | None,
    pool: str | None,
    progress: bool,
) -> None:
    """Map where the slider separates from the disc, like the paper's Fig. 27.

    Runs a grid of initial disc speed against time to stop (decelerating disc) or
    against acceleration (accelerating disc), each run ending at its first
    separation, and draws the separation region.
    """
    from fivdisc.extras import require

    require("distributed", "fivdisc separation-map")
    require("plot", "fivdisc separation-map")
    from fivdisc.case import load_case
    from fivdisc.files import ZARR, check_output, figure_suffixes
    from fivdisc.plots.sweep import plot_separation_map
    from fivdisc.sweep import separation_sweep

    spec = separation_sweep(
        profile,
        x=x_range,
        y=y_range,
        base=load_case(base) if base is not None else None,
        duration=duration,
    )
    store = check_output(output or Path(f"separation-{profile}.zarr"), "-o", ZARR,
                         inputs=[base], kind="directory")
    figure = check_output(figure or store.with_suffix(".png"), "--figure", figure_suffixes(),
                          inputs=[base])
    report = _run(spec, store, scheduler, workers, progress, pool)
    plot_separation_map(report.store, figure)
    click.echo(f"wrote {figure}")


@click.command()
@click.argument("sweep_file", type=CASE)
@click.option(
    "-o",
    "--output",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Image of the diagram (format from the suffix) [default: SWEEP_FILE with .png; "
    "for an example, NAME.png in the working directory].",
)
@click.option(
    "--store",
    type=click.Path(path_type=Path),
    help="Zarr store of the sweep [default: the one `fivdisc sweep SWEEP_FILE` writes, "
    "SWEEP_FILE with .zarr]. Points it lacks are computed first; a complete store is "
    "only drawn.",
)
@click.option(
    "--section",
    metavar="NAME",
    help="The section to draw, by its stored name [default: the sweep file's first "
    "[[reduce.section]]].",
)
@click.option(
    "--branch",
    "branch_file",
    type=click.Path(dir_okay=False, exists=True, path_type=Path),
    help="A branch of periodic orbits in the swept key (fivdisc continue -o) to lay over "
    "the diagram, stable solid and unstable dashed.",
)
@_scheduler_option
@_workers_option
@_pool_option
@_progress_option
def bifurcation(
    sweep_file: Path,
    output: Path | None,
    store: Path | None,
    section: str | None,
    branch_file: Path | None,
    scheduler: str | None,
    workers: int | None,
    pool: str | None,
    progress: bool,
) -> None:
    """Draw the bifurcation diagram of a sweep over one key.

    SWEEP_FILE is a sweep file (or the name of a packaged example, e.g.
    ``fivdisc bifurcation bifurcation-speed -o diagram.png``) with one axis and at least
    one ``[[reduce.section]]``: the section's values at every point are drawn as dots
    over the swept key. If the sweep keeps ``largest_lyapunov``, a second panel below
    shows the exponent. The sweep is run (or resumed) into its store first, as
    ``fivdisc sweep`` does, so an interrupted run continues when the command is rerun.
    """
    from fivdisc.extras import require

    require("distributed", "fivdisc bifurcation")
    require("plot", "fivdisc bifurcation")
    from fivdisc.files import ZARR, check_output, figure_suffixes
    from fivdisc.plots.sweep import plot_bifurcation
    from fivdisc.sweep import load_sweep
    from fivdisc.sweep.bifurcation import check_diagram

    spec = load_sweep(sweep_file)
    chosen = check_diagram(spec, section)
    branch = None
    if branch_file is not None:
        from fivdisc.continuation.branch import open_branch

        branch = open_branch(branch_file)
        swept = next(iter(spec.axes))
        if branch.key != swept:
            raise FivdiscError(f"--branch {branch_file} is continued in {branch.key}, the "
                               f"sweep in {swept}: they cannot share an axis")
        if chosen["variable"] not in ("phi", "phi_dot", "normal_force"):
            raise FivdiscError(f"--branch: a branch keeps phi, phi_dot and normal_force per "
                               f"slider, not the section's variable {chosen['variable']!r}")
    store = check_output(store or default_output(sweep_file, ".zarr"), "--store", ZARR,
                         inputs=[sweep_file], kind="directory")
    figure = check_output(output or default_output(sweep_file, ".png"), "-o",
                          figure_suffixes(), inputs=[sweep_file])
    report = _run(spec, store, scheduler, workers, progress, pool)
    plot_bifurcation(report.store, figure, section=section, name=sweep_file.stem,
                     branch=branch)
    click.echo(f"wrote {figure}")
