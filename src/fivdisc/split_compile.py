"""The first compilation of the simulation kernel, shared between two processes.

numba compiles a function, and every function it calls, in one thread of one process: the
first compilation of :func:`fivdisc._kernels.integrate.run` keeps one core busy for about
20 s while the other idles. :func:`compile_split` shares it out. A helper process
compiles the steps' stages, the event location and the output samples into numba's
on-disk cache, while this process compiles the switches (``switch._switch``, with the
right-hand side and the impact law it calls); then this process compiles ``run`` itself,
which loads the helper's part from the cache instead of compiling it
(``benchmarks/bench_compile.py`` measures the whole).

The kernel with tangent vectors (``run`` given ``tan``) is a second compilation of
``run``, about as long again, which adds the tangent code. It is shared out the same
way: the helper compiles the saltation at a switch (:func:`fivdisc._kernels.tangent.
saltation`, with the switch on the complex state), this process the tangent step and the
stages that feed it; the plain kernel's parts, when they are not in the cache either,
first, as above (``benchmarks/bench_first_use.py`` times the commands).

A cache entry holds one signature, so each function is compiled for the argument types
``run`` passes it, :func:`callee_types`. Every case's arrays have the same types, so the
default case's stand for any. Were a prediction wrong, ``run`` would compile that
function once more itself: slower, never wrong (``tests/test_split_compile.py`` checks
that it does not happen).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from fivdisc.integration import Integration

__all__ = ["HELPER_KERNELS", "OWN_KERNELS", "TANGENT_HELPER_KERNELS", "TANGENT_OWN_KERNELS",
           "callee_types", "compile_split", "compile_split_tangents", "default_run"]

#: What the helper process compiles, and what this process compiles before ``run``: two
#: shares of about the same compile time.
HELPER_KERNELS = ("_stages", "_complete_rows", "locate", "_event_at", "_sample_states",
                  "dense_coefficients")
OWN_KERNELS = ("_switch",)
#: The same for the kernel with tangent vectors (``tangent_stages`` is ``_stages`` for
#: the stage states that the tangent step reads).
TANGENT_HELPER_KERNELS = ("saltation",)
TANGENT_OWN_KERNELS = ("tangent_stages", "step", "interpolate", "accept")

# The helper is given this long [s] before this process gives up on it and compiles its
# part itself: only so that a hung helper cannot hang the first simulation.
_HELPER_TIMEOUT = 600.0


def _dispatchers() -> dict[str, Any]:
    from fivdisc._kernels import dopri5, integrate, switch, tangent

    return {"_stages": integrate._stages, "_complete_rows": integrate._complete_rows,
            "locate": integrate.locate, "_event_at": integrate._event_at,
            "_sample_states": integrate._sample_states,
            "dense_coefficients": dopri5.dense_coefficients, "_switch": switch._switch,
            "saltation": tangent.saltation, "tangent_stages": integrate._stages,
            "step": tangent.step, "interpolate": tangent.interpolate,
            "accept": tangent.accept}


def callee_types(run: Integration) -> dict[str, tuple]:
    """The numba argument types with which ``integrate.run``, called on ``run``'s arrays,
    calls each function of :data:`HELPER_KERNELS` and :data:`OWN_KERNELS`, and, if
    ``run`` carries tangent vectors, of :data:`TANGENT_HELPER_KERNELS` and
    :data:`TANGENT_OWN_KERNELS`.

    Arrays that ``run`` passes on are typed from ``run`` itself; those it makes (work
    rows, stage scratch, copies of the phases) are C-contiguous and writable, as
    ``np.empty`` and ``.copy()`` make them; the tangent scratch arrays have the types
    ``tangent.scratch`` returns (compiled here for it, a second or two).
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
    found = {
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
    from fivdisc._kernels import tangent

    tv, tk = (typeof(a) for a in run.tan)
    scratch_args = (mdl, y, types.intp)  # the vectors' count is a shape, an intp
    tangent.scratch.compile(scratch_args)
    tsc = tangent.scratch.overloads[scratch_args].signature.return_type
    tcx, tvn, tvs, ypre, sgpre, tys, twk = (tsc[i] for i in (0, 3, 4, 9, 10, 11, 12))
    row = typeof(run.k[0])
    found.update({
        "saltation": (i8, i8, f8, ypre, ph, sgpre, ev_prev, y, ph, sg, row, mdl, tv, tk, tsc),
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
    from fivdisc.integration import Integration
    from fivdisc.model import build_model
    from fivdisc.start import initial_state

    model = build_model(Case())
    run = Integration(model, initial_state(model), duration=1.0, output_rate=1.0)
    if tangents:
        run.set_tangents(np.eye(1, model.state_size))
    return run


def helper_main(tangents: bool = False) -> None:
    """What the helper process runs: compile :data:`HELPER_KERNELS` (with `tangents`:
    :data:`TANGENT_HELPER_KERNELS`) for the default case's types into the cache."""
    run = default_run(tangents)
    _compile(TANGENT_HELPER_KERNELS if tangents else HELPER_KERNELS, callee_types(run))


def _shares(run: Integration) -> list[tuple[bool, tuple[str, ...]]]:
    """(whether the tangent kernel's, this process's functions) of each share that
    ``run``'s first call would compile, in the order to compile them."""
    from fivdisc._kernels import integrate, tangent
    from fivdisc.compilation import needs_compiling

    shares = []
    if needs_compiling(integrate.run):
        shares.append((False, OWN_KERNELS))
    # The saltation is compiled for the kernel with tangents alone.
    if run.tan is not None and needs_compiling(tangent.saltation):
        shares.append((True, TANGENT_OWN_KERNELS))
    return shares


def compile_split(run: Integration) -> bool:
    """Compile the kernel's parts on two processes before ``run``'s first step, if the
    machine has two cores and the kernel (with tangents, if ``run`` carries them) is not
    in numba's cache; returns whether it did.

    ``run.advance`` then compiles ``integrate.run`` itself, taking the parts from memory
    and from the cache. A helper that fails or hangs costs time only: ``run`` compiles
    what is missing.
    """
    if _cores() < 2:
        return False
    shares = _shares(run)
    if not shares:
        return False
    types = callee_types(run)
    package_parent = str(Path(__file__).resolve().parents[1])
    path = os.environ.get("PYTHONPATH")
    env = {**os.environ,
           "PYTHONPATH": package_parent + (os.pathsep + path if path else "")}
    for tangents, own in shares:
        helper = subprocess.Popen(
            [sys.executable, "-c",
             f"from fivdisc.split_compile import helper_main; helper_main({tangents})"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            env=env)
        try:
            _compile(own, types)
            helper.wait(timeout=_HELPER_TIMEOUT)
        except subprocess.TimeoutExpired:
            pass
        finally:
            if helper.poll() is None:
                helper.kill()
                helper.wait()
    return True


def compile_split_tangents() -> bool:
    """:func:`compile_split` for the kernel with tangent vectors, for a caller that has no
    run at hand yet (the types are every case's); returns whether it compiled."""
    from fivdisc._kernels import tangent
    from fivdisc.compilation import needs_compiling

    if _cores() < 2 or not needs_compiling(tangent.saltation):
        return False
    return compile_split(default_run(tangents=True))
