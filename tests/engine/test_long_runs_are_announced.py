"""A run that would take long says so, with its estimate, before or as soon as it can;
one that cannot end within its step budget is refused up front (issue 40, item 5)."""

from __future__ import annotations

import os
import signal
import threading
import time
import warnings

import pytest

from fivdisc import Case, simulate
from fivdisc.errors import FivdiscError, FivdiscWarning


def test_a_max_step_too_small_for_the_run_is_refused_up_front() -> None:
    """simulation.max_step = 1e-12 s: 1e12 steps for a second, refused by the step
    estimate (which did not count max_step) before the run starts."""
    start = time.perf_counter()
    with pytest.raises(FivdiscError) as info:
        simulate(Case(simulation={"max_step": 1e-12}))
    message = str(info.value)
    assert "the run needs about 1e+12 integrator steps, more than simulation.max_steps" in message
    assert "1 / simulation.max_step = 1e+12 1/s limits the step to 1e-12 s" in message
    assert time.perf_counter() - start < 10


def test_a_run_of_minutes_warns_with_its_estimate_up_front() -> None:
    """A disc of density 1e-9 kg/m^3 makes 0.02 s a run of minutes or hours (modes at
    7e9 rad/s, 3e8 steps; the step budget raised to allow them): it said nothing. A fifth
    of a second in, it warns with the time its steps take, measured; the test stops it
    there with Ctrl-C."""
    case = Case(disc={"density": 1e-9}, simulation={"duration": 0.02, "max_steps": 10**10})
    sent = []

    def interrupt(caught: list) -> None:
        # Once the run has warned (or after a minute), as a user reading it would.
        deadline = time.monotonic() + 60.0
        while not caught and time.monotonic() < deadline:
            time.sleep(0.05)
        sent.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        simulate(case.replace({"simulation.duration": 1e-6}))  # the kernel loaded
        caught.clear()
        threading.Thread(target=interrupt, args=(caught,), daemon=True).start()
        start = time.perf_counter()
        result = simulate(case)
    assert sent and result.status == "interrupted"
    assert sent[0] - start < 30  # warned within seconds, not at the end of minutes
    notes = [str(w.message) for w in caught if issubclass(w.category, FivdiscWarning)]
    assert len(notes) == 1, notes
    assert notes[0].startswith("the run will take about ")
    assert "integrator steps at " in notes[0] and "a second, measured" in notes[0]
    assert "disc.modes C03 natural frequency = 7.44e+09 1/s" in notes[0]
    assert notes[0].endswith("Ctrl-C stops it and keeps what was computed")


def test_a_short_run_says_nothing() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error", FivdiscWarning)
        assert simulate(Case(simulation={"duration": 0.05})).ok
