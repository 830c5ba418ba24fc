"""What the benchmarks share: the fastest of several runs of the same work."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any


def fastest(rounds: int, work: Callable[[], Any]) -> tuple[float, Any]:
    """The shortest wall time of `rounds` calls of `work` [s], and what the last returned
    (the fastest is the one least disturbed by the machine's other work)."""
    times, out = [], None
    for _ in range(rounds):
        start = time.perf_counter()
        out = work()
        times.append(time.perf_counter() - start)
    return min(times), out
