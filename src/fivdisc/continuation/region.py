"""The bistable region in two keys: where stable sliding and a stable stick-slip
vibration coexist.

Complex eigenvalue analysis says where steady sliding is unstable; past a subcritical
Hopf point sliding is stable and a large enough disturbance still starts a vibration.
:func:`bistable_region` maps that region in a box of two keys (``x``, ``y``):

1. the Hopf curves of the sliding equilibrium in the box, with their first Lyapunov
   coefficients and Bautin points (:func:`~fivdisc.analysis.codimension.hopf_curves`);
2. at one value of ``y`` (the case's, if inside the box), the Hopf point on the stability
   boundary along ``x``, which must be subcritical;
3. the stable vibration there: the orbit a forward run settles on (after 675 periods of
   the Hopf oscillation) when the slider starts stuck to the disc (the largest kick) on
   the equilibrium's stable side of the Hopf point,
   continued along ``x`` (:func:`~fivdisc.continuation.walk.continue_orbit`) to where it
   ends or loses stability: a fold of cycles, or a grazing (its stick phase vanishes,
   where it meets the unstable orbits from the Hopf point);
4. that end followed in ``y`` across the box both ways
   (:func:`~fivdisc.continuation.codim2.bifurcation_curve`; an end at a border where the
   flow map jumps, which no defining condition describes, by a one-parameter walk at
   each value of ``y``); optionally also the threshold orbits' end (the unstable orbits
   born at the Hopf point, where they graze the stick boundary or fold);
5. on a grid, the equilibrium's stability (:func:`~fivdisc.analysis.stability.stability_map`)
   and, where it is stable, whether the point lies on the vibration's side of its end:
   *sliding unstable*, *bistable* or *sliding only*.

The vibration is assumed to persist from the end back across the box to the Hopf curve
and beyond (the branch is followed from its start to its end only): forward runs check
it (the tests, and the tutorial).
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

import numpy as np

from fivdisc.analysis.kinds import BifurcationKind as Kind
from fivdisc.case import Case
from fivdisc.continuation.branch import Branch
from fivdisc.continuation.settings import ContinuationSettings
from fivdisc.errors import CaseError, ConvergenceError, FivdiscError

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["REGIONS", "bistable_region"]

#: The region codes of :func:`bistable_region`'s grid.
REGIONS = {-1: "undetermined", 0: "sliding stable only", 1: "bistable",
           2: "sliding unstable"}
# Where along the stable side, from the Hopf point towards the box's far end, the forward
# runs that look for the vibration start (fractions of the way), in turn.
_TRIES = (0.3, 0.5, 0.15, 0.7)
# The transient before the search for the vibration's orbit, in periods of the Hopf
# point's oscillation (3 s at 225 Hz: the stick-slip of three pads settles within it).
_TRANSIENT = 675
# The branch kinds that end the stable vibration, and the condition each is followed by.
# None: a border where the flow map jumps, located by one-parameter walks (_by_walks).
_ENDS = {Kind.FOLD: Kind.FOLD, Kind.GRAZING: Kind.GRAZING,
         Kind.SIGNATURE_CHANGE: Kind.GRAZING, Kind.STICK_SPLIT: Kind.STICK_SPLIT,
         Kind.END: Kind.GRAZING, Kind.DISCONTINUITY: None, Kind.DISCONTINUITY_END: None,
         Kind.CASCADE_END: None}


def bistable_region(
    case: Case,
    x: tuple[str, tuple[float, float]],
    y: tuple[str, tuple[float, float]],
    *,
    points: int = 12,
    grid: tuple[int, int] = (41, 21),
    threshold: bool = False,
    seeds: int = 6,
    vibration: Branch | None = None,
    settings: ContinuationSettings | None = None,
    progress: bool = False,
) -> xr.Dataset:
    """The region of two keys where stable sliding and a stable vibration coexist.

    Parameters
    ----------
    case : Case
        A constant-speed case.
    x, y : (str, (float, float))
        Dotted case key and (start, stop) of each side of the box; ``x`` is the key the
        orbits are continued in (the disc speed, typically).
    points : int
        Points of each curve followed in ``y`` from the case's value to each side of the
        box (>= 2).
    grid : (int, int)
        Values of ``x`` and ``y`` of the grid the regions are shaded on.
    threshold : bool
        Also follow the end of the unstable orbits born at the Hopf point (their
        grazing or fold; below it they are the threshold a kick must cross).
    seeds : int
        Seed lines per side of :func:`~fivdisc.analysis.codimension.hopf_curves`.
    vibration : Branch, optional
        The stable vibration's branch in ``x`` at the case's value of ``y``
        (:func:`~fivdisc.continuation.walk.continue_orbit` of a stable stick-slip orbit,
        followed to its end), instead of the one found from a stuck start: where several
        stable vibrations coexist, each has its own region.
    settings : ContinuationSettings, optional
        Tolerances and budgets of the continuations.
    progress : bool
        Say what is being done, on stderr.

    Returns
    -------
    xarray.Dataset
        Dimensions named after the two keys (the grid) with ``region`` (codes of
        :data:`REGIONS`) and ``max_growth_rate`` [1/s]; dimension ``curve_point`` with
        ``curve_x``, ``curve_y``, ``curve`` (index), ``curve_period`` [s],
        ``curve_residual`` (shooting) and ``curve_condition`` (the defining condition);
        dimension ``curve`` with ``curve_kind`` (fold or grazing), ``curve_role``
        (``"vibration end"``, ``"threshold end"``) and ``curve_stop``; dimension
        ``hopf_point`` with ``hopf_x``, ``hopf_y``, ``hopf_curve``, ``hopf_l1`` [s^2],
        ``hopf_on_boundary``; dimension ``special`` with ``special_kind`` (Bautin, double
        Hopf, ...), ``special_x``, ``special_y``. Attributes ``x_key``, ``y_key``,
        ``x_range``, ``y_range``, ``y_start`` (the value of ``y`` the orbits were found
        at), ``hopf_value``, ``vibration`` (the vibration's orbit in words),
        ``vibration_end`` (its end at ``y_start``, in words), ``seconds`` and the case.

    Raises
    ------
    CaseError
        Keys or ranges that are not valid, too few points.
    FivdiscError
        No Hopf point on the stability boundary along ``x`` at ``y_start``, or one that
        is not subcritical (no bistability begins there), or no stable vibration found.

    See Also
    --------
    fivdisc.hopf_curves : The Hopf curves alone.
    fivdisc.bifurcation_curve : One bifurcation of orbits in two keys.
    fivdisc.plots.plot_bistable_region : Draws the result.

    Notes
    -----
    A grid point is *bistable* where the largest growth rate of the equilibrium is
    negative and the point lies between the Hopf curve and the vibration's end curve,
    i.e. ``(x - x_end(y)) s < 0`` with ``s`` the side the end lies on from the Hopf
    point at ``y_start``; ``x_end(y)`` is interpolated linearly between the curve's
    points, and outside the ``y`` the curve reached the region is *undetermined*.

    Examples
    --------
    A slider on a rigid disc with exponential friction: sliding loses stability below a
    subcritical Hopf speed, and the stable stick-slip orbit goes on above it up to where
    it reaches the disc's speed tangentially (a grazing); rows from the smallest damping
    (2 sliding unstable, 1 bistable, 0 sliding stable only):

    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5})
    >>> region = fivdisc.bistable_region(rigid, ("speed.value", (6.0, 14.0)),
    ...                                  ("slider.rotational_damping", (0.45, 0.55)),
    ...                                  points=3, grid=(9, 3), seeds=3)
    >>> print(region["region"].values)
    [[2 2 2 2 2 1 1 1 0]
     [2 2 2 2 1 1 1 0 0]
     [2 2 2 1 1 1 0 0 0]]
    >>> print(str(region["curve_kind"].values[0]), str(region["curve_role"].values[0]))
    grazing vibration end
    """
    from fivdisc.analysis.codimension import hopf_curves
    from fivdisc.analysis.hopf import hopf_points
    from fivdisc.analysis.points import check_box, check_keys, check_values
    from fivdisc.analysis.stability import stability_map
    from fivdisc.continuation.checks import check_target

    began = time.monotonic()
    xkey, ykey = x[0], y[0]
    xr_, yr_ = check_values("x", xkey, x[1]), check_values("y", ykey, y[1])
    if len(xr_) != 2 or len(yr_) != 2:
        raise CaseError("a box needs KEY=START:STOP for each key (two values)")
    check_keys(case, [xkey, ykey], ["x", "y"])
    check_box(case, [(xkey, xr_), (ykey, yr_)], ["x", "y"])
    # a constant speed, and an end of x the orbits can be continued to
    check_target(case, xkey, float(xr_[1]) if case.get(xkey) != xr_[1] else float(xr_[0]))
    if isinstance(points, bool) or not isinstance(points, int) or points < 2:
        raise CaseError(f"points = {points!r} is invalid: must be an integer >= 2")
    nx, ny = grid
    if min(nx, ny) < 2 or max(nx, ny) > 1000:
        raise CaseError(f"grid = {grid!r} is invalid: between 2 and 1000 values per key")
    settings = settings or ContinuationSettings()

    def say(text: str) -> None:
        if progress:
            import sys

            print(f"[{time.monotonic() - began:6.1f} s] {text}", file=sys.stderr)

    lo_y, hi_y = float(min(yr_)), float(max(yr_))
    y_case = float(case.get(ykey))
    y_start = y_case if lo_y <= y_case <= hi_y else 0.5 * (lo_y + hi_y)
    base = case.replace({ykey: y_start})
    say(f"Hopf points along {xkey} at {ykey} = {y_start:g}")
    found = [h for h in hopf_points(base, xkey, np.linspace(xr_[0], xr_[1], 41))
             if h.on_boundary]
    if not found:
        raise FivdiscError(f"no Hopf point on the sliding equilibrium's stability boundary "
                           f"along {xkey} from {xr_[0]:g} to {xr_[1]:g} at {ykey} = "
                           f"{y_start:g}: no bistable region begins there (widen --x)")
    hopf = found[0]
    if hopf.criticality != "subcritical":
        raise FivdiscError(f"the {hopf}: not subcritical, so no bistable range begins at "
                           f"{ykey} = {y_start:g} (choose a box where the Hopf point is "
                           "subcritical)")
    say(f"Hopf curves in ({xkey}, {ykey})")
    curves_h = hopf_curves(case, (xkey, tuple(xr_)), (ykey, tuple(yr_)), seeds=seeds,
                           step=0.1)
    # the equilibrium's stable side of the Hopf point along x
    side = -float(hopf.direction)
    far = float(max(xr_) if side > 0 else min(xr_))
    if vibration is None:
        say(f"the stable vibration beyond {xkey} = {hopf.value:.8g}")
        vib, orbit_text = _vibration(base, xkey, hopf.value, float(far),
                                     _TRANSIENT * 2.0 * np.pi / hopf.omega, settings)
    else:
        if vibration.key != xkey or not np.isclose(float(vibration.case.get(ykey)), y_start):
            raise FivdiscError(f"vibration is a branch in {vibration.key} at {ykey} = "
                               f"{vibration.case.get(ykey)!r}: it must be one in {xkey} at "
                               f"{ykey} = {y_start:g}")
        if not vibration.stable[0]:
            raise FivdiscError(f"vibration: the branch's first orbit (at {xkey} = "
                               f"{vibration.parameter[0]:.6g}) is unstable: give a branch "
                               "that starts from a stable vibration")
        vib = vibration
        orbit_text = (f"the given branch ({' / '.join(vib.signature(0))} at {xkey} = "
                      f"{vib.parameter[0]:.6g}, T = {vib.period[0]:.6g} s)")
    ends = []
    end = _stable_end(vib)
    if end is None:
        raise FivdiscError(f"the stable vibration ({orbit_text}) does not end between "
                           f"{xkey} = {hopf.value:g} and {far:g}: widen --x")
    ends.append(("vibration end", vib, end))
    record = vib.bifurcations()[end[0]]
    end_text = (f"{record['kind']} at {xkey} = {record['parameter']:.9g}: "
                f"{record['note']}")
    if threshold:
        from fivdisc.continuation.from_hopf import hopf_cycles

        say("the threshold orbits from the Hopf point")
        cycles = hopf_cycles(hopf, float(far), settings=settings)
        last = [(i, b["kind"]) for i, b in enumerate(cycles.bifurcations())
                if b["kind"] in (Kind.GRAZING, Kind.FOLD)]
        if last:
            ends.append(("threshold end", cycles, last[0]))
    rows = []
    for role, branch, (which, condition) in ends:
        say(f"the {role} in {ykey}")
        rows.append((role, *_both_ways(branch, which, condition, ykey, y_start, lo_y, hi_y,
                                       points, far, settings)))
    say("the equilibrium's stability on the grid")
    xs = np.linspace(xr_[0], xr_[1], nx)
    ys = np.linspace(yr_[0], yr_[1], ny)
    smap = stability_map(case, (xkey, xs), (ykey, ys))
    growth = smap["max_growth_rate"].transpose(ykey, xkey).values
    region = _classify(growth, xs, ys, rows[0][3], side)
    return _dataset(case, curves_h, rows, xs, ys, growth, region, (xkey, xr_), (ykey, yr_),
                    y_start, hopf, (orbit_text, end_text), time.monotonic() - began)


def _vibration(base: Case, xkey: str, hopf_value: float, far: float, transient: float,
               settings: ContinuationSettings):
    """The stable stick-slip orbit a start stuck to the disc settles on after
    ``transient`` [s], at values of ``x`` on the stable side of the Hopf point
    (:data:`_TRIES`), continued to ``far``: the branch and the orbit in words."""
    from fivdisc.analysis.orbits import periodic_orbit
    from fivdisc.continuation.walk import continue_orbit

    reasons = []
    for frac in _TRIES:
        at = hopf_value + frac * (far - hopf_value)
        case = base.replace({xkey: at})
        # the slider starts stuck: its rate at the disc's (the largest kick)
        case = case.replace({"simulation.initial_state": "equilibrium",
                             "simulation.perturbation.phi_dot": abs(case.speed.value),
                             "simulation.perturbation.phi": 0.0})
        try:
            orbit = periodic_orbit(case, transient=transient, rtol=settings.rtol,
                                   tol=settings.tol)
        except (ConvergenceError, FivdiscError) as exc:
            reasons.append(f"{xkey} = {at:.6g}: {exc}")
            continue
        if orbit.verdict != "stable":
            reasons.append(f"{xkey} = {at:.6g}: the orbit found is {orbit.verdict}")
            continue
        branch = continue_orbit(case, xkey, far, orbit=orbit, settings=settings)
        signature = branch.signature(0)
        if "stick" not in " ".join(signature):
            reasons.append(f"{xkey} = {at:.6g}: the orbit found never sticks")
            continue
        text = (f"{orbit.symmetry or 'an orbit'} ({' / '.join(signature)}) found at {xkey} "
                f"= {at:.6g} from a start stuck to the disc, T = {orbit.period:.6g} s")
        return branch, text
    raise FivdiscError("no stable stick-slip orbit found from a start stuck to the disc on "
                       "the stable side of the Hopf point (" + "; ".join(reasons) + ")")


def _stable_end(branch) -> tuple[int, str] | None:
    """The bifurcation where ``branch`` (from a stable orbit) ends or loses stability,
    and the condition it is followed by; None if it does neither."""
    bifs = branch.bifurcations()
    stable = branch.stable
    lost = np.flatnonzero(~stable.astype(bool))
    first = int(lost[0]) if lost.size else len(stable)
    for i, b in enumerate(bifs):
        if b["kind"] in _ENDS and b["point"] <= first:
            return i, _ENDS[b["kind"]]
    return None


def _both_ways(branch, which: int, condition: str | None, ykey: str, y_start: float,
               lo: float, hi: float, points: int, far: float,
               settings: ContinuationSettings):
    """The bifurcation followed in ``ykey`` from ``y_start`` to both ends of the box,
    joined in order of ``ykey``: (kind, stop reasons, curve table of rows ``x, y,
    period, residual, condition``). Where ``condition`` is None (a border where the flow
    map jumps, which no condition of :mod:`~fivdisc.continuation.codim2` describes) or
    the condition's curve cannot start, the end is located at each value of ``ykey`` by
    the one-parameter walk instead (:func:`_by_walks`)."""
    from fivdisc.continuation.codim2 import curve_from_branch

    parts, stops, kind = [], [], ""
    for to in (lo, hi):
        if to == y_start:
            continue
        why = ""
        if condition is not None:
            try:
                curve = curve_from_branch(branch, which, ykey, to, condition=condition,
                                          points=points, settings=settings)
            except (ConvergenceError, FivdiscError) as exc:
                why = f"the {condition} not followed ({exc}); "
            else:
                kind = curve.kind
                stops.append(f"towards {ykey} = {to:g}: {curve.stop_reason}")
                parts.append(np.column_stack([curve.parameter, curve.second_parameter,
                                              curve.period, curve.dataset["residual"].values,
                                              curve.condition]))
                continue
        table, stop = _by_walks(branch, which, ykey, y_start, to, points, far, settings)
        kind = "located by one-parameter walks"
        stops.append(f"towards {ykey} = {to:g}: {why}located by one-parameter walks: {stop}")
        parts.append(table)
    if not parts:
        raise FivdiscError(f"the end of the stable vibration could not be followed in {ykey}: "
                           + "; ".join(stops))
    table = np.vstack(parts)
    table = table[np.argsort(table[:, 1], kind="stable")]
    _, keep = np.unique(table[:, 1], return_index=True)
    return kind or str(condition), "; ".join(stops), table[keep]


def _by_walks(branch, which: int, ykey: str, y_start: float, to: float, points: int,
              far: float, settings: ContinuationSettings) -> tuple[np.ndarray, str]:
    """The end of ``branch``'s stable part at ``points`` values of ``ykey`` from
    ``y_start`` to ``to``, each located by a one-parameter walk in the branch's key
    (:func:`~fivdisc.continuation.walk.continue_orbit`, which bisects a border to 1e-7
    of the key) from an orbit a little before the previous value's end (Newton at the
    new value of ``ykey``). Rows ``x, y, period, residual, nan`` (no defining condition:
    the walk's bisection locates it), and why it stopped."""
    from fivdisc.analysis.orbits import periodic_orbit
    from fivdisc.continuation.walk import continue_orbit

    key = branch.key
    first = branch.bifurcations()[which]
    rows = [(float(first["parameter"]), y_start, float(first["period"]),
             float(branch.dataset["residual"].values[min(int(first["point"]),
                                                          len(branch) - 1)]), np.nan)]
    for q in np.linspace(y_start, to, points)[1:]:
        b = branch.bifurcations()[which]
        # a start a few per cent of the branch's span before its end
        span = abs(branch.parameter[b["point"]] - branch.parameter[0])
        before = np.flatnonzero(np.abs(branch.parameter[: b["point"] + 1]
                                       - b["parameter"]) >= 0.02 * span)
        i = int(before[-1]) if before.size else 0
        case = branch.case.replace({key: float(branch.parameter[i]), ykey: float(q)})
        try:
            orbit = periodic_orbit(case, branch.dataset["state"].values[i],
                                   period=float(branch.period[i]), phases=branch.phases(i),
                                   rtol=settings.rtol, tol=settings.tol)
            walked = continue_orbit(case, key, far, orbit=orbit,
                                    settings=settings.replace(confirm_periods=0))
        except (ConvergenceError, FivdiscError) as exc:
            return np.array(rows).reshape(-1, 5), f"no orbit at {ykey} = {q:.6g} ({exc})"
        end = _stable_end(walked)
        if end is None:
            return np.array(rows).reshape(-1, 5), (f"the stable orbit does not end before "
                                                   f"{key} = {far:g} at {ykey} = {q:.6g}")
        branch, which = walked, end[0]
        b = walked.bifurcations()[which]
        k = min(int(b["point"]), len(walked) - 1)
        rows.append((float(b["parameter"]), float(q), float(b["period"]),
                     float(walked.dataset["residual"].values[k]), np.nan))
    return np.array(rows).reshape(-1, 5), f"reached {ykey} = {to:g}"


def _classify(growth: np.ndarray, xs: np.ndarray, ys: np.ndarray, table: np.ndarray,
              side: float) -> np.ndarray:
    """The region code (:data:`REGIONS`) of each grid point (``growth`` is (y, x))."""
    region = np.full(growth.shape, -1, dtype=np.int8)
    region[growth >= 0.0] = 2
    x_end = np.interp(ys, table[:, 1], table[:, 0], left=np.nan, right=np.nan)
    if table.shape[0] == 1:
        x_end = np.where(ys == table[0, 1], table[0, 0], np.nan)
    for i, xe in enumerate(x_end):
        if not np.isfinite(xe):
            continue
        stable = growth[i] < 0.0
        inside = (xs - xe) * side < 0.0
        region[i, stable & inside] = 1
        region[i, stable & ~inside] = 0
    return region


def _dataset(case: Case, curves_h: xr.Dataset, rows: list, xs: np.ndarray, ys: np.ndarray,
             growth: np.ndarray, region: np.ndarray, x: tuple, y: tuple, y_start: float,
             hopf: Any, texts: tuple[str, str], seconds: float) -> xr.Dataset:
    import xarray as xr

    from fivdisc.engine.conventions import global_attrs, key_attrs

    (xkey, xr_), (ykey, yr_) = x, y
    xa, ya = key_attrs(xkey), key_attrs(ykey)
    table = np.vstack([r[3] for r in rows])
    index = np.concatenate([np.full(r[3].shape[0], c, dtype=np.int64)
                            for c, r in enumerate(rows)])
    hc = curves_h
    return xr.Dataset(
        {
            "region": ((ykey, xkey), region, {
                "long_name": "region", "flag_values": np.array(list(REGIONS), dtype=np.int8),
                "flag_meanings": " ".join(v.replace(" ", "_") for v in REGIONS.values())}),
            "max_growth_rate": ((ykey, xkey), growth, {
                "long_name": "largest growth rate of the sliding equilibrium",
                "units": "s-1"}),
            "curve_x": ("curve_point", table[:, 0], {**xa, "long_name": f"{xa['long_name']} "
                                                                       "on the curve"}),
            "curve_y": ("curve_point", table[:, 1], {**ya, "long_name": f"{ya['long_name']} "
                                                                       "on the curve"}),
            "curve": ("curve_point", index, {"units": "1", "long_name": "which curve"}),
            "curve_period": ("curve_point", table[:, 2], {"units": "s",
                                                          "long_name": "orbit's period"}),
            "curve_residual": ("curve_point", table[:, 3], {
                "units": "1", "long_name": "scaled shooting residual of the orbit"}),
            "curve_condition": ("curve_point", table[:, 4], {
                "units": "1", "long_name": "defining condition's value (zero on the curve)"}),
            "curve_kind": ("curve", np.array([r[1] for r in rows], dtype=str),
                           {"long_name": "bifurcation followed (fold, grazing)"}),
            "curve_role": ("curve", np.array([r[0] for r in rows], dtype=str), {
                "long_name": "vibration end: where the stable vibration ends or loses "
                             "stability; threshold end: where the unstable orbits from the "
                             "Hopf point end"}),
            "curve_stop": ("curve", np.array([r[2] for r in rows], dtype=str),
                           {"long_name": "why the curve stopped on each side"}),
            "hopf_x": ("hopf_point", hc[xkey].values, xa),
            "hopf_y": ("hopf_point", hc[ykey].values, ya),
            "hopf_curve": ("hopf_point", hc["hopf_curve"].values,
                           {"units": "1", "long_name": "which Hopf curve"}),
            "hopf_l1": ("hopf_point", hc["l1"].values, {
                "units": "s2", "long_name": "first Lyapunov coefficient (> 0 subcritical)"}),
            "hopf_on_boundary": ("hopf_point", hc["on_boundary"].values, {
                "units": "1", "long_name": "on the stability boundary"}),
            "special_kind": ("special", hc["codim2_kind"].values,
                             {"long_name": "codimension-two point of the Hopf curves"}),
            "special_x": ("special", hc["codim2_x"].values, xa),
            "special_y": ("special", hc["codim2_y"].values, ya),
        },
        coords={xkey: (xkey, xs, xa), ykey: (ykey, ys, ya)},
        attrs={**global_attrs(f"fivdisc bistable region over {xkey} and {ykey}",
                              "fivdisc.continuation.bistable_region"),
               "fivdisc_kind": "bistable_region", "x_key": xkey, "y_key": ykey,
               "x_range": np.asarray(xr_, dtype=float), "y_range": np.asarray(yr_, dtype=float),
               "y_start": y_start, "hopf_value": float(hopf.value), "hopf": str(hopf),
               "vibration": texts[0], "vibration_end": texts[1], "seconds": float(seconds),
               "case": case.to_toml()},
    )
