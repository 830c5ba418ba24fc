"""Tangent dynamics across switches against finite differences of the flow map.

The kernel carries tangent vectors through each phase (variational equations, complex-step
Jacobian) and across each switch (saltation matrix). The reference here is the flow map
itself: central differences of the final state with respect to each free initial
coordinate, with two Richardson extrapolations (steps e, e/2, e/4), which need no
derivative of anything. Every perturbed run must take the same switch sequence (checked),
so the flow map is smooth where it is differenced.

Why 1e-6 is reachable and what limits it: the runs use rtol 1e-12; each switch is located
to a bracket of 1e-12 s, so a perturbed run's state carries noise of about 1e-12 s times
the jump of the acceleration at each switch. Differencing with relative steps 1e-3 keeps
that noise near 1e-8 of the derivative, and the extrapolation removes the truncation error
(O(e^2), then O(e^4)), leaving O(e^6) ~ 1e-18. The comparison is made on the Jacobian in
scaled coordinates (each coordinate divided by the size of its block, q, phi, z and their
rates) so that units do not weigh in; the error is the largest entry's deviation over the
largest entry.
"""

from __future__ import annotations

import numpy as np
import pytest

from fivdisc.case import Case
from fivdisc.engine.integration import Integration
from fivdisc.engine.result import EVENT_KINDS
from fivdisc.model.build import build_model
from fivdisc.model.layout import Phase

RTOL, ATOL = 1e-12, 1e-16
BASE = {"disc": {"density": 720.0, "modes": [[0, 0], [0, 1]]}, "speed": {"value": 1.0}}
ONE = Case(slider={"mass": 1.0, "normal_damping": 20.0, "preload": 50.0}, **BASE)
TWO = Case(
    sliders=[
        {"mass": 1.0, "normal_damping": 20.0, "preload": 50.0, "angle": 0.0},
        {"mass": 0.5, "normal_damping": 10.0, "preload": 50.0, "angle": 2.0, "face": "bottom"},
    ],
    **BASE,
)


def _kicked(model) -> np.ndarray:
    """Rest, with the first mode's rate kicked so that the sliders fly and land."""
    x0 = np.zeros(model.state_size)
    x0[model.state_size // 2] = 0.5
    return x0


def _flow(model, x0, span, phases, tangents=False):
    """State at ``span`` (contact coordinates filled in as the output has them), the
    tangents of the identity if asked, the event table and the free coordinates."""
    run = Integration(model, x0, duration=span, output_rate=1.0 / span, rtol=RTOL, atol=ATOL,
                      phases=phases)
    if tangents:
        run.set_tangents(np.eye(model.state_size))
    run.advance(0.0)
    free = run.free()
    run.run_to(span)
    assert run.status_name == "success"
    _, rows = run.events()
    y = run.out_y[1, : model.state_size].copy()
    return y, (run.tangents().T if tangents else None), [tuple(r) for r in rows], free


def _start(model, x0, t):
    """State and phases reached at ``t`` from ``x0`` (the output row at ``t``)."""
    run = Integration(model, x0, duration=t, output_rate=1.0 / t, rtol=RTOL, atol=ATOL)
    run.run_to(t)
    return run.out_y[1, : model.state_size].copy(), run.ph.copy()


def _scales(model, *states):
    n, s = model.n, model.n_sliders
    half = model.state_size // 2
    sc = np.zeros(model.state_size)
    for block in (slice(0, n), slice(n, n + s), slice(n + s, n + 2 * s)):
        for off in (0, half):
            b = slice(block.start + off, block.stop + off)
            sc[b] = max(max(np.max(np.abs(x[b])) for x in states), 1e-12)
    return sc


def _tangent_error(model, x0, phases, span, kinds, steps=(1e-3, 5e-4, 2.5e-4)):
    y, jac, events, free = _flow(model, x0, span, phases, tangents=True)
    seen = {EVENT_KINDS[e[0]] for e in events}
    assert kinds <= seen, f"span crosses {sorted(seen)}, needs {sorted(kinds)}"
    sc = _scales(model, x0, y)
    fd = np.zeros_like(jac)
    for j in np.flatnonzero(free):
        d = []
        for e in steps:
            xp, xm = x0.copy(), x0.copy()
            xp[j] += e * sc[j]
            xm[j] -= e * sc[j]
            yp, _, ev_p, _ = _flow(model, xp, span, phases)
            ym, _, ev_m, _ = _flow(model, xm, span, phases)
            assert ev_p == events == ev_m, "a perturbation changed the switch sequence"
            d.append((yp - ym) / (2 * e * sc[j]))
        r1 = (4 * d[1] - d[0]) / 3
        r2 = (4 * d[2] - d[1]) / 3
        fd[:, j] = (16 * r2 - r1) / 15
    scaled = lambda m: m * sc[None, :] / sc[:, None]  # noqa: E731
    return np.max(np.abs(scaled(jac) - scaled(fd))) / np.max(np.abs(scaled(fd)))


def test_tangent_matches_flow_map_one_slider():
    """From flight: landing with a bounce (impact releases it), landing, stick, slip and
    separation."""
    model = build_model(ONE)
    x0, phases = _start(model, _kicked(model), 0.005)
    assert phases[0] == Phase.SEPARATION
    err = _tangent_error(model, x0, phases, 0.0115,
                         {"recontact", "separation", "stick", "slip"})
    assert err < 1e-6


def test_tangent_matches_flow_map_two_sliders():
    """One slider flying, the other in contact: stick, slip, separation, a landing that
    bounces, landings on a disc the other slider touches (the impact's complementarity
    problem), a slip reversal."""
    model = build_model(TWO)
    x0, phases = _start(model, _kicked(model), 0.0005)
    err = _tangent_error(model, x0, phases, 0.011,
                         {"recontact", "separation", "stick", "slip", "reversal"})
    assert err < 1e-6


def test_tangent_matches_flow_map_across_speed_kinks():
    """A decelerating table profile whose kinks fall inside the span (non-autonomous:
    the event rates carry dOmega/dt, the stick reaction jumps at a kink)."""
    case = ONE.replace({"speed": {"profile": "table", "times": [0.0, 0.004, 0.009, 1.0],
                                  "values": [1.0, 1.0, 0.4, 0.4]}})
    model = build_model(case)
    x0, phases = _start(model, _kicked(model), 0.002)
    assert model.speed.breakpoints.size >= 2
    err = _tangent_error(model, x0, phases, 0.012, {"stick"})
    assert err < 1e-6


def test_tangents_leave_the_trajectory_unchanged():
    """The step sequence is the state's alone: with and without tangents the runs are the
    same to the last bit, events and samples included."""
    model = build_model(TWO)
    x0 = _kicked(model)
    runs = []
    for tangents in (False, True):
        run = Integration(model, x0, duration=0.05, output_rate=2e3)
        if tangents:
            run.set_tangents(np.eye(3, model.state_size))
        for target in np.linspace(0.0, 0.05, 7):
            run.run_to(target)
        runs.append(run)
    plain, tang = runs
    assert np.array_equal(plain.y, tang.y)
    assert np.array_equal(plain.out_y[: plain.n_samples], tang.out_y[: tang.n_samples])
    for a, b in zip(plain.events(), tang.events(), strict=True):
        assert np.array_equal(a, b)
    assert plain.events()[0].size > 10


def test_sticking_collapses_the_slider_rate():
    """In stick phidot = Omega whatever the perturbation: the slip-to-stick saltation
    removes every tangent's phidot component, and none comes back while it sticks."""
    case = Case(disc={"density": 720.0, "modes": [[0, 0]]},
                slider={"mass": 1.0, "normal_damping": 20.0}, speed={"value": 1.0})
    model = build_model(case)
    run = Integration(model, np.zeros(model.state_size), duration=0.5)
    run.set_tangents(np.eye(model.state_size))
    run.advance(0.0)
    while run.ph[0] != Phase.STICK and run.t < 0.5:
        run.advance(run.t + 1e-4)
    assert run.ph[0] == Phase.STICK
    tangents = run.tangents()
    phid = model.index("phi_dot")
    assert np.all(tangents[:, phid] == 0.0)


@pytest.mark.parametrize("friction", [
    {},
    {"law": "stribeck", "stribeck_velocity": 0.3, "stribeck_exponent": 1.5, "viscous": 0.01,
     "kinetic_max": 0.6, "kinetic_min": 0.35, "static": 0.8},
    {"law": "table", "speeds": [0.0, 0.2, 0.5, 1.0], "values": [0.6, 0.5, 0.42, 0.4],
     "static": 0.8},
])
def test_tangent_linear_rhs_equals_the_complex_step(friction):
    """One slider's Jacobian-vector product is the hand-derived tangent-linear form of the
    right-hand side; the complex step of the right-hand side itself is its independent
    reference (both exact to rounding). Random states and directions, every phase and
    slip sign, a damped disc with doublets, the bottom face, a decelerating disc."""
    from fivdisc import core

    fr = {"law": "exponential"} | friction
    case = Case(disc={"modes": [[0, 0], [0, 2], [1, 1]], "damping_ratio": 0.01},
                slider={"face": "bottom", "angle": 0.4}, friction=fr,
                speed={"profile": "decelerating", "initial": 6.0, "duration": 10.0})
    model = build_model(case)
    cm = core.core_model(model)
    rng = np.random.default_rng(3)
    nd = model.state_size
    for phase, sign in ((Phase.SLIP, 1), (Phase.SLIP, -1), (Phase.STICK, 1), (Phase.SEPARATION, 1)):
        for _ in range(5):
            y = rng.standard_normal(nd) * 1e-4
            y[model.index("phi_dot")] = 6.0 * (1 - 0.9 * sign * rng.random())
            v = rng.standard_normal(nd)
            ph, sg = np.array([phase]), np.array([sign])
            t = float(rng.uniform(0.0, 5.0))
            fast = core.jvp(cm, t, y, v, ph, sg, True, "linear")
            ref = core.jacobian(cm, t, y, ph, sg) @ v
            assert np.max(np.abs(fast - ref)) <= 1e-12 * np.max(np.abs(ref)), (phase, sign)
