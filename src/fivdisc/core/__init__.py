"""Compiled kernels (numba). Importing the package keys their on-disk cache to the
sources of all of them (:mod:`fivdisc.core.cache`).

Integer and boolean constants that the kernels pass to compiled functions are numpy
scalars (``dynamics.RIGHT``, ``switch.MODE_START``, ...), and so are variables that start
from a constant and are passed on (counters, "none found yet"): numba types a Python
``int`` or ``bool`` there as a literal and compiles the callee once per value, which
made the first compilation about 40 % longer. ``tests/core/test_kernel_literals.py`` checks
the call sites.

Functions of the cold path called from one or two places (the start's phases, a
switch, the settling of the other sliders, the restart after a switch, an impact, the
first step size, one output sample) are inlined into their callers
(``inline="always"``): numba links every callee into each separately compiled function
and optimises and emits it there again, so each such function lengthened the first
compilation (``benchmarks/bench_compile.py`` measures it). ``switch._switch`` is
written as one loop over the switches at one instant so that each of its helpers has a
single call site.
"""

from fivdisc.core.cache import install

install()
