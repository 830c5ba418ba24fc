"""``fivdisc sweep SWEEP.toml -o STORE.zarr`` and ``fivdisc separation-map``."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import click

from fivdisc.cli._case import CASE, default_output

if TYPE_CHECKING:
    from fivdisc.sweep import Sweep, SweepReport

# Shell convention for a command ended by SIGINT (128 + 2).
_EXIT_INTERRUPTED = 130

_scheduler_option = click.option(
    "--scheduler",
    metavar="ADDRESS",
    help="Run on an existing Dask distributed cluster (e.g. tcp://host:8786) "
    "instead of a local process pool.",
)
_workers_option = click.option(
    "--workers",
    type=click.IntRange(min=1),
    help="Processes of the local pool [default: number of CPUs].",
)
_progress_option = click.option(
    "--progress/--no-progress",
    default=True,
    show_default=True,
    help="Show a progress bar (points, failures, time left).",
)


def _run(
    spec: Sweep, output: Path, scheduler: str | None, workers: int | None, progress: bool
) -> SweepReport:
    """Run a sweep into `output`, print what happened; exit 130 on Ctrl-C."""
    from fivdisc.sweep import read_mask, run_sweep

    try:
        report = run_sweep(spec, output, scheduler=scheduler, workers=workers, progress=progress)
    except KeyboardInterrupt:
        done = int(read_mask(output).sum()) if output.exists() else 0
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


@click.command()
@click.argument("sweep_file", type=CASE)
@click.option(
    "-o",
    "--output",
    type=click.Path(path_type=Path),
    help="Zarr store for the results [default: SWEEP_FILE with .zarr; for an example, "
    "NAME.zarr in the working directory]. An existing store of the same sweep is resumed.",
)
@_scheduler_option
@_workers_option
@_progress_option
def sweep(
    sweep_file: Path,
    output: Path | None,
    scheduler: str | None,
    workers: int | None,
    progress: bool,
) -> None:
    """Run the sweep of SWEEP_FILE and store one value per point and reduction.

    SWEEP_FILE is a TOML sweep file or the name of a packaged example, e.g.
    ``fivdisc sweep sweep_fig27 -o fig27.zarr``.

    Results are written as points finish, so an interrupted sweep (Ctrl-C, a killed
    process) continues where it stopped when the same command is run again. A
    point whose run fails is stored with its error message, and the sweep goes on.
    """
    from fivdisc.sweep import load_sweep

    spec = load_sweep(sweep_file)
    _run(spec, output or default_output(sweep_file, ".zarr"), scheduler, workers, progress)


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
    progress: bool,
) -> None:
    """Map where the slider separates from the disc, like the paper's Fig. 27.

    Runs a grid of initial disc speed against time to stop (decelerating disc) or
    against acceleration (accelerating disc), each run ending at its first
    separation, and draws the separation region.
    """
    from fivdisc.case import load_case
    from fivdisc.sweep import plot_separation_map, separation_sweep

    spec = separation_sweep(
        profile,
        x=x_range,
        y=y_range,
        base=load_case(base) if base is not None else None,
        duration=duration,
    )
    output = output or Path(f"separation-{profile}.zarr")
    report = _run(spec, output, scheduler, workers, progress)
    figure = figure or output.with_suffix(".png")
    plot_separation_map(report.store, figure)
    click.echo(f"wrote {figure}")
