"""``fivdisc simulate CASE.toml -o OUT.nc``."""

from __future__ import annotations

import sys
from pathlib import Path

import click


@click.command()
@click.argument("case_file", type=click.Path(dir_okay=False, path_type=Path))
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="netCDF file for the result (default: CASE with .nc).")
@click.option("--progress/--no-progress", default=True, show_default=True,
              help="Show a progress bar in simulated time.")
def simulate(case_file: Path, output: Path | None, progress: bool) -> None:
    """Simulate CASE_FILE and write the time histories and events as netCDF.

    A failed run (non-finite state, step-size underflow, endless switching) still
    writes what was computed, marked as failed, and exits with status 1.
    """
    from fivdisc.case import load_case
    from fivdisc.files import NETCDF, check_output
    from fivdisc.simulate import simulate as run

    case = load_case(case_file)
    out = check_output(output or case_file.with_suffix(".nc"), "-o", NETCDF, inputs=[case_file])
    result = run(case, progress=progress)
    result.to_netcdf(out)
    s = result.summary()
    phases = ", ".join(f"{k} {v:.4g} s" for k, v in s["time_in_phase"].items())
    click.echo(f"wrote {out}")
    click.echo(f"time in phase: {phases}")
    click.echo(f"switches: {s['switches']}, separations: {s['separations']}, "
               f"impacts: {s['impacts']}")
    click.echo(f"peak normal force: {s['peak_normal_force']:.6g} N, "
               f"largest |w| at probes: {s['max_abs_w']:.6g} m, wall time: {s['wall_time']:.3g} s")
    if not result.ok:
        click.echo(f"error: simulation failed: {result.message}", err=True)
        sys.exit(1)
