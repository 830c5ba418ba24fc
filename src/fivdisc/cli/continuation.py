"""``fivdisc continue``: a branch of periodic orbits followed in one case key, with its
bifurcations."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import click

from fivdisc.analysis.kinds import CURVE_CONDITIONS
from fivdisc.cli._case import CASE
from fivdisc.continuation.settings import ContinuationSettings
from fivdisc.errors import FivdiscError

_DEFAULT = ContinuationSettings()
# How the first orbit's search options are named in messages.
_SEARCH_OPTIONS = ("--period", "--transient", "the search window", "--rtol")


@click.command(name="continue")
@click.argument("case_file", type=CASE, required=False)
@click.option("--key", required=True,
              help="The numeric case key to continue in (speed.value, slider.normal_damping, "
              "sliders.1.preload, friction.decay, disc.damping_ratio, ...).")
@click.option("--to", "target", type=float,
              help="The key's value where the continuation stops [the key's unit]; its side "
              "of the case's value sets the direction. Required, except with --key2.")
@click.option("--back-to", "back_to", type=float,
              help="The other end of the window [the key's unit]: a branch that turns at a "
              "fold stops where the key comes back past it (default: the start's value). "
              "Give a value beyond the orbits' range to follow a closed branch round.")
@click.option("--from", "from_file", type=click.Path(dir_okay=False, exists=True,
                                                     path_type=Path),
              help="Start from a file instead of the case's orbit: an orbit (fivdisc orbit "
              "-o), a simulation result (its final state) or a branch (fivdisc continue -o; "
              "its last point, --point K or --bifurcation K). Without CASE_FILE, the case "
              "stored in the file is used.")
@click.option("--bifurcation", "which", type=int,
              help="With --from BRANCH: start at its bifurcation K (from 0); at a period "
              "doubling, continue the branch of doubled orbits born there, at a symmetry "
              "breaking the branch of the orbits that break the symmetry.")
@click.option("--point", type=int,
              help="With --from BRANCH: start at its point K (from 0; negative from the end; "
              "default: the last), at the key's value there.")
@click.option("--from-hopf", "hopf_spec", metavar="START:STOP:N",
              help="Start from the orbits born at a Hopf point of the sliding equilibrium "
              "in --key, searched on N values from START to STOP: the first where the "
              "equilibrium changes stability, else the first found, with a warning (its "
              "orbits are unstable). Says which it takes, whether it is sub- or "
              "supercritical and the bistable range.")
@click.option("--key2", help="With --from BRANCH --bifurcation K: follow the bifurcation in "
              "two keys, --key solved for as this second key goes --to2 a value (a curve of "
              "--curve-points points, each with its shooting residual and the defining "
              "condition's value).")
@click.option("--to2", type=float, help="Where the curve in --key2 ends [its unit].")
@click.option("--condition", type=click.Choice([str(k) for k in CURVE_CONDITIONS]),
              help="The defining condition the curve follows (default: the bifurcation's "
              "kind); needed where a branch ends at a border, e.g. 'grazing' where the "
              "stick phase of a stick-slip orbit vanishes.")
@click.option("--curve-points", type=int, default=50, show_default=True,
              help="Points on the --key2 curve, evenly spaced in --key2.")
@click.option("--points", type=int, default=_DEFAULT.max_points, show_default=True,
              help="Most points on the branch.")
@click.option("--step", type=float, default=_DEFAULT.step, show_default=True,
              help="First arclength step (relative change of the orbit, period and key).")
@click.option("--max-step", type=float, default=_DEFAULT.max_step, show_default=True,
              help="Largest arclength step.")
@click.option("--transient", type=float,
              help="Transient run before the first orbit is searched [s] (default: the "
              "case's simulation.duration).")
@click.option("--period", type=float, help="A guess of the first orbit's period [s].")
@click.option("--rtol", type=float, default=_DEFAULT.rtol, show_default=True,
              help="Integration tolerance of the shooting runs.")
@click.option("--tol", type=float, default=_DEFAULT.tol, show_default=True,
              help="Tolerance of the shooting residual (scaled |phi_T(x) - x| over the "
              "orbit's size), of the first orbit and of every point.")
@click.option("--json", "as_json", is_flag=True,
              help="Print the points and bifurcations as JSON.")
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="Write the branch to a netCDF file (.nc), for fivdisc plot.")
@click.option("--progress/--no-progress", default=True, show_default=True,
              help="Show the Newton iterations and the points on a terminal.")
def continuation(case_file: Path | None, key: str, target: float | None, back_to: float | None,
                 from_file: Path | None, which: int | None, point: int | None,
                 hopf_spec: str | None, key2: str | None, to2: float | None,
                 condition: str | None, curve_points: int, points: int, step: float,
                 max_step: float,
                 transient: float | None, period: float | None, rtol: float, tol: float,
                 as_json: bool,
                 output: Path | None, progress: bool) -> None:
    """Follow a periodic orbit of CASE_FILE (constant speed) as --key goes --to a value.

    Pseudo-arclength continuation of the shooting equations, with the exact monodromy
    across every switch: each point's period, event signature, Floquet multipliers and
    amplitude measures; folds, period doublings, torus bifurcations and changes of the
    event signature (stick phases appearing, grazing, ...) located to 1e-6 in the key.
    CASE_FILE is a TOML file or a packaged example. Ctrl-C stops the continuation and
    writes the branch so far.
    """
    if key2 is not None or to2 is not None or condition is not None:
        _curve(case_file, key, from_file, which, key2, to2, condition, curve_points, rtol, tol,
               as_json, output, progress)
        return
    if target is None:
        raise FivdiscError("--to VALUE is needed: the key's value where the continuation "
                           "stops")
    with _interrupts_wait_for_the_branch():
        _continue(case_file, key, target, back_to, from_file, which, point, hopf_spec, points,
                  step, max_step, transient, period, rtol, tol, as_json, output, progress)


def _curve(case_file: Path | None, key: str, from_file: Path | None, which: int | None,
           key2: str | None, to2: float | None, condition: str | None, curve_points: int,
           rtol: float, tol: float, as_json: bool, output: Path | None,
           progress: bool) -> None:
    """``--key2``: a bifurcation of a branch followed in two keys; the curve printed
    (every point with its residuals) and written."""
    import json

    from fivdisc.case import load_case
    from fivdisc.continuation.branch import open_branch
    from fivdisc.continuation.checks import full_key
    from fivdisc.continuation.codim2 import curve_from_branch
    from fivdisc.errors import FivdiscError
    from fivdisc.files import check_output

    if key2 is None or to2 is None:
        raise FivdiscError("a curve in two keys needs --key2 KEY and --to2 VALUE (with --from "
                           "BRANCH --bifurcation K)")
    if from_file is None or which is None:
        raise FivdiscError("--key2 follows a bifurcation of a branch: give --from BRANCH "
                           "(a file of fivdisc continue -o) and --bifurcation K")
    key, key2 = full_key(key, "--key"), full_key(key2, "--key2")
    inputs = [p for p in (case_file, from_file) if p is not None]
    out = check_output(output, "-o", (".nc",), inputs=inputs) if output else None
    if isinstance(curve_points, bool) or curve_points < 2:
        raise FivdiscError(f"--curve-points = {curve_points!r} is invalid: must be an "
                           "integer >= 2")
    branch = open_branch(from_file)
    if branch.key != key:
        raise FivdiscError(f"--key {key} differs from the branch's key {branch.key}: the curve "
                           "solves for the branch's own key")
    if case_file is not None:
        # the case given replaces the stored one (the same system, other settings)
        branch.dataset.attrs["case"] = load_case(case_file).to_toml()
    settings = _DEFAULT.replace(rtol=rtol, tol=tol)
    curve = curve_from_branch(branch, which, key2, to2, condition=condition,
                              points=curve_points, settings=settings, progress=progress)
    if out is not None:
        curve.to_netcdf(out)
    if as_json:
        click.echo(json.dumps({"kind": curve.kind, "key": curve.key, "key2": curve.key2,
                               "stop_reason": curve.stop_reason,
                               "points": [{"value": float(p), "value2": float(q),
                                           "period": float(t), "residual": float(r),
                                           "condition": float(g)}
                                          for p, q, t, r, g in zip(
                                              curve.parameter, curve.second_parameter,
                                              curve.period, curve.dataset["residual"].values,
                                              curve.condition, strict=True)]}, indent=2))
    else:
        click.echo(str(curve))
    if len(curve) < 2:
        sys.exit(1)


@contextmanager
def _interrupts_wait_for_the_branch() -> Iterator[None]:
    """The first Ctrl-C stops the continuation, which keeps the branch so far; a second
    one, while that branch is being finished and written, is refused with a note (it
    would lose the branch); a third quits without it."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    count = 0

    def interrupted(signum, frame) -> None:
        nonlocal count
        count += 1
        if count == 2:
            click.echo("interrupted again: the branch so far is being written; Ctrl-C once "
                       "more quits without it", err=True)
            return
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGINT, interrupted)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _continue(case_file: Path | None, key: str, target: float, back_to: float | None,
              from_file: Path | None, which: int | None, point: int | None,
              hopf_spec: str | None, points: int, step: float, max_step: float,
              transient: float | None, period: float | None, rtol: float, tol: float,
              as_json: bool, output: Path | None, progress: bool) -> None:
    from fivdisc.continuation.checks import check_key, check_window, full_key
    from fivdisc.continuation.settings import INTERRUPTED
    from fivdisc.continuation.walk import continue_orbit
    from fivdisc.errors import ConvergenceError, FivdiscError
    from fivdisc.files import check_output

    # A key's last part alone (normal_damping), as fivdisc stability takes it.
    key = full_key(key, "--key")
    inputs = [p for p in (case_file, from_file) if p is not None]
    out = check_output(output, "-o", (".nc",), inputs=inputs) if output else None
    if which is not None and from_file is None:
        raise FivdiscError("--bifurcation needs --from BRANCH (a file of fivdisc continue -o)")
    try:
        settings = _DEFAULT.replace(max_points=points, step=step, max_step=max_step, rtol=rtol,
                                    tol=tol)
    except FivdiscError as exc:
        # The settings name their fields; the message names the option given.
        name, _, rest = str(exc).partition(" = ")
        option = {"max_points": "--points", "max_step": "--max-step"}.get(name, f"--{name}")
        raise FivdiscError(f"{option} = {rest}") from None
    if hopf_spec is not None:
        if (from_file is not None or transient is not None or period is not None
                or back_to is not None or point is not None):
            raise FivdiscError("--from-hopf starts at a Hopf point: leave out --from, "
                               "--point, --transient, --period and --back-to")
        branch = _from_hopf(case_file, key, target, hopf_spec, settings, progress, as_json)
        if out is not None:
            branch.to_netcdf(out)
        click.echo(branch.to_json() if as_json else str(branch))
        sys.exit(130 if branch.stop_reason == INTERRUPTED else 1 if branch.lost else 0)
    orbit = None
    try:
        case, orbit, along, search, source = _start(case_file, from_file, which, point, key,
                                                    target, rtol, tol, transient, period)
        if back_to is not None:
            check_window(key, check_key(case, key), target, back_to, "--back-to")
        branch = continue_orbit(case, key, target, orbit=orbit, along=along,
                                back_to=back_to, settings=settings, progress=progress,
                                **search)
    except ConvergenceError as exc:
        if orbit is not None and orbit.start.startswith("at the symmetry breaking"):
            # A Neimark-Sacker crossing of the reduced map near a resonance gives tori,
            # and orbits without the symmetry exist near it only where this converges.
            click.echo(f"error: no orbit without the symmetry converges {orbit.start} "
                       f"({exc}): the motions born there need not be periodic (a "
                       "Neimark-Sacker bifurcation of the reduced map near a resonance "
                       "gives tori drifting through the orbit's images); a forward run "
                       "(fivdisc simulate --from BRANCH --point K) shows them", err=True)
            sys.exit(1)
        click.echo(f"error: no periodic orbit to start from: {exc}", err=True)
        sys.exit(1)
    if source is not None:
        from fivdisc.continuation.from_hopf import restate_hopf

        # The same orbits, on from a branch born at a Hopf point: its kind and the
        # bistable range over both.
        restate_hopf(branch, source)
    if out is not None:
        branch.to_netcdf(out)
    click.echo(branch.to_json() if as_json else str(branch))
    if branch.stop_reason == INTERRUPTED:
        sys.exit(130)
    if branch.lost:
        sys.exit(1)


def _from_hopf(case_file: Path | None, key: str, target: float, spec: str,
               settings: ContinuationSettings, progress: bool, as_json: bool = False):
    """The branch of orbits from the first Hopf point on ``spec``'s values of ``key``
    (which one, on stdout, or on stderr under --json, whose stdout is the JSON)."""
    import numpy as np

    from fivdisc.analysis.eigenbranches import branch_bytes
    from fivdisc.analysis.hopf import hopf_points
    from fivdisc.case import Case, load_case
    from fivdisc.continuation.from_hopf import hopf_cycles
    from fivdisc.errors import CaseError, FivdiscError
    from fivdisc.limits import check_memory

    usage = f"--from-hopf = {spec!r} is invalid: write START:STOP:N (N >= 2 values of {key})"
    try:
        start, stop, num = spec.split(":")
        count = int(num)
        # The size of the scan, before its values are made.
        check_memory(branch_bytes(load_case(case_file) if case_file else Case()) * count,
                     f"--from-hopf with N = {count} values", "lower N")
        values = np.linspace(float(start), float(stop), count)
    except ValueError:
        raise FivdiscError(usage) from None
    if values.size < 2 or not np.all(np.isfinite(values)) or values[0] == values[-1]:
        raise FivdiscError(usage)
    case = _checked(load_case(case_file) if case_file else Case(), key, target)
    for value in values[[0, -1]]:
        try:
            case.replace({key: float(value)})
        except CaseError as exc:
            raise CaseError(f"--from-hopf = {spec!r} is invalid: its end {value:g} is not a "
                            f"value of {key} ({exc})") from None
    found = hopf_points(case, key, values, option="--key")
    if not found:
        raise FivdiscError(f"--from-hopf {spec}: no Hopf point of the sliding equilibrium in "
                           f"{key} between {values[0]:g} and {values[-1]:g}")
    hopf = next((h for h in found if h.on_boundary), found[0])
    click.echo(hopf_choice(found, hopf, key, values), err=as_json)
    if not hopf.on_boundary:
        others = ", ".join(hopf.unstable_modes) or "another mode"
        click.echo(f"warning: at {key} = {hopf.value:.10g} {others} of the sliding "
                   "equilibrium stay unstable: every orbit born there is unstable, and "
                   "no Hopf point between "
                   f"{values[0]:g} and {values[-1]:g} changes the equilibrium's stability "
                   "(widen START:STOP to find one)", err=True)
    return hopf_cycles(hopf, target, settings=settings, progress=progress)


def hopf_choice(found, hopf, key: str, values) -> str:
    """Which of the Hopf points `found` on `values` of `key` is taken, and why: the
    points listed (numbered from 0) when there are several."""
    lines = []
    if len(found) > 1:
        lines.append(f"{len(found)} Hopf points in {key} between {values[0]:g} and "
                     f"{values[-1]:g}:")
        lines += [f"  [{k}] {h}" for k, h in enumerate(found)]
    k = found.index(hopf)
    why = ("the first where the equilibrium changes stability" if hopf.on_boundary
           else "the first found: none changes the equilibrium's stability")
    lines.append(f"taking [{k}]: {hopf} ({why})" if len(found) > 1
                 else f"taking the {hopf} ({why})")
    return "\n".join(lines)


def _checked(case, key: str, target: float):
    """The case, once its key and the target are known to be valid."""
    from fivdisc.continuation.checks import check_key
    from fivdisc.errors import CaseError, FivdiscError

    if case.speed.profile != "constant":
        raise FivdiscError(f"continue needs a constant disc speed (speed.profile = "
                           f"'constant'), not {case.speed.profile!r}: with a varying speed "
                           "the system is not autonomous and has no periodic orbits")
    check_key(case, key, "--key")
    try:
        case.replace({key: target})
    except CaseError as exc:
        raise CaseError(f"--to {target!r} is invalid for {key}: {exc}") from None
    return case


def _start(case_file, from_file, which, point, key, target, rtol, tol, transient, period):
    """The case, the orbit to start from (None: searched as fivdisc orbit does), the
    branch-switching direction, the search's options, and the branch whose orbits the
    new one continues (None unless from a branch, at one of its points or at a
    bifurcation other than a period doubling or a symmetry breaking); the key and the
    target are checked before any orbit is computed."""
    from fivdisc.analysis.checks import check_period, check_time
    from fivdisc.analysis.kinds import BifurcationKind as Kind
    from fivdisc.analysis.orbits import periodic_orbit, saved_start
    from fivdisc.case import load_case
    from fivdisc.continuation.branch import CONTENT, open_branch
    from fivdisc.continuation.checks import check_search
    from fivdisc.continuation.starts import broken_start, doubled_start
    from fivdisc.errors import FivdiscError

    case = load_case(case_file) if case_file is not None else None
    search = {"transient": transient, "period": period}
    if from_file is None:
        if case is None:
            raise FivdiscError("continue needs CASE_FILE or --from FILE")
        if point is not None:
            raise FivdiscError("--point needs --from BRANCH (a file of fivdisc continue -o)")
        case = _checked(case, key, target)
        check_search(case, search, rtol, _SEARCH_OPTIONS)
        return case, None, None, search, None
    from fivdisc.files import read_dataset

    if read_dataset(from_file, "--from").attrs.get("content") == CONTENT:
        br = open_branch(from_file)
        if br.key != key:
            raise FivdiscError(f"--key {key} differs from the branch's key {br.key}: a branch "
                               "is continued in its own key")
        if which is None:
            saved = saved_start(from_file, point)
            case = _checked(case or saved.case, key, target).replace({key: saved.value})
            orbit = periodic_orbit(case, saved.state, period=saved.period,
                                   phases=saved.phases, rtol=rtol, tol=tol,
                                   start=saved.start)
            return case, orbit, None, {}, br
        if point is not None:
            raise FivdiscError("--point and --bifurcation both name where on the branch to "
                               "start: give one")
        case = case or br.case
        bifs = br.bifurcations()
        if not 0 <= which < len(bifs):
            raise FivdiscError(f"--bifurcation {which} is invalid: the branch has "
                               f"{len(bifs)} bifurcation(s), numbered from 0")
        b = bifs[which]
        value, state, per, kind = b["parameter"], b["state"], b["period"], b["kind"]
        phases = b["phases"]
        case = _checked(case, key, target).replace({key: value})
        if kind == Kind.PERIOD_DOUBLING:
            orbit, along = doubled_start(case, state, per, phases, rtol=rtol)
            return case, orbit, along, {}, None
        if kind == Kind.SYMMETRY_BREAKING:
            orbit, along = broken_start(case, state, per, phases, b, rtol=rtol)
            return case, orbit, along, {}, None
        orbit = periodic_orbit(case, state, period=per, phases=phases, rtol=rtol, tol=tol,
                               start=f"from bifurcation {which} of the branch in {from_file}")
        return case, orbit, None, {}, br
    saved = saved_start(from_file, point)
    case = case or saved.case
    if case is None:
        raise FivdiscError(f"--from {from_file} stores no case: give CASE_FILE")
    _checked(case, key, target)
    if period is not None:  # no transient: the search starts from the file's state
        check_time("--period", period)
        check_period(case, period, "--period")
    orbit = periodic_orbit(case, saved.state, period=period or saved.period,
                           phases=saved.phases, rtol=rtol, tol=tol, start=saved.start)
    return case, orbit, None, {}, None
