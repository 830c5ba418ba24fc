"""``fivdisc simulate CASE.toml -o OUT.nc``."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import click

from fivdisc.cli._case import CASE, default_output


@click.command()
@click.argument("case_file", type=CASE, required=False)
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="netCDF file for the result [default: CASE_FILE with .nc; for an example, "
              "NAME.nc in the working directory; with --from only, FILE's name with "
              "-continued.nc].")
@click.option("--from", "from_file", type=click.Path(dir_okay=False, exists=True,
                                                     path_type=Path),
              help="Start from a saved state instead of simulation.initial_state: a "
              "simulation result (its final state), an orbit (fivdisc orbit -o) or a branch "
              "(fivdisc continue -o; its last point or --point K, at the key's value "
              "there). Without CASE_FILE, the case stored in the file is used.")
@click.option("--point", type=int,
              help="With --from BRANCH: start from its point K (from 0; negative from the "
              "end).")
@click.option("--at", "at_value", type=float,
              help="With --from BRANCH: run at this value of the branch's key instead of "
              "the point's (a forward run past a branch's end from its last orbit).")
@click.option("--progress/--no-progress", default=True, show_default=True,
              help="Show a progress bar in simulated time.")
def simulate(case_file: Path | None, output: Path | None, from_file: Path | None,
             point: int | None, at_value: float | None, progress: bool) -> None:
    """Simulate CASE_FILE and write the time histories and events as netCDF.

    CASE_FILE is a TOML case file or the name of a packaged example (``fivdisc examples``),
    e.g. ``fivdisc simulate fig10 -o fig10.nc``. With --from FILE the run starts from the
    state FILE holds (its case's simulation.initial_state is not used; the output says
    so), and CASE_FILE may be left out.

    A failed run (non-finite state, step-size underflow, endless switching) still
    writes what was computed, marked as failed, and exits with status 1. If the output
    cannot be written (a full disk), the run is written to the system's temporary
    directory instead, where that is possible, and the one-line error names both.
    """
    from fivdisc.case import load_case
    from fivdisc.engine.preload import warm_up
    from fivdisc.engine.simulation import simulate as run
    from fivdisc.errors import FivdiscError
    from fivdisc.files import NETCDF, check_output

    for option, given in (("--point", point), ("--at", at_value)):
        if given is not None and from_file is None:
            raise FivdiscError(f"{option} needs --from BRANCH (a file of fivdisc continue -o)")
    case = load_case(case_file) if case_file is not None else None
    initial = phases = None
    notes = []
    if from_file is not None:
        from fivdisc.analysis.orbits import saved_start

        saved = saved_start(from_file, point)
        if at_value is not None and not saved.key:
            raise FivdiscError(f"--at needs --from BRANCH: {from_file} holds no branch")
        if case is None:
            case = saved.case
        if saved.key:
            value = saved.value if at_value is None else at_value
            given = case.get(saved.key)
            case = case.replace({saved.key: value})
            if at_value is not None:
                notes.append(f"run at {saved.key} = {value:.9g}, not the point's "
                             f"{saved.value:.9g} (--at)")
            elif case_file is not None and given != value:
                notes.append(f"run at {saved.key} = {value:.9g}, the branch point's, not "
                             f"CASE_FILE's {given:.9g} (--at VALUE runs the point's state "
                             "at another value)")
        initial, phases = saved.state, saved.phases
    if case is None:
        raise FivdiscError("simulate needs CASE_FILE, or --from a file that stores its case")
    inputs = [p for p in (case_file, from_file) if p is not None]
    name = case_file if case_file is not None else from_file.with_name(
        from_file.stem + "-continued.nc")
    out = check_output(output or default_output(name, ".nc"), "-o", NETCDF, inputs=inputs)
    imported = warm_up("netcdf")
    result = run(case, initial=initial, phases=phases, progress=progress).named(name.stem)
    imported()
    _save(result, out)
    click.echo(f"wrote {out}")
    if from_file is not None:
        click.echo(f"started {saved.start} (simulation.initial_state is not used)")
    for note in notes:
        click.echo(f"note: {note}")
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
