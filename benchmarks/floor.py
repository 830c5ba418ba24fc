"""The floor of the kernel's cost per step: a plain numba Dormand-Prince 5(4) loop with
the same step-size control over a linear system of the same state size.

``floor_cost(model, duration)`` integrates ``y' = J y`` with J the exact Jacobian of the
model's slip equations at a generic state (so the step sizes resemble the real run's),
no events, no contact solve, no output, and returns the median wall time per accepted
step [s] and the steps taken. Anything the real kernel spends beyond this is the price of
its right-hand side, events and output.

Run ``python benchmarks/floor.py``: it prints, for the paper's Fig. 10 case (one slider,
7 modal coordinates), the kernel's cost per accepted step without output and with the
10 kHz output, each as a ratio to the floor measured in the same run.
"""

from __future__ import annotations

import time

import numpy as np
from numba import njit

from fivdisc._kernels.dopri5 import A, E
from fivdisc._kernels.dynamics import complex_step_jacobian

# The kernel's own step-control constants: the floor must take the steps the kernel would
# (its PI controller below repeats the kernel's lines on purpose, without events).
from fivdisc._kernels.integrate import _BETA, _EXPO1


@njit(cache=True)
def _matvec(jac, y, out):
    for i in range(y.shape[0]):
        acc = 0.0
        for j in range(y.shape[0]):
            acc += jac[i, j] * y[j]
        out[i] = acc


@njit(cache=True)
def _dopri_linear(jac, y, t_final, rtol, atol):
    """DOPRI5 with the kernel's PI control on y' = J y; returns accepted steps."""
    ns = y.shape[0]
    k = np.zeros((7, ns))
    ytmp = np.empty(ns)
    err_vec = np.empty(ns)
    _matvec(jac, y, k[0])
    t = 0.0
    h = 1e-6
    err_old = 1e-4
    steps = 0
    after_reject = False
    while t < t_final:
        hs = min(h, t_final - t)
        for st in range(1, 7):
            ytmp[:] = y
            for j in range(st):
                a = hs * A[st, j]
                if a != 0.0:
                    for i in range(ns):
                        ytmp[i] += a * k[j, i]
            _matvec(jac, ytmp, k[st])
        err_vec[:] = 0.0
        for st in range(7):
            a = hs * E[st]
            if a != 0.0:
                for i in range(ns):
                    err_vec[i] += a * k[st, i]
        acc = 0.0
        for i in range(ns):
            sc = atol + rtol * max(abs(y[i]), abs(ytmp[i]))
            acc += (err_vec[i] / sc) ** 2
        err = np.sqrt(acc / ns)
        if err > 1.0:
            h = hs / min(5.0, err**_EXPO1 / 0.9)
            after_reject = True
            continue
        steps += 1
        pi = err**_EXPO1 / err_old**_BETA if err > 0.0 else 0.0
        fac = min(5.0, max(0.1, 0.9 / pi)) if pi > 0.0 else 5.0
        err_old = max(err, 1e-4)
        if after_reject:
            fac = min(fac, 1.0)
        after_reject = False
        y[:] = ytmp
        for i in range(ns):
            k[0, i] = k[6, i]
        t += hs
        h = hs * fac
    return steps


def floor_cost(model, duration: float, rtol: float = 1e-6, atol: float = 1e-9,
               repeat: int = 3) -> tuple[float, int]:
    """Median wall time per accepted step [s] of the linear floor, and its step count."""
    from fivdisc.analysis.equilibrium import slip_phases

    ph, sg = slip_phases(model)
    y = np.zeros(model.state_size)
    y[: model.n] = 1e-6
    y[model.index("phi_dot")] = 1.0
    jac = complex_step_jacobian(0.0, y, ph, sg, model.kernel_args)
    # The sliders' own z, zdot are held in contact; keep them so (zero rows).
    for j in range(model.n_sliders):
        jac[model.index("z", j)] = 0.0
        jac[model.index("z_dot", j)] = 0.0
    start = np.zeros(model.state_size)
    start[: model.n] = 1e-5
    start[model.n + 2 * model.n_sliders : 2 * model.n + 2 * model.n_sliders] = 1e-2
    _dopri_linear(jac, start.copy(), 1e-3, rtol, atol)
    costs = []
    steps = 0
    for _ in range(repeat):
        t0 = time.perf_counter()
        steps = _dopri_linear(jac, start.copy(), duration, rtol, atol)
        costs.append((time.perf_counter() - t0) / steps)
    return float(np.median(costs)), steps


def main() -> None:
    from bench_family import CASES, per_step
    from fivdisc import Case, build_model

    fig10 = CASES["fig10"]
    quiet = {**fig10, "simulation": {**fig10["simulation"], "output_rate": 0.1}}
    kernel = per_step({"no output": quiet, "10 kHz output": fig10})
    floor, steps = floor_cost(build_model(Case(**fig10)), 35.0)
    print(f"floor (linear DOPRI5, same state size): {floor * 1e6:.2f} us per step "
          f"({steps} steps)")
    for label, c in kernel.items():
        print(f"kernel, {label:14s}: {c['cost'] * 1e6:.2f} us per step ({c['steps']} steps)"
              f" -> {c['cost'] / floor:.2f} x floor")


if __name__ == "__main__":
    main()
