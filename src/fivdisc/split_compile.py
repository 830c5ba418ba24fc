"""The first compilation of the simulation kernel, shared between two processes.

numba compiles a function, and every function it calls, in one thread of one process: the
first compilation of :func:`fivdisc._kernels.integrate.run` keeps one core busy for about
20 s while the other idles. :func:`compile_split` shares it out. A helper process
compiles the steps' stages, the event location and the output samples into numba's
on-disk cache, while this process compiles the switches (``switch._switch``, with the
right-hand side and the impact law it calls); then this process compiles ``run`` itself,
which loads the helper's part from the cache instead of compiling it
(``benchmarks/bench_compile.py`` measures the whole).

A cache entry holds one signature, so each function is compiled for the argument types
``run`` passes it, :func:`callee_types`. Were a prediction wrong, ``run`` would compile
that function once more itself: slower, never wrong (``tests/test_split_compile.py``
checks that it does not happen).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fivdisc.integration import Integration

__all__ = ["HELPER_KERNELS", "OWN_KERNELS", "callee_types", "compile_split"]

#: What the helper process compiles, and what this process compiles before ``run``: two
#: shares of about the same compile time.
HELPER_KERNELS = ("_stages", "_complete_rows", "locate", "_event_at", "_sample_states",
                  "dense_coefficients")
OWN_KERNELS = ("_switch",)

# The helper is given this long [s] before this process gives up on it and compiles its
# part itself: only so that a hung helper cannot hang the first simulation.
_HELPER_TIMEOUT = 600.0


def _dispatchers() -> dict[str, Any]:
    from fivdisc._kernels import dopri5, integrate, switch

    return {"_stages": integrate._stages, "_complete_rows": integrate._complete_rows,
            "locate": integrate.locate, "_event_at": integrate._event_at,
            "_sample_states": integrate._sample_states,
            "dense_coefficients": dopri5.dense_coefficients, "_switch": switch._switch}


def callee_types(run: Integration) -> dict[str, tuple]:
    """The numba argument types with which ``integrate.run``, called on ``run``'s arrays
    without tangents, calls each function of :data:`HELPER_KERNELS` and
    :data:`OWN_KERNELS`.

    Arrays that ``run`` passes on are typed from ``run`` itself; those it makes (work
    rows, stage scratch, copies of the phases) are C-contiguous and writable, as
    ``np.empty`` and ``.copy()`` make them.
    """
    import numpy as np
    from numba import typeof, types

    from fivdisc._kernels.switch import NO_EVENT

    f8 = types.float64
    i8 = typeof(NO_EVENT)
    vec = typeof(np.empty(1))
    mat = typeof(np.empty((1, 1)))
    ivec = typeof(np.empty(1, dtype=np.int64))
    y, ph, sg, mdl = typeof(run.y), typeof(run.ph), typeof(run.sg), typeof(run.mdl)
    k, ev_prev, ev_t, ev_i = typeof(run.k), typeof(run.ev_prev), typeof(run.ev_t), typeof(
        run.ev_i)
    ist, fst, ctl = typeof(run.ist), typeof(run.fst), typeof(run.ctl)
    out_y, out_aux = typeof(run.out_y), typeof(run.out_aux)
    none = typeof(None)
    return {
        "_stages": (f8, f8, y, ph, sg, mdl, mat, k, vec, vec, vec, none, none),
        "_complete_rows": (i8, i8, ctl, mdl, mat, vec, vec, ivec, ivec, out_y, out_aux, fst),
        "locate": (i8, f8, f8, f8, f8, f8, f8, mat, ph, sg, mdl, mat, vec, vec, vec, ist),
        "_event_at": (f8, i8, f8, f8, mat, ph, sg, mdl, mat, vec, vec, vec, ist),
        "_sample_states": (f8, f8, f8, mat, ph, sg, ctl, out_y, out_aux, ist),
        "dense_coefficients": (y, vec, k, f8, mat),
        "_switch": (i8, i8, f8, y, ph, sg, ph, ev_prev, mdl, mat, vec, k, ev_prev, ev_t, ev_i,
                    ist, fst),
    }


def _compile(names: tuple[str, ...], signatures: dict[str, tuple]) -> None:
    dispatchers = _dispatchers()
    for name in names:
        dispatchers[name].compile(signatures[name])


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def helper_main() -> None:
    """What the helper process runs: compile :data:`HELPER_KERNELS` for the default case's
    types (every case's arrays have the same types) into the cache."""
    from fivdisc.case import Case
    from fivdisc.integration import Integration
    from fivdisc.model import build_model
    from fivdisc.start import initial_state

    model = build_model(Case())
    run = Integration(model, initial_state(model), duration=1.0, output_rate=1.0)
    _compile(HELPER_KERNELS, callee_types(run))


def compile_split(run: Integration) -> bool:
    """Compile the kernel's parts on two processes before ``run``'s first step, if the
    machine has two cores and the kernel is not in numba's cache; returns whether it did.

    ``run.advance`` then compiles ``integrate.run`` itself, taking the parts from memory
    and from the cache. A helper that fails or hangs costs time only: ``run`` compiles
    what is missing.
    """
    from fivdisc._kernels import integrate
    from fivdisc.compilation import needs_compiling

    if run.tan is not None or _cores() < 2 or not needs_compiling(integrate.run):
        return False
    package_parent = str(Path(__file__).resolve().parents[1])
    path = os.environ.get("PYTHONPATH")
    env = {**os.environ,
           "PYTHONPATH": package_parent + (os.pathsep + path if path else "")}
    helper = subprocess.Popen(
        [sys.executable, "-c", "from fivdisc.split_compile import helper_main; helper_main()"],
        stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        env=env)
    try:
        _compile(OWN_KERNELS, callee_types(run))
        helper.wait(timeout=_HELPER_TIMEOUT)
    except subprocess.TimeoutExpired:
        pass
    finally:
        if helper.poll() is None:
            helper.kill()
            helper.wait()
    return True
