"""The periodic orbits born at a Hopf point: against the averaged (first Lyapunov
coefficient) closed form of the rigid-disc oscillator, the Hopf period, and forward
simulations on either side of the Hopf point."""

from __future__ import annotations

import numpy as np
import pytest

from fivdisc import Case
from fivdisc.analysis.hopf import hopf_points
from fivdisc.continuation.from_hopf import hopf_cycles
from fivdisc.engine.integration import Integration
from fivdisc.errors import FivdiscError
from fivdisc.model.build import build_model

from support.cli import run_cli

# The rigid-disc oscillator of test_hopf: I u'' + C u' + K u = r N0 mu(r (Omega - u')) with
# mu = mu_k + dmu exp(-alpha v). Expanded about steady sliding in the slip-speed change
# r u': I u'' + a I u' + b u'^2 + d I u'^3 + K u = 0 with a = (C + r^2 N0 mu') / I and
# d = r^4 N0 mu''' / (6 I). The u'^2 term is reversible (t -> -t) and does not move the
# amplitude; averaging the energy balance over x = A cos(w t) gives the orbit's
# rate amplitude V = A w from a + (3/4) d V^2 = 0. At the Hopf point
# (r^2 N0 alpha dmu exp(-alpha r Omega) = C) da/dOmega = r alpha C / I and
# d = -r^2 alpha^2 C / (6 I), so Omega - Omega_H = r alpha V^2 / 8 > 0: the orbits lie on
# the side where sliding is stable (mu''' < 0): the Hopf point is subcritical.
R, ALPHA = 0.1, 1.0
CASE = Case(disc={"modes": []}, slider={"rotational_damping": 0.5},
            friction={"decay": ALPHA}, speed={"value": 1.0})


@pytest.fixture(scope="module")
def hopf():
    (point,) = hopf_points(CASE, "speed.value", np.linspace(0.5, 30.0, 25))
    return point


@pytest.fixture(scope="module")
def cycles(hopf):
    return hopf_cycles(hopf, 30.0, max_points=120)


def _rate_amplitude(branch, i: int = 0) -> float:
    ds = branch.dataset
    # Half the range of phi_dot: the second harmonic from the u'^2 term adds alike to
    # both extremes and drops out.
    return 0.5 * float(ds["phi_dot_max"].values[i, 0] - ds["phi_dot_min"].values[i, 0])


def test_small_orbits_follow_the_averaged_closed_form(hopf):
    """At amplitudes 0.01 and 0.02 of grazing (alpha r V ~ 1e-2), the first orbit's
    speed offset equals r alpha V^2 / 8 to 1 % (the averaging's next terms are
    O((alpha r V)^2) relative, the orbit's residual far smaller), and its period tends to
    2 pi / omega like the square of the amplitude."""
    offsets, periods = [], []
    for amplitude in (0.01, 0.02):
        first = hopf_cycles(hopf, 30.0, amplitude=amplitude, max_points=1)
        v = _rate_amplitude(first)
        offset = first.parameter[0] - hopf.value
        assert offset == pytest.approx(R * ALPHA * v**2 / 8.0, rel=1e-2)
        offsets.append(offset)
        periods.append(first.period[0])
        assert first.dataset.attrs["criticality"] == "subcritical"
        assert not first.stable[0]
    assert offsets[1] / offsets[0] == pytest.approx(4.0, rel=2e-2)
    shifts = np.abs(np.array(periods) - hopf.period) / hopf.period
    assert shifts[0] < 1e-5
    assert shifts[1] / shifts[0] == pytest.approx(4.0, rel=0.1)


STRIBECK = Case(disc={"modes": []}, slider={"rotational_damping": 0.2},
                friction={"law": "stribeck", "stribeck_velocity": 1.0,
                          "stribeck_exponent": 2.0}, speed={"value": 1.0})


@pytest.fixture(scope="module")
def stribeck_hopf():
    return hopf_points(STRIBECK, "speed.value", np.linspace(0.2, 30.0, 40))


@pytest.mark.parametrize("which", [0, 1])
def test_stribeck_hopf_points_supercritical_below_subcritical_above(stribeck_hopf, which):
    """mu = mu_k + dmu exp(-(u / v_s)^2) has two Hopf points (test_hopf). The averaging of
    the module docstring, for any law, gives Omega - Omega_H = -r mu''' V^2 / (8 mu''):
    at the lower point (u / v_s = 0.08) mu''' > 0 > mu'', the orbits lie above it where
    sliding is unstable, and are stable: supercritical; at the upper one (u / v_s = 1.76)
    mu''' < 0 < mu'', the orbits lie above it where sliding is stable: subcritical. The
    first orbit (r V / v_s ~ 1e-3 and 2e-2) matches the offset to 1e-3."""
    hopf = stribeck_hopf[which]
    first = hopf_cycles(hopf, 30.0, max_points=1)
    x = R * hopf.value  # v_s = 1 m/s
    d2, d3 = (4 * x**2 - 2) * np.exp(-x**2), (12 * x - 8 * x**3) * np.exp(-x**2)
    v = _rate_amplitude(first)
    offset = first.parameter[0] - hopf.value
    assert offset == pytest.approx(-R * d3 * v**2 / (8 * d2), rel=1e-3)
    expected = ("supercritical", True) if which == 0 else ("subcritical", False)
    assert (first.hopf()["criticality"], bool(first.stable[0])) == expected


def test_a_subcritical_branch_stopped_before_grazing_leaves_bistability_open(
        hopf, stribeck_hopf):
    """A subcritical Hopf point's first orbits are unstable on the side where sliding is
    stable: they bound the equilibrium's basin, and what lies outside them (stick-slip, in
    test_simulations_agree_with_the_subcritical_verdict) may coexist with stable sliding.
    A branch stopped before its orbits fold or graze (here after its first point) has not
    decided the bistable range, so it must not print "none found" (read: no
    bistability); a supercritical point's stable orbits on the unstable side do decide
    that there is none near it."""
    first = hopf_cycles(hopf, 30.0, max_points=1)
    info = first.hopf()
    assert info["criticality"] == "subcritical"
    assert np.isnan(info["bistable"][0]) and info["bistable_undetermined"]
    text = str(first)
    assert "none found" not in text
    assert "not determined" in text
    super_first = hopf_cycles(stribeck_hopf[0], 30.0, max_points=1)
    assert super_first.hopf()["criticality"] == "supercritical"
    assert not super_first.hopf()["bistable_undetermined"]
    assert "bistable range (stable sliding and a stable vibration): none found" in str(
        super_first)


def test_branch_grazes_and_gives_the_bistable_range(hopf, cycles):
    """The unstable slipping orbits grow with the speed until the slip speed touches
    zero; the branch ends there, and the bistable range runs from the Hopf speed to it
    at least: the stick-slip orbits that begin at the grazing are not followed, so that
    end is a bound, and the summary says so."""
    br = cycles
    assert np.all(np.diff(br.parameter) > 0)
    assert not br.stable.any()
    (end,) = br.bifurcations()
    assert end["kind"] == "grazing"
    assert "grazes" in br.stop_reason
    ds = br.dataset
    assert ds["phi_dot_max"].values[-1, 0] == pytest.approx(br.parameter[-1], rel=1e-3)
    assert ds.attrs["bistable_low"] == hopf.value
    assert ds.attrs["bistable_high"] == end["parameter"]
    assert br.hopf()["bistable_open"]
    assert "subcritical" in str(br)
    assert "at least" in str(br)


def _run(speed: float, rate: float, duration: float = 0.4) -> tuple[float, int]:
    """From the sliding equilibrium at ``speed`` with phi_dot kicked by ``rate``: the
    last 0.05 s's largest |phi_dot - phi_dot_eq| and the number of stick events."""
    from fivdisc.engine.equilibrium import sliding_equilibrium

    model = build_model(CASE.replace({"speed.value": speed}))
    start = sliding_equilibrium(model).state.copy()
    start[model.index("phi_dot")] += rate
    run = Integration(model, start, duration=duration, output_rate=20000.0, rtol=1e-10,
                      atol=1e-14)
    run.run_to(duration)
    tail = run.out_y[: run.n_samples][-1000:, model.index("phi_dot")]
    _, events = run.events()
    return float(np.max(np.abs(tail))), int(events.shape[0])


def test_simulations_agree_with_the_subcritical_verdict(hopf, cycles):
    """Inside the bistable range the unstable orbit is the threshold: a kick of half its
    rate amplitude dies out, one of 1.5 times grows into stick-slip. Just below the Hopf
    speed (0.9 of it) a small kick does not settle on a small orbit (there is none: subcritical)
    but grows into stick-slip."""
    br = cycles
    speed = hopf.value + 0.5 * (br.parameter[-1] - hopf.value)
    amplitudes = [_rate_amplitude(br, i) for i in range(len(br))]
    threshold = float(np.interp(speed, br.parameter, amplitudes))
    small, sticks = _run(speed, 0.5 * threshold)
    # Slow near the threshold, then at the linear rate: a hundredfold in 0.4 s.
    assert small < 1e-2 * 0.5 * threshold and sticks == 0
    large, sticks = _run(speed, 1.5 * threshold)
    assert large > threshold and sticks > 0
    # Growth rate there hopf.rate * 0.1 Omega_H, 23 1/s: a 1e-2 kick grows a hundredfold
    # within 0.2 s.
    below, sticks = _run(0.9 * hopf.value, 1e-2 * hopf.value, duration=1.0)
    assert below > 0.5 * hopf.value and sticks > 0


def test_bad_amplitude_is_refused(hopf):
    with pytest.raises(FivdiscError, match=r"amplitude = 0\.0 is invalid"):
        hopf_cycles(hopf, 30.0, amplitude=0.0)


def test_continue_from_hopf_on_the_command_line(tmp_path):
    """fivdisc continue --from-hopf: the Hopf point, the verdict, a branch file that
    keeps them; a bad range is refused in one line (exit status 2)."""

    from fivdisc.continuation.branch import open_branch

    case = tmp_path / "rigid.toml"
    case.write_text(CASE.to_toml())
    out = tmp_path / "cycles.nc"
    res = run_cli(["continue", str(case), "--key", "speed.value", "--to",
                                   "30", "--from-hopf", "0.5:30:25", "--points", "3",
                                   "--no-progress", "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert "Hopf point at speed.value = 9.16290" in res.output
    assert "subcritical" in res.output
    saved = open_branch(out).hopf()
    assert saved["criticality"] == "subcritical" and saved["direction"] == -1
    bad = run_cli(["continue", str(case), "--key", "speed.value", "--to",
                                   "30", "--from-hopf", "0.5:30"])
    assert bad.exit_code == 2
    assert "--from-hopf = '0.5:30' is invalid" in bad.output


def test_the_bistable_range_ends_at_the_located_fold():
    """Subcritical orbits that turn stable at a fold of cycles: the range of stable
    sliding beside a stable vibration ends at the fold, located to 1e-6 relative, not at
    the last stable point computed before it. On a three-slider trial case (speed 10
    rad/s, in sliders.2.rotational_damping) the printed end was the point 0.25999818
    next to the fold at 0.25999895. The branch here stands for that one: unstable points
    up to the fold, stable ones as the parameter turns back."""
    import types

    import xarray as xr

    from fivdisc.continuation.from_hopf import _judge

    p = np.array([0.0414, 0.1, 0.2, 0.25999891, 0.25999818, 0.2599933])
    stable = np.array([False, False, False, False, True, True])
    fold = {"kind": "fold", "parameter": 0.259998949, "point": 3}
    branch = types.SimpleNamespace(parameter=p, stable=stable, dataset=xr.Dataset(),
                                   bifurcations=lambda: [fold])
    hopf = types.SimpleNamespace(value=0.0413536562, direction=-1, on_boundary=True,
                                 omega=1224.7)
    _judge(branch, hopf)
    attrs = branch.dataset.attrs
    assert attrs["criticality"] == "subcritical"
    assert (attrs["bistable_low"], attrs["bistable_high"]) == (0.0413536562, 0.259998949)
    assert not attrs["bistable_open"]
