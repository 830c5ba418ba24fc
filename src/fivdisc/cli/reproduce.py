"""``fivdisc reproduce [--figures 3,8,27 | --all] -o DIR [--force]``."""

from __future__ import annotations

from pathlib import Path

import click

from fivdisc.errors import FivdiscError


@click.command()
@click.option("--figures", "figures", metavar="LIST",
              help="Figures to reproduce, e.g. 3,8,27 or 8-12 (the paper's Figs. 3-28).")
@click.option("--all", "all_figures", is_flag=True, help="Reproduce every figure (3-28).")
@click.option("-o", "--outdir", required=True, type=click.Path(file_okay=False, path_type=Path),
              help="Directory for figNN.png, figNN.nc, REPORT.md and REPORT.html.")
@click.option("--force", is_flag=True,
              help="Recompute figures that are already up to date in the directory.")
@click.option("--workers", type=int, default=None,
              help="Processes to use (default: at most 2).")
@click.option("--progress/--no-progress", default=True, show_default=True,
              help="Show a progress bar over the figures.")
def reproduce(figures: str | None, all_figures: bool, outdir: Path, force: bool,
              workers: int | None, progress: bool) -> None:
    """Reproduce the paper's figures, with the paper's numbers beside fivdisc's.

    Writes figNN.png and figNN.nc (the data behind the figure) per figure, then
    REPORT.md and a self-contained REPORT.html. Figures already up to date in OUTDIR
    (same parameters) are reused unless --force is given, so an interrupted run
    resumes where it stopped.
    """
    from fivdisc.extras import require
    from fivdisc.files import check_output
    from fivdisc.paper.reproduce import SWEEP_FIGURES, parse_figures
    from fivdisc.paper.reproduce import reproduce as run

    require("plot", "fivdisc reproduce")
    check_output(outdir, "-o", (), kind="directory")
    if all_figures == (figures is not None):
        raise FivdiscError("give either --figures LIST (e.g. --figures 3,8,27) or --all")
    numbers = None if all_figures else parse_figures(figures, "--figures")
    sweeps = [n for n in numbers or SWEEP_FIGURES if n in SWEEP_FIGURES]
    if sweeps:
        require("distributed", f"fivdisc reproduce (Fig. {sweeps[0]}, a sweep)")
    if workers is not None and workers < 1:
        raise FivdiscError(f"--workers = {workers} is invalid: must be >= 1")
    report = run(numbers, outdir, force=force, progress=progress, workers=workers)
    click.echo(f"wrote {report.outdir / 'REPORT.md'} and {report.outdir / 'REPORT.html'}")
    click.echo(f"figures computed: {', '.join(map(str, report.computed)) or 'none'}; "
               f"reused: {', '.join(map(str, report.reused)) or 'none'}; "
               f"wall time {report.wall_time:.0f} s")
