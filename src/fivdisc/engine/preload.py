"""Imports a run will need next, done in a background thread while the kernel integrates.

The integration kernel releases the GIL, so while it runs a second thread can import what
the result needs afterwards: for a command that writes netCDF, the netCDF library (a
fifth of a second of processor time). On a machine with two cores the import then costs
little wall time. While the thread imports, the interpreter's switch interval is
shortened (0.2 ms, restored after), so that the main thread, back from each kernel call,
takes the GIL at once instead of waiting for the import to let go. In a process that
already has the library it does nothing.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable


def _netcdf() -> None:
    import netCDF4  # noqa: F401


_TASKS: dict[str, tuple[Callable[[], None], str]] = {
    # name: (what to do, the module whose presence means it is not needed)
    "netcdf": (_netcdf, "netCDF4"),
}
_threads: dict[str, threading.Thread] = {}


def _quietly(tasks: list[Callable[[], None]]) -> None:
    # With the default switch interval (5 ms) the main thread, back from each 2 ms
    # kernel call, would wait for this import about as long as the import takes.
    interval = sys.getswitchinterval()
    sys.setswitchinterval(min(interval, 2e-4))
    try:
        for task in tasks:
            try:
                task()
            except Exception:
                # A failure here (a missing optional library, say) is the main thread's
                # to report, when it imports the same module and needs it.
                return
    finally:
        sys.setswitchinterval(interval)


def warm_up(*names: str) -> Callable[[], None]:
    """Start importing ``names`` (``"netcdf"``) in a daemon thread.

    Returns a function that waits until they are imported: call it before using the
    modules, so that the main thread never imports them while the thread is half-way
    through. Names imported before are skipped; one already started is waited for.
    """
    todo = [name for name in names
            if name not in _threads and _TASKS[name][1] not in sys.modules]
    if todo:
        thread = threading.Thread(target=_quietly, args=([_TASKS[n][0] for n in todo],),
                                  name="fivdisc-warm-up", daemon=True)
        _threads.update(dict.fromkeys(todo, thread))
        thread.start()
    waits = {_threads[name] for name in names if name in _threads}

    def wait() -> None:
        for thread in waits:
            thread.join()

    return wait
