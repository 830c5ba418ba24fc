"""Saying so while a kernel compiles.

numba compiles a kernel on its first call in a fresh installation and caches it on disk,
so later processes load it in a second or two. :func:`compile_notice` wraps that first
call: when the kernel is neither in memory nor in numba's cache it prints what is
happening on stderr (once per process and kernel), with a spinner and the seconds
elapsed when stderr is a terminal, and the time it took at the end.

How long it takes depends on the machine and its load (7 to 44 s for the right-hand side
alone, 30 s to a few minutes for the whole kernel were seen): the notice gives no number
of its own. It says how long the same kernel took the last time it compiled on this
machine, measured then and kept beside numba's cache (:func:`measured_seconds`).
"""

from __future__ import annotations

import json
import sys
import threading
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any, TextIO

__all__ = ["announce_by_default", "compile_notice", "measured_seconds", "needs_compiling",
           "tangent_notice"]

_FRAMES = "|/-\\"
_TICK = 0.25  # [s] between spinner frames
_TIMES_FILE = "fivdisc-compile-seconds.json"
# What this process has announced already, and whether notices are shown when the caller
# does not say (the command line turns them on; a library call stays quiet).
_announced: set[str] = set()
_default_show = False


def announce_by_default(show: bool = True) -> None:
    """Show compilation notices where a caller does not say (``show=None``): the command
    line turns them on for every command, library calls leave them off."""
    global _default_show
    _default_show = show


def needs_compiling(dispatcher: Any) -> bool:
    """Whether calling a numba dispatcher will compile it: it has no compiled signature in
    this process and numba's on-disk cache holds no fresh entry for it.

    An index that numba would find stale (written by another numba version, or for kernel
    sources since edited, see :mod:`fivdisc.core.cache`) counts as no entry, as does
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


def _times_file(dispatcher: Any) -> Path | None:
    """The file beside `dispatcher`'s numba cache that keeps measured compile times."""
    path = getattr(getattr(dispatcher, "_cache", None), "_cache_path", None)
    return Path(path) / _TIMES_FILE if isinstance(path, str | Path) else None


def measured_seconds(dispatcher: Any, what: str) -> float | None:
    """How long compiling `what` (the kernel whose first call is `dispatcher`) took the last
    time on this machine [s], or None if it was never measured here."""
    path = _times_file(dispatcher)
    try:
        value = json.loads(path.read_text())[what] if path is not None else None
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return float(value) if isinstance(value, int | float) and value > 0 else None


def _record_seconds(dispatcher: Any, what: str, seconds: float) -> None:
    path = _times_file(dispatcher)
    if path is None:
        return
    try:
        try:
            times = json.loads(path.read_text())
        except (OSError, ValueError):
            times = {}
        if not isinstance(times, dict):
            times = {}
        times[what] = round(seconds, 1)
        from fivdisc.files import write_atomic

        write_atomic(path, lambda target: Path(target).write_text(json.dumps(times)))
    except OSError:
        pass  # a read-only cache: the next notice gives no number


@contextmanager
def compile_notice(dispatcher: Any | Sequence[Any], show: bool | None = True,
                   stream: TextIO | None = None,
                   what: str = "simulation kernel") -> Iterator[None]:
    """Print a notice on `stream` while the body compiles `dispatcher`, if it will.

    Parameters
    ----------
    dispatcher
        The numba dispatcher the body calls first, or several: the notice is printed if
        any of them will compile (the first one's cache keeps the measured time).
    show
        False: say nothing (the body still runs); None: what
        :func:`announce_by_default` set (off unless the command line turned it on).
    stream
        Where to write [default: sys.stderr].
    what
        What compiles, in words; a notice for it is printed once per process.
    """
    dispatchers = list(dispatcher) if isinstance(dispatcher, Sequence) else [dispatcher]
    if show is None:
        show = _default_show
    if not show or what in _announced or not any(map(needs_compiling, dispatchers)):
        yield
        return
    _announced.add(what)
    out = stream if stream is not None else sys.stderr
    before = measured_seconds(dispatchers[0], what)
    line = f"compiling the {what}, once"
    line += (f" (it took {before:.0f} s when last compiled on this machine)"
             if before is not None else " (numba keeps it for later runs)")
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
    seconds = time.perf_counter() - start
    _record_seconds(dispatchers[0], what, seconds)
    stop(f"compiled the {what} in {seconds:.0f} s; later runs load it")


@contextmanager
def tangent_notice(show: bool | None = True) -> Iterator[None]:
    """:func:`compile_notice` for the kernel with tangent vectors: its first use compiles
    a second version of the kernel (and of its helpers, such as
    ``fivdisc.core.tangent.prepare``, compiled only for it)."""
    from fivdisc.core import tangent

    with compile_notice(tangent.prepare, show=show, what="kernel with tangent vectors"):
        yield
