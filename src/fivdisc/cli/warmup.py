"""``fivdisc warmup``: compile every kernel now, before any command needs it."""

from __future__ import annotations

import click


@click.command("warmup")
def warmup() -> None:
    """Compile every kernel now, once per installation, so that no command waits for it.

    numba compiles fivdisc's kernels at their first use and keeps them in its cache:
    without this, the first simulation, the first orbit (Lyapunov exponents,
    continuation) and the first stability analysis each wait for theirs. This compiles
    them all in one go, the plain kernel and the one with tangent vectors each shared
    between two processes on a machine with two cores or more, and says what it compiles.
    Where they are compiled already it only loads them (a few seconds).
    """
    import time

    from fivdisc.analysis.exponents import warm_tangent_kernel
    from fivdisc.analysis.stability import linear_stability
    from fivdisc.case import Case
    from fivdisc.core import integrate
    from fivdisc.engine.compilation import compile_notice
    from fivdisc.engine.simulation import warm_kernel
    from fivdisc.engine.split_compile import compile_split, default_run

    start = time.perf_counter()
    with compile_notice(integrate.run, what="simulation kernel"):
        # The helper goes on with the tangent kernel's share while this process
        # finishes the plain kernel (compiled by the run's first call).
        run = default_run()
        compile_split(run, tangents=True)
        run.advance(0.0)
        warm_kernel()
    warm_tangent_kernel(show=True)
    # The right-hand side's Jacobian at the sliding equilibrium (fivdisc stability).
    linear_stability(Case())
    click.echo(f"every kernel is compiled ({time.perf_counter() - start:.0f} s); "
               "later runs load them")
