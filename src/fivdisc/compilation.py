"""Saying so while the simulation kernel compiles.

numba compiles the kernel on its first call in a fresh installation (about a minute) and
caches it on disk, so later processes load it in a second or two. :func:`compile_notice`
wraps that first call: when the kernel is neither in memory nor in numba's cache it
prints what is happening on stderr, with a spinner and the seconds elapsed when stderr is
a terminal, and the time it took at the end.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any, TextIO

__all__ = ["COMPILE_SECONDS", "TANGENT_COMPILE_SECONDS", "compile_notice", "needs_compiling",
           "tangent_notice"]

#: Typical time to compile the kernel [s]: 44-67 s measured on a loaded 2-core machine,
#: 118 s on one under heavier load; benchmarks/bench_simulate.py measures it on yours.
COMPILE_SECONDS = 90
#: Typical time to compile the kernel with tangent vectors (orbits, Lyapunov exponents),
#: once more after the plain one [s]: 80-120 s measured on a 2-core machine.
TANGENT_COMPILE_SECONDS = 120
_FRAMES = "|/-\\"
_TICK = 0.25  # [s] between spinner frames


def needs_compiling(dispatcher: Any) -> bool:
    """Whether calling a numba dispatcher will compile it: it has no compiled signature in
    this process and numba's on-disk cache holds no fresh entry for it.

    An index that numba would find stale (written by another numba version, or for kernel
    sources since edited, see :mod:`fivdisc._kernels.cache`) counts as no entry, as does
    one it cannot read.
    """
    if getattr(dispatcher, "signatures", None):
        return False
    cache_file = getattr(getattr(dispatcher, "_cache", None), "_cache_file", None)
    load_index = getattr(cache_file, "_load_index", None)
    if load_index is None:
        return True
    try:
        return not load_index()
    except Exception:
        # Whatever numba cannot unpickle it compiles afresh.
        return True


@contextmanager
def compile_notice(dispatcher: Any, show: bool = True, stream: TextIO | None = None,
                   what: str = "simulation kernel",
                   seconds: float = COMPILE_SECONDS) -> Iterator[None]:
    """Print a notice on `stream` while the body compiles `dispatcher`, if it will.

    Parameters
    ----------
    dispatcher
        The numba dispatcher the body calls first.
    show
        False: say nothing (the body still runs).
    stream
        Where to write [default: sys.stderr].
    what, seconds
        What compiles, and about how long it takes [s].
    """
    if not show or not needs_compiling(dispatcher):
        yield
        return
    out = stream if stream is not None else sys.stderr
    line = f"compiling the {what}, once: about {seconds:.0f} s"
    live = out.isatty()
    start = time.perf_counter()
    done = threading.Event()

    def spin() -> None:
        frame = 0
        while not done.wait(_TICK):
            elapsed = time.perf_counter() - start
            out.write(f"\r{line} {_FRAMES[frame % len(_FRAMES)]} {elapsed:.0f} s ")
            out.flush()
            frame += 1

    spinner = threading.Thread(target=spin, daemon=True)
    if live:
        spinner.start()
    else:
        out.write(line + "\n")
        out.flush()

    def stop(ending: str) -> None:
        done.set()
        if live:
            spinner.join()
            out.write("\r" + ending.ljust(len(line) + 8) + "\n")
        elif ending:
            out.write(ending + "\n")
        out.flush()

    try:
        yield
    except BaseException:
        stop("")
        raise
    stop(f"compiled the {what} in {time.perf_counter() - start:.0f} s; later runs load it")


@contextmanager
def tangent_notice(show: bool = True) -> Iterator[None]:
    """:func:`compile_notice` for the kernel with tangent vectors: its first use compiles
    a second version of the kernel (and of its helpers, such as
    ``fivdisc._kernels.tangent.prepare``, compiled only for it)."""
    from fivdisc._kernels import tangent

    with compile_notice(tangent.prepare, show=show, what="kernel with tangent vectors",
                        seconds=TANGENT_COMPILE_SECONDS):
        yield
