"""Long work shows progress on a terminal and stays silent elsewhere (issue 27, item 4)."""

from __future__ import annotations

import io
import sys

import pytest

from fivdisc import Case, simulate
from fivdisc.engine.progress import progress_bar


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize(("stream", "show", "shown"), [
    (_Terminal, True, True), (_Terminal, False, False), (io.StringIO, True, False),
])
def test_a_bar_only_on_a_terminal(monkeypatch, stream, show, shown):
    err = stream()
    monkeypatch.setattr(sys, "stderr", err)
    with progress_bar(total=4, desc="Newton", unit="it", show=show) as bar:
        for _ in range(4):
            bar.update()
    text = err.getvalue()
    assert ("Newton" in text and "4/4" in text) if shown else text == ""


def test_simulate_shows_simulated_time_on_a_terminal(monkeypatch):
    simulate(Case(simulation={"duration": 0.01}))  # imports done before, quietly
    err = _Terminal()
    monkeypatch.setattr(sys, "stderr", err)
    simulate(Case(simulation={"duration": 0.02}), progress=True)
    assert "simulating" in err.getvalue() and "0.02/0.02 s" in err.getvalue()
