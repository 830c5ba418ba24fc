"""``fivdisc orbit`` and ``fivdisc lyapunov``: periodic orbits with their Floquet
multipliers, and Lyapunov exponents."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from fivdisc.cli._case import CASE

_NC = click.Path(dir_okay=False, path_type=Path)


def _report(res, case, as_json: bool, out: Path | None) -> None:
    """Print a result (text or JSON) and write it, with its case, to netCDF if asked."""
    from fivdisc.files import write_netcdf

    click.echo(res.to_json() if as_json else str(res))
    if out is not None:
        ds = res.to_dataset()
        ds.attrs["case"] = case.to_toml()
        write_netcdf(out, ds.to_netcdf)


@click.command()
@click.argument("case_file", type=CASE, required=False)
@click.option("--period", type=float, help="A guess of the period [s] (default: the first "
              "close return after the transient); the orbit found is reduced to its "
              "minimal period either way.")
@click.option("--transient", type=float, help="Transient run before the search [s] "
              "(default: the case's simulation.duration).")
@click.option("--from", "from_file", type=click.Path(dir_okay=False, exists=True,
                                                     path_type=Path),
              help="Start from a saved state instead of a transient: an orbit file "
              "(fivdisc orbit -o), a simulation result (its final state) or a branch "
              "(fivdisc continue -o; its last point or --point K, at the key's value "
              "there). Without CASE_FILE, the case stored in the file is used.")
@click.option("--point", type=int,
              help="With --from BRANCH: start from its point K (from 0; negative from the "
              "end).")
@click.option("--window", type=float, default=1.0, show_default=True,
              help="How long to follow the trajectory for its first return [s].")
@click.option("--rtol", type=float, default=1e-12, show_default=True,
              help="Integration tolerance of the shooting runs (sets the multipliers' "
              "accuracy).")
@click.option("--tol", type=float, default=1e-8, show_default=True,
              help="Tolerance of the shooting residual (scaled |phi_T(x) - x| over the "
              "orbit's size). A Newton stall within the integration's own accuracy is "
              "converged at that accuracy (said so); one on a discontinuity of the "
              "shooting map is not, and names the pads whose switches change order.")
@click.option("--symmetric", is_flag=True,
              help="Where the pads are identical and equally spaced (fivdisc orbit prints "
              "the case's symmetry) and the orbit found has a spatio-temporal symmetry "
              "(x(t + T/n) = P x(t): the pads in turn), solve it over T/n with the pads "
              "permuted: n times shorter runs, symmetric by construction; the multipliers "
              "are the full period's.")
@click.option("--json", "as_json", is_flag=True,
              help="Print period, multipliers, verdict and residual as JSON.")
@click.option("-o", "--output", type=_NC, help="Write the orbit to a netCDF file (.nc).")
@click.option("--progress/--no-progress", default=True, show_default=True,
              help="Show the Newton iterations on a terminal.")
def orbit(case_file: Path | None, period: float | None, transient: float | None,
          from_file: Path | None, point: int | None, window: float, rtol: float, tol: float,
          symmetric: bool, as_json: bool, output: Path | None, progress: bool) -> None:
    """Periodic orbit of CASE_FILE (constant speed) and its Floquet multipliers.

    Runs the case for its duration (or --transient), finds the first return of the
    trajectory and refines the orbit by Newton shooting with the exact monodromy matrix
    (saltation matrices at every switch); the orbit is reported at its minimal period.
    CASE_FILE is a TOML file or a packaged example. An orbit that does not converge, or
    whose period is shorter than any motion of the model, is not a result: exit status
    1, with the residual reached.
    """
    from fivdisc.analysis.checks import check_orbit_request, check_period
    from fivdisc.analysis.orbits import periodic_orbit, saved_start
    from fivdisc.case import load_case
    from fivdisc.errors import ConvergenceError, FivdiscError
    from fivdisc.files import check_output

    inputs = [p for p in (case_file, from_file) if p is not None]
    out = check_output(output, "-o", (".nc",), inputs=inputs) if output else None
    guess = phases = None
    start = ""
    case = load_case(case_file) if case_file is not None else None
    if point is not None and from_file is None:
        raise FivdiscError("--point needs --from BRANCH (a file of fivdisc continue -o)")
    if from_file is not None:
        saved = saved_start(from_file, point)
        guess, phases, start = saved.state, saved.phases, saved.start
        case = case or saved.case
        if saved.key and case is not saved.case:
            case = case.replace({saved.key: saved.value})
        period = period if period is not None else saved.period
    if case is None:
        raise FivdiscError("orbit needs CASE_FILE, or --from a file that stores its case")
    check_orbit_request(case, period=period, transient=transient, window=window, rtol=rtol)
    if not (tol > 0 and tol < 1):
        raise FivdiscError(f"--tol = {tol!r} is invalid: must be in (0, 1)")
    try:
        res = periodic_orbit(case, guess, period=period, phases=phases, transient=transient,
                             window=window, rtol=rtol, tol=tol, start=start,
                             progress=progress, symmetric=symmetric)
    except ConvergenceError as exc:
        if as_json and exc.result is not None:
            click.echo(exc.result.to_json())
        click.echo(f"error: {exc}", err=True)
        sys.exit(1)
    try:
        check_period(case, res.period, "the period found")
    except FivdiscError as err:
        click.echo(f"error: no periodic orbit: {err}", err=True)
        sys.exit(1)
    _report(res, case, as_json, out)
    if res.verdict == "unstable" and guess is None and not as_json:
        # The search starts where a transient run ended: near an orbit it passes slowly,
        # which need not be the motion the case settles to.
        spent = case.simulation.duration if transient is None else transient
        click.echo(f"note: this orbit is unstable, so a run leaves it: the transient "
                   f"({spent:g} s) ended near it; a longer --transient may reach the motion "
                   "the case settles to")


@click.command()
@click.argument("case_file", type=CASE)
@click.option("--n", "count", type=int, default=2, show_default=True,
              help="How many exponents (largest first). The second gives the first's "
              "verdict its scale: with --n 1 an exponent near zero stays undecided.")
@click.option("--transient", type=float,
              help="Simulated time before the measurement, over which the tangent vectors "
              "align [s] (default: a fifth of the case's simulation.duration).")
@click.option("--duration", type=float,
              help="Length of the measurement [s] (default: simulation.duration).")
@click.option("--interval", type=float,
              help="Re-orthonormalisation interval [s] (default: 0.05, or the duration "
              "when shorter).")
@click.option("--json", "as_json", is_flag=True,
              help="Print the exponents [1/s], their uncertainty and verdicts as JSON.")
@click.option("-o", "--output", type=_NC,
              help="Write the exponents and their running estimates to netCDF (.nc).")
@click.option("--progress/--no-progress", default=True, show_default=True,
              help="Show a progress bar (on stderr).")
def lyapunov(case_file: Path, count: int, transient: float | None, duration: float | None,
             interval: float | None, as_json: bool, output: Path | None, progress: bool) -> None:
    """Lyapunov exponents of CASE_FILE by the QR method on the tangent dynamics.

    The tangent vectors are carried across every switch by its saltation matrix, and
    through the transient so that they align before the measurement; for --n above 1,
    two sets from independent random starts. Each exponent is printed with its
    uncertainty u (standard error of ten blocks, drift of the estimate and difference
    between the starts) and a verdict: positive or negative (more than 3 u from zero),
    consistent with zero (within u of zero, and resolved from another exponent decided
    non-zero, as the flow direction's 0 of a periodic orbit is from the next), or
    undecided at this length.
    CASE_FILE is a TOML file or a packaged example. Exits with status 0 when the largest
    exponent is decided, 1 when it is undecided (with what would decide it).
    """
    from fivdisc.analysis.exponents import lyapunov as compute
    from fivdisc.case import load_case
    from fivdisc.files import check_output

    case = load_case(case_file)
    out = check_output(output, "-o", (".nc",), inputs=[case_file]) if output else None
    res = compute(case, n=count, transient=transient, duration=duration, interval=interval,
                  progress=progress)
    _report(res, case, as_json, out)
    if not res.decided[0]:
        click.echo(f"error: {res.explain(0)}", err=True)
        sys.exit(1)
