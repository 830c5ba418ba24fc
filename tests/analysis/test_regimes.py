"""The response type by Lyapunov exponents and multipliers, against the spectral label."""

from __future__ import annotations

import fivdisc
from fivdisc.analysis.exponents import lyapunov
from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.analysis.regimes import cross_check
from fivdisc.analysis.spectra import classify, find_peaks, spectrum
from fivdisc.case import Case

# The rigid-disc stick-slip oscillator of test_orbits: a stable periodic orbit whose other
# exponents (-4.7 1/s, the damped disc mode) are far from zero.
RIGID = Case(
    disc={"modes": [[0, 0]]},
    slider={"rotational_damping": 0.0, "normal_damping": 5.0},
    friction={"static": 0.8, "kinetic_max": 0.5, "kinetic_min": 0.5, "decay": 0.0},
    speed={"value": 1.0},
    simulation={"duration": 8.0, "output_rate": 5000.0},
)


def test_stick_slip_cycle_is_periodic_by_every_measure():
    ds = fivdisc.simulate(RIGID).dataset
    spectral = classify(find_peaks(spectrum(ds, "phi", t0=4.0))).kind
    assert spectral == "periodic"
    spec = lyapunov(RIGID, n=3, transient=4.0, duration=20.0)
    orbit = periodic_orbit(RIGID, transient=4.0)
    regime = cross_check(spectral, spec, orbit)
    assert regime.lyapunov == "periodic" and regime.zero_exponents == 1
    assert regime.consistent
    assert regime.multiplier < 1.0


def test_decaying_response_is_an_equilibrium_and_contradicts_periodic():
    """A light disc whose sliding equilibrium is stable: every exponent negative. Called
    periodic by a spectrum, the check says so."""
    case = Case(disc={"density": 720.0, "modes": [[0, 0]]},
                slider={"mass": 1.0, "normal_damping": 20.0, "rotational_damping": 4.0},
                friction={"decay": 0.5}, speed={"value": 1.0},
                simulation={"initial_state": "equilibrium"})
    spec = lyapunov(case, n=2, transient=1.0, duration=10.0)
    regime = cross_check("periodic", spec)
    assert regime.lyapunov == "equilibrium" and regime.zero_exponents == 0
    assert not regime.consistent
    assert cross_check("none", spec).consistent
