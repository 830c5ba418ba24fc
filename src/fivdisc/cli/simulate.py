"""``fivdisc simulate CASE.toml -o OUT.nc``."""

from __future__ import annotations

import os
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
    writes what was computed, marked as failed, and exits with status 1. If the output
    cannot be written (a full disk), the run is written to the system's temporary
    directory instead, where that is possible, and the one-line error names both.
    """
    from fivdisc.case import load_case
    from fivdisc.engine.preload import warm_up
    from fivdisc.engine.simulation import simulate as run
    from fivdisc.files import NETCDF, check_output

    case = load_case(case_file)
    out = check_output(output or default_output(case_file, ".nc"), "-o", NETCDF,
                       inputs=[case_file])
    imported = warm_up("netcdf")
    result = run(case, progress=progress).named(case_file.stem)
    imported()
    _save(result, out)
    click.echo(f"wrote {out}")
    for line in result.summary().lines()[1:]:
        click.echo(line)
    if not result.ok:
        click.echo(f"error: simulation failed: {result.message}", err=True)
        sys.exit(1)


def _save(result, out: Path) -> None:
    """Write `result` to `out`; if that fails (e.g. a full disk), keep the computed run in
    the temporary directory if it fits there, and end with one line saying where."""
    import tempfile

    from fivdisc.files import OutputError

    try:
        result.to_netcdf(out)
    except OutputError as exc:
        kept = Path(tempfile.gettempdir()) / f"fivdisc-{out.stem}-{os.getpid()}.nc"
        if kept.parent.resolve() == out.parent.resolve():
            raise OutputError(f"{exc}; the run is lost: free space and run again") from None
        try:
            result.to_netcdf(kept)
        except OutputError:
            raise OutputError(f"{exc}; the run is lost (it could not be written to {kept} "
                              "either): free space and run again") from None
        raise OutputError(f"{exc}; the run is kept in {kept}: move it to {out} when space "
                          "is freed") from None
