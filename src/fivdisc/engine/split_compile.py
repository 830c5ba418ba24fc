"""The first compilation of the simulation kernel, shared between two processes.

numba compiles a function, and every function it calls, in one thread of one process: the
first compilation of :func:`fivdisc.core.integrate.run` keeps one core busy for about
20 s while the other idles. :func:`compile_split` shares it out. A helper process
compiles the steps' stages, the event location and the output samples into numba's
on-disk cache, while this process compiles the switches (``switch._switch``, with the
right-hand side and the impact law it calls); then this process compiles ``run`` itself,
which loads the helper's part from the cache instead of compiling it
(``benchmarks/bench_compile.py`` measures the whole).

The kernel with tangent vectors (``run`` given ``tan``) is a second compilation of
``run``, longer still, which adds the tangent code. It is shared out the same way: the
helper compiles the saltation at a switch (:func:`fivdisc.core.tangent.saltation`,
with the switch on the complex state), this process the tangent step and the stages that
feed it. A command that will need the tangent kernel after a plain run (``orbit``,
``lyapunov``, ``continue``, ``warmup``) says so to :func:`compile_split`
(``tangents=True``): the helper then goes on with the tangent kernel's share as soon as
it has done the plain one's, while this process still compiles the plain kernel, and
:func:`compile_split_tangents` later finds it under way
(``benchmarks/bench_first_use.py`` times the commands). :func:`compile_split_rhs` does
the same for the right-hand side on a real state and its complex-step Jacobian, which the
sliding equilibrium (``fivdisc stability``) calls from Python.

A cache entry holds one signature, so each function is compiled for the argument types
``run`` passes it, :func:`callee_types`. Every case's arrays have the same types, so the
default case's stand for any. Were a prediction wrong, ``run`` would compile that
function once more itself: slower, never wrong (``tests/engine/test_split_compile.py`` checks
that it does not happen).
"""

from __future__ import annotations

import atexit
import os
import queue
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fivdisc.engine.integration import Integration

__all__ = ["HELPER_KERNELS", "OWN_KERNELS", "RHS_HELPER_KERNELS", "RHS_OWN_KERNELS",
           "TANGENT_HELPER_AHEAD", "TANGENT_HELPER_KERNELS", "TANGENT_OWN_KERNELS",
           "callee_types", "compile_split", "compile_split_rhs", "compile_split_tangents",
           "default_run"]

#: What the helper process compiles, and what this process compiles before ``run``: two
#: shares of about the same compile time.
HELPER_KERNELS = ("_stages", "_complete_rows", "locate", "_event_at", "_sample_states",
                  "dense_coefficients")
OWN_KERNELS = ("_switch",)
#: The same for the kernel with tangent vectors, in the order compiled: ``tangent_stages``
#: is ``_stages`` for the stage states that the tangent step reads; ``step`` last, so that
#: the right-hand side on a complex state at a real time, which the saltation calls too,
#: may be in the cache by then when the helper began first.
TANGENT_HELPER_KERNELS = ("saltation",)
TANGENT_OWN_KERNELS = ("tangent_stages", "interpolate", "accept", "step")
#: What the helper compiles first of the tangent kernel's share when it did the plain
#: kernel's share before, while this process still compiles the plain kernel: the
#: right-hand side on a complex state at a real time (``jvp_rhs``, ``evaluate`` for it),
#: which the saltation and this process's ``step`` both call; ``step`` then finds it in
#: the cache instead of compiling it a second time.
TANGENT_HELPER_AHEAD = ("jvp_rhs",)
#: The same for the right-hand side that the sliding equilibrium (``fivdisc stability``)
#: calls from Python, and its Jacobian by the complex step: two compilations of the
#: right-hand side, on a real and on a complex state.
RHS_HELPER_KERNELS = ("complex_step_jacobian",)
RHS_OWN_KERNELS = ("new_work", "evaluate")
_SHARES = {"plain": HELPER_KERNELS, "tangents": TANGENT_HELPER_KERNELS,
           "rhs": RHS_HELPER_KERNELS}

# The helper is given this long [s] before this process gives up on it and compiles its
# part itself: only so that a hung helper cannot hang the first simulation.
_HELPER_TIMEOUT = 600.0


def _dispatchers() -> dict[str, Any]:
    from fivdisc.core import dopri5, dynamics, integrate, switch, tangent

    return {"new_work": dynamics.new_work, "evaluate": dynamics.evaluate,
            "complex_step_jacobian": dynamics.complex_step_jacobian,
            "_stages": integrate._stages, "_complete_rows": integrate._complete_rows,
            "locate": integrate.locate, "_event_at": integrate._event_at,
            "_sample_states": integrate._sample_states,
            "dense_coefficients": dopri5.dense_coefficients, "_switch": switch._switch,
            "jvp_rhs": dynamics.evaluate, "saltation": tangent.saltation,
            "tangent_stages": integrate._stages,
            "step": tangent.step, "interpolate": tangent.interpolate,
            "accept": tangent.accept}


def callee_types(run: Integration) -> dict[str, tuple]:
    """The numba argument types with which ``integrate.run``, called on ``run``'s arrays,
    calls each function of :data:`HELPER_KERNELS` and :data:`OWN_KERNELS`, and, if
    ``run`` carries tangent vectors, of :data:`TANGENT_HELPER_KERNELS` and
    :data:`TANGENT_OWN_KERNELS`; with those of :data:`RHS_HELPER_KERNELS` and
    :data:`RHS_OWN_KERNELS` as ``fivdisc.engine.equilibrium`` calls them on arrays of
    ``run``'s types.

    Arrays that ``run`` passes on are typed from ``run`` itself; those it makes (work
    rows, stage scratch, copies of the phases) are C-contiguous and writable, as
    ``np.empty`` and ``.copy()`` make them; the tangent scratch arrays have the types
    ``tangent.scratch`` returns (compiled here for it, a second or two).
    """
    import numpy as np
    from numba import typeof, types

    from fivdisc.core.switch import NO_EVENT

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
    found = {
        # fivdisc.engine.equilibrium: a Python bool for the side, a new work array
        "new_work": (mdl, y),
        "evaluate": (f8, y, ph, sg, types.boolean, mdl, mat, vec),
        "complex_step_jacobian": (f8, y, ph, sg, mdl),
        "_stages": (f8, f8, y, ph, sg, mdl, mat, k, vec, vec, vec, none, none),
        "_complete_rows": (i8, i8, ctl, mdl, mat, vec, vec, ivec, ivec, out_y, out_aux, fst),
        "locate": (i8, f8, f8, f8, f8, f8, f8, mat, ph, sg, mdl, mat, vec, vec, vec, ist),
        "_event_at": (f8, i8, f8, f8, mat, ph, sg, mdl, mat, vec, vec, vec, ist),
        "_sample_states": (f8, f8, f8, mat, ph, sg, ctl, out_y, out_aux, ist),
        "dense_coefficients": (y, vec, k, f8, mat),
        "_switch": (i8, i8, f8, y, ph, sg, ph, ev_prev, mdl, mat, vec, k, ev_prev, ev_t, ev_i,
                    ist, fst),
    }
    if run.tan is None:
        return found
    from fivdisc.core import tangent

    tv, tk = (typeof(a) for a in run.tan)
    scratch_args = (mdl, y, types.intp)  # the vectors' count is a shape, an intp
    tangent.scratch.compile(scratch_args)
    tsc = tangent.scratch.overloads[scratch_args].signature.return_type
    tcx, tvn, tvs, ypre, sgpre, tys, twk = (tsc[i] for i in (0, 3, 4, 9, 10, 11, 12))
    row = typeof(run.k[0])
    found.update({
        # tangent.jvp: the side a numpy bool, the complex-step arrays of the scratch
        "jvp_rhs": (f8, tcx[0], ph, sg, types.boolean, mdl, tcx[2], tcx[1]),
        "saltation": (i8, i8, f8, ypre, ph, sgpre, ev_prev, y, ph, sg, row, mat, mdl, tv, tk,
                      tsc),
        "tangent_stages": (f8, f8, y, ph, sg, mdl, mat, k, vec, vec, vec, tys, twk),
        "step": (f8, f8, ph, sg, mdl, tys, twk, tv, tk, tvn, tvs, tcx),
        "interpolate": (f8, f8, tv, tk, tsc),
        "accept": (tv, tk, tvn),
    })
    return found


def _compile(names: tuple[str, ...], signatures: dict[str, tuple]) -> None:
    dispatchers = _dispatchers()
    for name in names:
        dispatchers[name].compile(signatures[name])


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def default_run(tangents: bool = False) -> Integration:
    """An integration of the default case (one tangent vector with `tangents`), not
    started: its arrays have the types of every case's."""
    import numpy as np

    from fivdisc.case import Case
    from fivdisc.engine.integration import Integration
    from fivdisc.model.build import build_model

    model = build_model(Case())
    # Only the types matter: a state at rest (fivdisc.engine.equilibrium, which calls this module
    # for the equilibrium's compilation, is not imported back).
    run = Integration(model, np.zeros(model.state_size), duration=1.0, output_rate=1.0)
    if tangents:
        run.set_tangents(np.eye(1, model.state_size))
    return run


def helper_main(*shares: str) -> None:
    """What the helper process runs: compile each share (``plain``: :data:`HELPER_KERNELS`,
    ``tangents``: :data:`TANGENT_HELPER_KERNELS`, ``rhs``: :data:`RHS_HELPER_KERNELS`) for
    the default case's types into the cache, printing its name after it."""
    types = callee_types(default_run("tangents" in shares))
    for name in shares:
        ahead = TANGENT_HELPER_AHEAD if name == "tangents" and "plain" in shares else ()
        _compile(ahead + _SHARES[name], types)
        print(name, flush=True)


class _Helper:
    """A helper process compiling shares into the cache; it prints a line after each."""

    def __init__(self, *shares: str) -> None:
        package_parent = str(Path(__file__).resolve().parents[1])
        path = os.environ.get("PYTHONPATH")
        env = {**os.environ,
               "PYTHONPATH": package_parent + (os.pathsep + path if path else "")}
        self.process = subprocess.Popen(
            [sys.executable, "-c", "from fivdisc.engine.split_compile import helper_main; "
             f"helper_main(*{shares!r})"],
            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
            env=env, text=True)
        self.deadline = time.monotonic() + _HELPER_TIMEOUT
        self._lines: queue.Queue[str] = queue.Queue()
        self._ended = False
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        for line in self.process.stdout:
            self._lines.put(line.strip())
        self._lines.put("")  # the helper has ended

    def wait_for(self, share: str) -> None:
        """Until the helper has compiled `share`, has ended, or has had its time."""
        while not self._ended:
            try:
                line = self._lines.get(timeout=max(0.0, self.deadline - time.monotonic()))
            except queue.Empty:
                self.stop()
                return
            self._ended = line == ""
            if line == share:
                return

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait()
        self._reader.join()  # at the pipe's end, now that the helper has ended
        self.process.stdout.close()
        self._ended = True


# A helper that compiles the tangent kernel's share for a later compile_split_tangents;
# one that is still at it when the process ends is stopped then.
_pending: _Helper | None = None


@atexit.register
def _stop_pending() -> None:
    global _pending
    if _pending is not None:
        _pending.stop()
        _pending = None


def compile_split(run: Integration, tangents: bool = False) -> bool:
    """Compile the kernel's parts on two processes before ``run``'s first step, if the
    machine has two cores and the kernel (with tangents, if ``run`` carries them) is not
    in numba's cache; returns whether it did.

    ``run.advance`` then compiles ``integrate.run`` itself, taking the parts from memory
    and from the cache. A helper that fails or hangs costs time only: ``run`` compiles
    what is missing. With `tangents` (the caller will need the kernel with tangent
    vectors next) the helper goes on with that kernel's share meanwhile, for
    :func:`compile_split_tangents`.
    """
    global _pending
    from fivdisc.core import integrate, tangent
    from fivdisc.engine.compilation import needs_compiling

    if _cores() < 2:
        return False
    plain = needs_compiling(integrate.run)
    # The saltation is compiled for the kernel with tangents alone.
    with_tangents = ((run.tan is not None or tangents) and _pending is None
                     and needs_compiling(tangent.saltation))
    if not (plain or with_tangents):
        return False
    helper = _Helper(*(["plain"] if plain else []) + (["tangents"] if with_tangents else []))
    try:
        if plain:
            _compile(OWN_KERNELS, callee_types(run))
            helper.wait_for("plain")
        if with_tangents and run.tan is None:
            _pending, helper = helper, None
        elif with_tangents:
            _compile(TANGENT_OWN_KERNELS, callee_types(run))
            helper.wait_for("tangents")
    finally:
        if helper is not None:
            helper.stop()
    return True


def compile_split_tangents() -> bool:
    """:func:`compile_split` for the kernel with tangent vectors, for a caller that has no
    run at hand yet (the types are every case's); returns whether it compiled."""
    global _pending
    from fivdisc.core import tangent
    from fivdisc.engine.compilation import needs_compiling

    if _pending is not None:
        # Started by compile_split(tangents=True): this process's share, then the helper's.
        helper, _pending = _pending, None
        try:
            _compile(TANGENT_OWN_KERNELS, callee_types(default_run(tangents=True)))
            helper.wait_for("tangents")
        finally:
            helper.stop()
        return True
    if _cores() < 2 or not needs_compiling(tangent.saltation):
        return False
    return compile_split(default_run(tangents=True))


def compile_split_rhs() -> bool:
    """Compile the right-hand side that the sliding equilibrium calls and its complex-step
    Jacobian on two processes, if the machine has two cores and the Jacobian is not in
    numba's cache; returns whether it did."""
    from fivdisc.core import dynamics
    from fivdisc.engine.compilation import needs_compiling

    if _cores() < 2 or not needs_compiling(dynamics.complex_step_jacobian):
        return False
    helper = _Helper("rhs")
    try:
        _compile(RHS_OWN_KERNELS, callee_types(default_run()))
        helper.wait_for("rhs")
    finally:
        helper.stop()
    return True
