"""``fivdisc simulate CASE.toml -o OUT.nc``."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from fivdisc.cli._case import CASE, default_output


@click.command()
@click.argument("case_file", type=CASE)
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="netCDF file for the result [default: CASE_FILE with .nc; for an example, "
              "NAME.nc in the working directory].")
@click.option("--progress/--no-progress", default=True, show_default=True,
              help="Show a progress bar in simulated time.")
def simulate(case_file: Path, output: Path | None, progress: bool) -> None:
    """Simulate CASE_FILE and write the time histories and events as netCDF.

    CASE_FILE is a TOML case file or the name of a packaged example (``fivdisc examples``),
    e.g. ``fivdisc simulate fig10 -o fig10.nc``.

    A failed run (non-finite state, step-size underflow, endless switching) still
    writes what was computed, marked as failed, and exits with status 1.
    """
    from fivdisc.case import load_case
    from fivdisc.files import NETCDF, check_output
    from fivdisc.simulate import simulate as run
    from fivdisc.warmup import warm_up

    case = load_case(case_file)
    out = check_output(output or default_output(case_file, ".nc"), "-o", NETCDF,
                       inputs=[case_file])
    imported = warm_up("xarray", "netcdf")
    result = run(case, progress=progress).named(case_file.stem)
    imported()
    result.to_netcdf(out)
    click.echo(f"wrote {out}")
    for line in result.summary().lines()[1:]:
        click.echo(line)
    if not result.ok:
        click.echo(f"error: simulation failed: {result.message}", err=True)
        sys.exit(1)
