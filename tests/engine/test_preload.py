"""The background imports of fivdisc.engine.preload: done off the main thread, with a
short switch interval while they run (so that the main thread, back from each kernel
call, does not wait 5 ms for the GIL), and the interval restored after."""

from __future__ import annotations

import sys
import threading

from fivdisc.engine import preload


def test_a_warm_up_shortens_the_switch_interval_only_while_it_runs(monkeypatch) -> None:
    seen: list[tuple[float, str]] = []

    def task() -> None:
        seen.append((sys.getswitchinterval(), threading.current_thread().name))

    monkeypatch.setitem(preload._TASKS, "probe", (task, "a module nobody imports"))
    monkeypatch.setattr(preload, "_threads", {})
    before = sys.getswitchinterval()
    preload.warm_up("probe")()
    assert len(seen) == 1
    interval, thread = seen[0]
    assert interval <= 2e-4 < before
    assert thread == "fivdisc-warm-up"
    assert sys.getswitchinterval() == before


def test_a_failing_warm_up_restores_the_interval_and_is_silent(monkeypatch) -> None:
    def task() -> None:
        raise ImportError("no such library")

    monkeypatch.setitem(preload._TASKS, "broken", (task, "a module nobody imports"))
    monkeypatch.setattr(preload, "_threads", {})
    before = sys.getswitchinterval()
    preload.warm_up("broken")()
    assert sys.getswitchinterval() == before
