"""A forward run past a branch's end confirms the end only where the branch's last orbit
is stable: a run leaves an unstable orbit on either side of the end alike (the new
user's three-pad branch, unstable throughout, was "confirmed" by a run that does not
settle, as does one from inside the branch)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from fivdisc.analysis.orbits import periodic_orbit
from fivdisc.continuation.borders import forward_run
from fivdisc.continuation.problem import OrbitProblem
from fivdisc.continuation.settings import ContinuationSettings

from support.cases import RIGID


@pytest.fixture(scope="module")
def rigid():
    orbit = periodic_orbit(RIGID, transient=4.0)
    problem = OrbitProblem(RIGID, "speed.value", orbit.phases, orbit.period,
                           ContinuationSettings())
    cycle = problem.shooting.cycle(orbit.state, orbit.period)
    shot = problem.shooting.shoot(orbit.state, orbit.period, tangents=False)
    return orbit, problem, cycle, shot


@pytest.mark.parametrize(("largest", "says"), [(0.92, False), (1.5, True)])
def test_a_run_that_does_not_settle_confirms_only_a_stable_orbit_s_end(rigid, largest, says):
    orbit, problem, cycle, shot = rigid
    # Started far from the orbit (its disc mode kicked), the run has not settled after
    # ten periods (the mode decays by 0.92 a period): what it says of the end depends on
    # the last orbit's multipliers alone.
    x = orbit.state.copy()
    x[: problem.base.n] *= 3.0
    lo = SimpleNamespace(x=x, phases=orbit.phases, period=orbit.period, cycle=cycle,
                         shot=shot, multipliers=np.array([1.0, largest, 0.5]), trivial=0)
    fwd = forward_run(problem, lo, problem.p0, 10)
    assert not fwd.settled
    assert ("does not confirm the end" in fwd.text) == says
