"""Branches of several configurations of pads (issue 36, item 7), each checked at three of
its points against plain forward runs, which share nothing with the shooting, the
monodromy or the continuation: the period (the time between a pad's successive sticks,
to 1e-7) and the stability (a small perturbation of the orbit decays or grows at the
rate of the largest multiplier)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from fivdisc.analysis.orbits import Shooting, energy_scales, periodic_orbit
from fivdisc.case import Case
from fivdisc.continuation.borders import groups
from fivdisc.continuation.walk import continue_orbit
from fivdisc.engine.integration import Integration
from fivdisc.engine.result import EVENT_KINDS
from fivdisc.model.build import build_model
from fivdisc.model.layout import Phase

PAD = {"track_radius": 0.1, "mass": 0.1, "normal_stiffness": 3e4, "normal_damping": 0.1,
       "rotational_stiffness": 2e3, "rotational_damping": 0.1, "preload": 500.0}
STRIBECK = {"law": "stribeck", "static": 0.8, "kinetic_max": 0.6, "kinetic_min": 0.35,
            "stribeck_velocity": 1.0, "stribeck_exponent": 2.0}
EXPONENTIAL = {"law": "exponential", "static": 0.6, "kinetic_max": 0.5, "kinetic_min": 0.3,
               "decay": 1.0}
START = {"duration": 1.0, "initial_state": "equilibrium",
         "perturbation": {"phi": 0.0, "phi_dot": 14.0}}


def facing(speed: float) -> Case:
    """Two identical pads facing each other at one angle, on the two faces."""
    return Case(disc={"modes": [[0, 0], [0, 1]], "damping_ratio": 0.003},
                sliders=[{**PAD, "face": "top"}, {**PAD, "face": "bottom"}],
                friction=EXPONENTIAL, speed={"value": speed}, simulation=START)


def ring(n: int, speed: float, friction: dict) -> Case:
    """n identical pads equally spaced on the top face."""
    return Case(disc={"modes": [[0, 0], [0, 1]], "damping_ratio": 0.003},
                sliders=[{**PAD, "angle": 2 * math.pi * k / n} for k in range(n)],
                friction=friction, speed={"value": speed}, simulation=START)


def _returns(case: Case, state: np.ndarray, phases: np.ndarray, periods: int,
             period: float) -> tuple[np.ndarray, np.ndarray]:
    """A plain run from ``state`` (the stuck pads moving with the disc): the times of pad
    0's sticks and the states there."""
    model = build_model(case)
    x = np.array(state, dtype=float)
    x[model.index("phi_dot") + np.flatnonzero(phases == Phase.STICK)] = case.speed.value
    run = Integration(model, x, duration=periods * period, rtol=1e-12, atol=1e-19,
                      phases=phases, stop_on=("stick",))
    times, states = [], []
    seen = 0
    while run.t < periods * period:
        run.advance(periods * period)
        t_ev, rows = run.events()
        for t, row in zip(t_ev[seen:], rows[seen:], strict=True):
            if EVENT_KINDS[int(row[0])] == "stick" and int(row[3]) == 0:
                times.append(float(t))
                states.append(run.state)
        seen = rows.shape[0]
        if run.status_name == "success":
            break
    return np.array(times), np.array(states)


def check_point(case: Case, state, phases, period: float, multipliers, trivial: int) -> None:
    """Period and stability of one branch point, by plain runs."""
    times, _ = _returns(case, state, phases, 4, period)
    np.testing.assert_allclose(np.diff(times), period, rtol=1e-7)
    model = build_model(case)
    scale = energy_scales(model)
    rng = np.random.default_rng(3)
    kick = scale * rng.standard_normal(state.size)
    kick[model.index("z"): model.index("z") + model.n_sliders] = 0.0
    kick[model.index("z_dot"): model.index("z_dot") + model.n_sliders] = 0.0
    size = np.linalg.norm(np.asarray(state) / scale)
    start = np.array(state, dtype=float) + 1e-6 * size * kick / np.linalg.norm(kick / scale)
    # the perturbed run against the unperturbed one, both plain runs with the same
    # steps (each settles on the plain integrator's own orbit, 1e-9 from the shooting's)
    _, base = _returns(case, state, phases, 400, period)
    _, seen = _returns(case, start, phases, 400, period)
    count = min(len(base), len(seen))
    # on the disc's and the pads' own coordinates (z, zdot in contact are the disc's
    # deflection under the pad, not state)
    own = np.ones(state.size, dtype=bool)
    for name in ("z", "z_dot"):
        own[model.index(name): model.index(name) + model.n_sliders] = False
    d = np.linalg.norm(((seen[:count] - base[:count]) / scale)[:, own], axis=1)
    early, late = d[100:150].mean(), d[count - 50:count].mean()
    others = np.delete(np.abs(multipliers), trivial)
    largest = float(others.max())
    steps = (count - 25) - 125
    rate = math.log(late / early) / steps
    if largest < 1:
        assert late < early
    else:
        assert late > early
    shooting = Shooting(model, phases, 1e-12, 1e-19)
    if any(len({j for _, j, _ in g}) > 1 for _, g in groups(shooting.cycle(state, period))):
        # switches of different pads coincide: the orbit lies where pieces of the flow map
        # meet, its multipliers are one side's (the integration's order of the
        # coinciding switches), and a perturbation, which parts them, decays or grows at
        # another side's rate (on the four pads in phase, 0.9963 per period against
        # 0.9914)
        return
    assert rate == pytest.approx(math.log(largest), rel=0.3, abs=2e-4)


CONFIGS = {
    "two pads on opposite faces, exponential law": (facing, 10.0, 9.0),
    "four pads at 90 degrees, Stribeck law": (lambda v: ring(4, v, STRIBECK), 15.0, 13.5),
}


@pytest.mark.parametrize("name", sorted(CONFIGS))
def test_a_branch_agrees_with_forward_runs_at_three_points(name):
    make, speed, to = CONFIGS[name]
    case = make(speed)
    orbit = periodic_orbit(case, transient=2.0)
    br = continue_orbit(case, "speed.value", to, orbit=orbit, max_points=4, confirm_periods=0)
    assert len(br) == 4
    for i in (0, 2, 3):
        at = case.replace({"speed.value": float(br.parameter[i])})
        check_point(at, br.dataset["state"].values[i], br.phases(i), float(br.period[i]),
                    br.multipliers[i], int(br.dataset["trivial_multiplier"].values[i]))


@pytest.mark.slow
def test_the_three_pad_branch_agrees_with_forward_runs_at_three_points():
    """Issue 36's three pads at 120 degrees (Stribeck law, four modes), from 22 rad/s."""
    data = Path(__file__).parents[1] / "data"
    case = Case.from_toml((data / "three_pads.toml").read_text(encoding="utf-8"))
    saved = np.load(data / "three_pads.npz")
    orbit = periodic_orbit(case, saved["S22_state"], period=float(saved["S22_period"]),
                           phases=saved["S22_phases"])
    br = continue_orbit(case, "speed.value", 20.0, orbit=orbit, max_points=4,
                        confirm_periods=0)
    for i in (0, 2, 3):
        at = case.replace({"speed.value": float(br.parameter[i])})
        check_point(at, br.dataset["state"].values[i], br.phases(i), float(br.period[i]),
                    br.multipliers[i], int(br.dataset["trivial_multiplier"].values[i]))
