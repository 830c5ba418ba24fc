"""Borders of the smooth pieces of the flow map with several sliders, and the forward runs
that confirm where a branch ends.

With one slider, a branch of orbits changes piece where a phase appears or vanishes (its
event signature changes). With several, the flow map also changes piece where switches
of *different* sliders change order, and there it may **jump**: when slider ``b``
switches, the contact forces change at once, and the static margin
``(mu_s N_a - |f_a|) / (mu_s N_a)`` of a stuck slider ``a`` jumps by some ``Delta``. If
``a`` would release just before ``b``'s switch on one side of the border and just after
it on the other, its release time jumps by ``Delta`` over the margin's rate (a relief,
``Delta > 0``, delays it), and so does the orbit. Where ``Delta < 0`` (a load) ``a``
releases at ``b``'s switch itself (a cascade, as the in-phase releases of identical pads
are); a cascade ends where the load turns into a relief.

The test functions of an orbit (:func:`switch_tests`), each zero at such a border:

* *gap*: the time between consecutive switches of different sliders;
* *margin*: a stuck slider's static margin just before another slider's switch (with the
  jump ``Delta`` that switch gives it);
* *cascade*: within switches at one instant, each stuck slider's margin once the ones
  before it have switched (negative while the cascade holds);
* *dip*: an interior minimum of a phase's own margin (a stick phase about to split, a
  slip phase about to graze the disc speed), and a phase's duration (a phase about to
  vanish).

Between two orbits the order of all switches (:func:`order_key`) says whether a border
was crossed. The forward run (:func:`forward_run`) tells a real end (no periodic orbit
past it, or another one) from a false one by the return distance of its section, not by
its period alone (a motion drifting through a symmetric orbit's images has a period
within 1 % of the orbit's and is not periodic).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fivdisc.analysis.cycle import EVENT_WORDS, SIMULTANEOUS, Cycle
from fivdisc.analysis.orbits import Shooting, newton_shooting
from fivdisc.continuation.problem import OrbitProblem, Point
from fivdisc.continuation.settings import NEAR_SWITCHES, PAST, SETTLES
from fivdisc.engine.equilibrium import contact_forces
from fivdisc.engine.integration import Integration
from fivdisc.engine.result import EVENT_KINDS
from fivdisc.errors import FivdiscError
from fivdisc.model.layout import EventKind, Phase

# Where the state just before a switch is taken: this fraction of the period before it.
_BEFORE = 1e-9
# A test function ahead of a branch's end names it when its zero, extrapolated from two
# points, lies within this many times the end's bracket past the last point.
_NAMES = 50.0


Label = tuple[str, int, int]  # (event kind, slider, its count among that slider's)


def labelled(cycle: Cycle) -> list[tuple[float, Label]]:
    """The switches of one period, each labelled (kind, slider, occurrence)."""
    seen: dict[tuple[str, int], int] = {}
    out = []
    for t, kind, j in cycle.events:
        i = seen.get((kind, j), 0)
        seen[(kind, j)] = i + 1
        out.append((t, (kind, j, i)))
    return out


def groups(cycle: Cycle) -> list[tuple[float, list[Label]]]:
    """The switches of one period in order, those at one instant (of different sliders,
    within :data:`~fivdisc.analysis.cycle.SIMULTANEOUS` of the period) in one group, in
    the order the integration made them."""
    tol = SIMULTANEOUS * cycle.period
    out: list[tuple[float, list[Label]]] = []
    for t, label in labelled(cycle):
        if out and t - out[-1][0] <= tol and all(label[1] != o[1] for o in out[-1][1]):
            out[-1][1].append(label)
        else:
            out.append((t, [label]))
    return out


def order_key(cycle: Cycle, classes: dict[int, int] | None = None) -> tuple:
    """The cyclic order of the switches of all sliders, simultaneous ones as a set:
    independent of where on the orbit its point lies. Two orbits of one smooth piece of
    the flow map have the same.

    ``classes`` (slider -> class) merges the sliders an orbit's spatial symmetry maps onto
    each other (``x = P x``: in phase): their switches are simultaneous by the symmetry,
    and which of them the integration makes first, and a fraction of a nanosecond
    earlier, is round-off, no order; within :data:`NEAR_SWITCHES` of the period, one
    switch of a class stands for all."""
    if not classes:
        seq = [tuple(sorted((k, j) for k, j, _ in g)) for _, g in groups(cycle)]
    else:
        tol = NEAR_SWITCHES * cycle.period
        merged: list[tuple[float, set]] = []
        for t, (kind, j, _) in labelled(cycle):
            label = (kind, classes.get(j, j))
            if merged and t - merged[-1][0] <= tol and label in merged[-1][1]:
                continue
            if merged and t - merged[-1][0] <= SIMULTANEOUS * cycle.period:
                merged[-1][1].add(label)
            else:
                merged.append((t, {label}))
        seq = [tuple(sorted(labels)) for _, labels in merged]
    if not seq:
        return ()
    return min(tuple(seq[i:] + seq[:i]) for i in range(len(seq)))


def pad_classes(point: Point) -> dict[int, int] | None:
    """The sliders ``point``'s spatial symmetry maps onto each other, as slider -> the
    least slider of its class; None without a spatial symmetry."""
    if point.sym is None or not point.sym.spatial:
        return None
    parent = list(range(point.phases.size))

    def root(j: int) -> int:
        while parent[j] != j:
            j = parent[j]
        return j

    for el in point.sym.spatial:
        for j, i in enumerate(el.pads):
            a, b = root(j), root(int(i))
            parent[max(a, b)] = min(a, b)
    return {j: root(j) for j in range(len(parent))}


def name(label: Label) -> str:
    kind, j, _ = label
    return f"pad {j}'s {EVENT_WORDS[kind]}"


@dataclass(frozen=True)
class Test:
    """One test function of an orbit: zero at a border of its piece of the flow map.

    Attributes
    ----------
    kind : str
        ``"gap"``, ``"margin"``, ``"cascade"``, ``"dip"`` or ``"phase"``.
    key : tuple
        What it is, the same on every orbit of the piece.
    value : float
        Its value: a gap or a phase's duration over the period; a margin (of ``mu_s N``);
        a dip's margin. Positive away from the border, but a cascade's (negative while
        it holds).
    jump : float
        The change of the stuck slider's margin at the other slider's switch (margin,
        cascade; > 0 a relief, < 0 a load), else nan.
    text : str
        In words.
    """

    kind: str
    key: tuple
    value: float
    jump: float
    text: str

    @property
    def gone(self) -> float:
        """Its value on the side where it has not yet reached its border (>= 0)."""
        return -self.value if self.kind == "cascade" else self.value


def _margins(mus: float, normal: np.ndarray, force: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(normal > 0, (mus * normal - np.abs(force)) / (mus * normal), np.nan)


def switch_tests(problem: OrbitProblem, point: Point) -> list[Test]:
    """The test functions of ``point``'s orbit (module docstring).

    The margins just before each switch are taken at the state a fraction
    :data:`_BEFORE` of the period before it (a run with the shooting's steps), with every
    slider in its phase, and again with the switching slider in its new phase (the rest
    unchanged): their difference is the jump ``Delta``. Within switches at one instant,
    each slider is switched in turn, in the integration's order."""
    cycle = point.cycle
    period = point.period
    model = problem.model(point.value)
    shooting = Shooting(model, point.phases, problem.rtol, problem.atol, problem.scale)
    mus = model.friction_value("static")
    omega = float(model.speed.omega(0.0))
    rates = model.index("phi_dot")
    tests: list[Test] = []
    grouped = groups(cycle)
    # the sliders an in-phase orbit's symmetry maps onto each other switch together by
    # the symmetry: the gaps between their switches of one kind are round-off, no test
    classes = pad_classes(point) or {}
    for (t1, g1), (t2, g2) in zip(grouped, grouped[1:] + grouped[:1], strict=True):
        if len(grouped) < 2 or ({j for _, j, _ in g1} == {j for _, j, _ in g2}):
            continue
        a, b = g1[-1], g2[0]
        if a[0] == b[0] and classes.get(a[1], a[1]) == classes.get(b[1], -1):
            continue
        gap = (t2 - t1) % period
        tests.append(Test("gap", ("gap", g1[-1], g2[0]), gap / period, math.nan,
                          f"{name(g2[0])} {gap * 1e9:.4g} ns after {name(g1[-1])}"))
    start = shooting.held(point.x)
    counts: dict[str, int] = {}
    for t, group in grouped:
        before = t - _BEFORE * period
        if not before > 0:
            continue
        run = Integration(model, start, duration=before, output_rate=0.0, rtol=problem.rtol,
                          atol=problem.atol, phases=point.phases, max_step=shooting.cap)
        run.run_to(before)
        if run.status_name != "success":
            continue
        y, ph, sg = run.state, np.array(run.ph), np.array(run.sg)
        normal, force = contact_forces(model, y, ph, sg, before)
        margin = _margins(mus, normal, force)
        stuck_before = ph == Phase.STICK
        members = [lab for lab in group if lab[0] in ("stick", "slip", "reversal")]
        # A group's cascade tests are keyed by the group (its kind and its count among
        # groups of that kind) and the place in it: which identical pad the integration
        # switches first is round-off.
        gkind = members[0][0] if members else ""
        gkey = (gkind, counts.get(gkind, 0))
        if len(members) > 1:
            counts[gkind] = counts.get(gkind, 0) + 1
        for i, lab in enumerate(members):
            kind, b, _ = lab
            if kind == "stick":
                ph[b] = Phase.STICK
                y[rates + b] = omega
            elif kind == "slip":
                ph[b] = Phase.SLIP
                sg[b] = 1 if force[b] > 0 else -1
            else:
                sg[b] = -sg[b]
            n2, f2 = contact_forces(model, y, ph, sg, before)
            after = _margins(mus, n2, f2)
            rest = {m[1] for m in members[i + 1:]}
            for a in np.flatnonzero(stuck_before & (ph == Phase.STICK)):
                a = int(a)
                if a == b:
                    continue
                jump = float(after[a] - margin[a])
                if a in rest:
                    # a switches at this instant too: its margin once b has switched
                    place = 1 + [m[1] for m in members].index(a)
                    tests.append(Test(
                        "cascade", ("cascade", gkey, place, i), float(after[a]), jump,
                        f"pad {a}'s margin once {name(lab)} has happened: {after[a]:+.3g} "
                        f"({'a load' if jump < 0 else 'a relief'} of {abs(jump):.3g})"))
                elif i == 0:
                    tests.append(Test(
                        "margin", ("margin", lab, a), float(margin[a]), jump,
                        f"pad {a}'s static margin just before {name(lab)}: {margin[a]:.3g} "
                        f"(it {'jumps up' if jump > 0 else 'jumps down'} by {abs(jump):.3g} "
                        f"there: {'a relief' if jump > 0 else 'a load'})"))
            margin = after
    for j, kind, value, when in cycle.dips:
        tests.append(Test("dip", ("dip", j, kind, round(when / period, 2)), value, math.nan,
                          f"pad {j}'s {'static margin' if kind == 'stick' else 'slip speed'} "
                          f"at its {'least' if kind == 'stick' else 'slowest'} inside a "
                          f"{'stick' if kind == 'stick' else 'slip'} phase: {value:.3g}"))
    times = {}
    for t, (kind, j, i) in labelled(cycle):
        times.setdefault(j, []).append((t, kind, i))
    for j, seq in times.items():
        for (t1, k1, i1), (t2, k2, i2) in zip(seq, seq[1:] + seq[:1], strict=True):
            if len(seq) < 2:
                continue
            span = (t2 - t1) % period
            tests.append(Test("phase", ("phase", (k1, j, i1), (k2, j, i2)), span / period,
                              math.nan, f"pad {j}'s phase between its {EVENT_WORDS[k1]} and "
                              f"{EVENT_WORDS[k2]}: {span * 1e9:.4g} ns"))
    return tests


@dataclass(frozen=True)
class Ahead:
    """The border a branch runs into: the test function and where it is extrapolated to
    vanish."""

    test: Test
    at: float
    before: Test


def border_ahead(problem: OrbitProblem, lo: Point, earlier: Point, p_hi: float
                 ) -> Ahead | None:
    """The test function of ``lo`` whose zero, extrapolated linearly in the key from
    ``earlier`` and ``lo`` (two orbits of one piece), lies nearest ahead of ``lo``, within
    :data:`_NAMES` times ``|p_hi - p_lo|`` past it (``p_hi`` the first value where the
    branch was not found); None if none does."""
    now = {t.key: t for t in switch_tests(problem, lo)}
    then = {t.key: t for t in switch_tests(problem, earlier)}
    p1, p0 = lo.value, earlier.value
    width = abs(p_hi - p1)
    best = None
    for key, test in now.items():
        old = then.get(key)
        if old is None or p1 == p0 or old.gone == test.gone:
            continue
        slope = (test.gone - old.gone) / (p1 - p0)
        if test.gone < 0 or slope == 0:
            continue
        at = p1 - test.gone / slope
        ahead = (at - p1) * np.sign(p_hi - p1)
        if ahead < -width or ahead > max(_NAMES * width, 0.05 * abs(p1 - p0)):
            continue
        if best is None or abs(at - p_hi) < abs(best.at - p_hi):
            best = Ahead(test, at, old)
    return best


def other_piece(problem: OrbitProblem, lo: Point, p: float
                ) -> list[tuple[np.ndarray, float, np.ndarray, float]]:
    """The orbits at ``p`` that Newton shooting finds from ``lo``'s point and period (the
    key held): first over ``T/k`` with the pads permuted if ``lo`` has a spatio-temporal
    symmetry (at a border of a symmetric orbit every image of a junction flips at once,
    and the symmetric orbit past it is the one to go on with), then over the full period.
    Each as (state, period, phases, residual); those that converged."""
    from fivdisc.analysis.orbits import SymmetricShooting

    model = problem.model(p)
    plain = Shooting(model, lo.phases, problem.rtol, problem.atol, problem.scale)
    tries: list[Shooting] = []
    if lo.sym is not None and lo.sym.shift is not None:
        tries.append(SymmetricShooting(model, lo.phases, problem.rtol, problem.atol,
                                       lo.sym.shift.matrix, lo.sym.k, problem.scale))
    tries.append(plain)
    found = []
    for shooting in tries:
        try:
            sol = newton_shooting(shooting, shooting.held(lo.x), lo.period, problem.tol, 20,
                          math.inf)
        except FivdiscError:
            continue
        if not sol.reason:
            found.append((shooting.held(sol.x0), float(sol.period), lo.phases.copy(),
                          float(sol.residual)))
    return found


@dataclass
class Forward:
    """What a forward run from the branch's last orbit, past its end, settles to."""

    value: float
    periods: int
    settled: bool
    period: float
    k: int
    spread: float
    closest: float
    sticks: tuple[int, ...]
    state: np.ndarray
    phases: np.ndarray
    same: bool = False
    text: str = ""


def forward_run(problem: OrbitProblem, lo: Point, value: float, periods: int) -> Forward:
    """Run from ``lo``'s point at the key's ``value`` (the stuck sliders' rates held at
    its disc speed) for ``periods`` of ``lo``'s periods, and tell whether the motion
    settles on a periodic orbit: the states at the switches of one kind of one slider (a
    section the orbit crosses once per period) come back, ``k`` returns apart (k <= 12),
    to within :data:`SETTLES` of the orbit's size over the last returns, closing in (the
    largest distance of the last half of the window below 0.9 of the first half's, as a
    periodic orbit's returns converge geometrically, unlike a torus's), with their return
    times agreeing to ``SETTLES`` of the period."""
    model = problem.model(value)
    shooting = Shooting(model, lo.phases, problem.rtol, problem.atol, problem.scale)
    ev = lo.cycle.events
    kind, pad = (ev[0][1], ev[0][2]) if ev else ("stick", 0)
    duration = periods * lo.period
    run = Integration(model, shooting.held(lo.x), duration=duration, output_rate=0.0,
                      rtol=problem.rtol, atol=problem.atol, phases=lo.phases,
                      stop_on=(kind,), max_step=shooting.cap)
    times: list[float] = []
    states: list[np.ndarray] = []
    phases: list[np.ndarray] = []
    seen = 0
    sticks_at: list[np.ndarray] = []
    count = np.zeros(model.n_sliders, dtype=np.int64)
    while run.t < duration:
        run.advance(duration)
        if run.status_name not in ("stopped", "running", "success"):
            break
        t_ev, rows = run.events()
        for t_i, row in zip(t_ev[seen:], rows[seen:], strict=True):
            if row[0] == EventKind.STICK:
                count[int(row[3])] += 1
            if EVENT_KINDS[int(row[0])] == kind and int(row[3]) == pad:
                times.append(float(t_i))
                states.append(run.state)
                phases.append(np.array(run.ph))
                sticks_at.append(count.copy())
        seen = rows.shape[0]
        if run.status_name == "success":
            break
    sc = problem.scale
    size = float(np.linalg.norm(lo.shot.rate_start / sc) * lo.period)
    n = len(times)
    out = Forward(value, periods, False, math.nan, 0, math.inf, math.inf,
                  (), lo.x, lo.phases)
    if n < 8:
        out.text = (f"a forward run {PAST:.1%} past the end (at {problem.key} = {value:.9g}) "
                    f"crosses its section only {n} times in {periods} periods: no orbit of "
                    "the branch's kind there")
        return out
    window = max(8, min(80, n // 4))
    half = window // 2
    best = None
    for k in range(1, 13):
        if n < window + k + 1:
            break
        d = [float(np.linalg.norm((states[i] - states[i - k]) / sc)) / size
             for i in range(n - window, n)]
        spans = [times[i] - times[i - k] for i in range(n - window, n)]
        recent, before = max(d[half:]), max(d[:half])
        spread = float(max(spans[half:]) - min(spans[half:]))
        # a periodic orbit's returns close in geometrically; a torus's or a drifting
        # motion's come back near, and no nearer
        closing = recent < 1e-10 or recent < 0.9 * before
        ok = recent < SETTLES and spread < SETTLES * np.mean(spans) and closing
        if best is None or (ok and not best[4]) or (ok == best[4] and recent < best[1]):
            best = (k, recent, spread, float(np.mean(spans[half:])), ok)
        if ok:
            break
    k, dist, spread, mean, ok = best
    out.k, out.closest, out.spread, out.period = k, dist, spread, mean
    out.settled = ok
    out.state, out.phases = states[-1], phases[-1]
    out.sticks = tuple(int(v) for v in (sticks_at[-1] - sticks_at[-1 - k]))
    where = f"a forward run {PAST:.1%} past the end (at {problem.key} = {value:.9g})"
    if out.settled:
        out.text = (f"{where} settles within {periods} periods on a periodic orbit of "
                    f"period {mean:.9g} s ({k} crossing{'s' if k > 1 else ''} of its section; "
                    f"sticks per pad {list(out.sticks)}; returns within {dist:.1e})")
    else:
        out.text = (f"{where} does not settle within {periods} periods: its returns to the "
                    f"section come back no closer than {dist:.1e} of the orbit's size, and "
                    f"no closer over time, and their times spread by {spread:.2e} s (over "
                    f"{k} crossing"
                    f"{'s' if k > 1 else ''}, mean {mean:.9g} s; sticks per pad "
                    f"{list(out.sticks)}): no periodic orbit there")
        others = np.delete(np.abs(lo.multipliers), lo.trivial)
        if others.size and others.max() > 1.0:
            # A run leaves an unstable orbit on either side of its end alike.
            out.text += (f", which does not confirm the end: the branch's last orbit is "
                         f"unstable (largest multiplier {others.max():.6g}), so a forward "
                         "run leaves it before the end too")
    return out


def same_piece(problem: OrbitProblem, lo: Point, fwd: Forward) -> bool:
    """Whether a settled forward run is on ``lo``'s piece: the same signature per pad and
    order of all switches, a period within 1e-2 of lo's."""
    if not fwd.settled or fwd.k != 1 or abs(fwd.period / lo.period - 1) > 1e-2:
        return False
    shooting = Shooting(problem.model(fwd.value), fwd.phases, problem.rtol, problem.atol,
                        problem.scale)
    try:
        cyc = shooting.cycle(fwd.state, fwd.period)
    except FivdiscError:
        return False
    return (cyc.cyclic() == lo.cycle.cyclic()
            and order_key(cyc, pad_classes(lo)) == order_key(lo.cycle, pad_classes(lo)))
