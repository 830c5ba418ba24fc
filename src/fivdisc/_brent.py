"""Brent's root bracketing, step for step as :func:`scipy.optimize.brentq` takes it.

:mod:`fivdisc.plate` finds the disc's frequency parameters and the peaks of its mode
shapes with it. ``scipy.optimize`` would do the same, but importing it (with
``scipy.linalg``, ``scipy.sparse`` and ``scipy.fft`` that it imports) is a third of a
second of every ``fivdisc simulate`` (``benchmarks/bench_startup.py``), for a routine
of twenty lines. Each step here is the same floating-point operation, in the same order,
as scipy's compiled routine takes, so the roots are the same numbers to the last bit
(``tests/test_plate.py`` compares them with scipy's over a range of plates), and so is
every model built from them.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable

__all__ = ["brentq"]


def brentq(f: Callable[[float], float], a: float, b: float, xtol: float = 2e-12,
           rtol: float = 4 * sys.float_info.epsilon, maxiter: int = 100) -> float:
    """A zero of ``f`` in ``[a, b]``, where ``f(a)`` and ``f(b)`` differ in sign.

    Parameters
    ----------
    f
        A continuous function of one real variable.
    a, b
        The bracket's ends.
    xtol, rtol
        The zero is found to within ``xtol + rtol |x|``; the defaults are
        :func:`scipy.optimize.brentq`'s.
    maxiter
        Most iterations.

    Returns
    -------
    float
        The zero, the same number :func:`scipy.optimize.brentq` returns for the same
        arguments.

    Raises
    ------
    ValueError
        If ``f(a)`` and ``f(b)`` have the same sign, or ``f`` is NaN somewhere.
    RuntimeError
        If it did not converge in ``maxiter`` iterations.

    Notes
    -----
    Brent (1973), *Algorithms for Minimization without Derivatives*, ch. 4: of the
    bracket ``[x_blk, x_cur]`` with ``|f(x_cur)| <= |f(x_blk)|``, the next point is an
    inverse quadratic (or secant) step from ``x_cur`` if it is short enough, else the
    midpoint; a step is at least half the tolerance.
    """

    def value(x: float) -> float:
        fx = float(f(x))
        if math.isnan(fx):
            raise ValueError(f"the function is NaN at x = {x!r}")
        return fx

    xpre, xcur = float(a), float(b)
    fpre, fcur = value(xpre), value(xcur)
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    if math.copysign(1.0, fpre) == math.copysign(1.0, fcur):
        raise ValueError(f"f({a!r}) and f({b!r}) must differ in sign")
    xblk = fblk = spre = scur = 0.0
    for _ in range(maxiter):
        if fpre != 0.0 and fcur != 0.0 and (
                math.copysign(1.0, fpre) != math.copysign(1.0, fcur)):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + rtol * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # secant
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:  # inverse quadratic
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):
                spre, scur = scur, stry
            else:
                spre = scur = sbis
        else:
            spre = scur = sbis
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > delta else (delta if sbis > 0 else -delta)
        fcur = value(xcur)
    raise RuntimeError(f"no convergence in {maxiter} iterations (last x = {xcur!r})")
