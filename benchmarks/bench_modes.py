"""Time 40 disc modes (k <= 3, l <= 9) of the paper's Table 1 plate, cold, against a baseline.

Run ``python benchmarks/bench_modes.py``. The baseline is what one writes first: for every
mode on its own, an unscaled determinant built from scipy's ``jvp``/``yvp``/``ivp``/``kvp``,
evaluated point by point on the same dense grid, the (k + 1)-th sign change refined by brentq,
and the modal mass by adaptive ``quad``; nothing is shared between modes. It also serves as a
cross-check: its frequencies and its R(r0)^2 / M at the slider's radius r0 (the quantity that
enters the dynamics, free of the shape's normalisation) must agree with :mod:`fivdisc.model.plate`.
"""

from __future__ import annotations

import math
import statistics
import time

import numpy as np
from scipy import integrate, optimize, special

from fivdisc.case import Case
from fivdisc.model.plate import AnnularPlate, clear_cache

# The paper's Table 1 plate and track radius, from the case defaults.
_DEFAULT = Case()
TABLE1 = {key: getattr(_DEFAULT.disc, key) for key in (
    "inner_radius", "outer_radius", "thickness", "density", "youngs_modulus", "poisson_ratio")}
R0 = _DEFAULT.slider.track_radius  # [m]
PAIRS = [(k, n) for n in range(10) for k in range(4)]
REPEATS = 7
BASELINE_REPEATS = 3


def fivdisc_modes() -> list[tuple[float, float]]:
    """(omega [rad/s], R(r0)^2 / M [1/kg]) of every pair, from a cold cache."""
    clear_cache()
    plate = AnnularPlate(**TABLE1)
    return [(mode.omega, mode.shape(R0) ** 2 / mode.modal_mass) for mode in plate.modes(PAIRS)]


def _baseline_columns(n: int, beta: float, r: float, d: int) -> np.ndarray:
    """d-th r-derivative of J_n, Y_n, I_n, K_n at beta r, unscaled."""
    x = beta * r
    derivatives = (special.jvp, special.yvp, special.ivp, special.kvp)
    return np.array([f(n, x, d) * beta**d for f in derivatives])


def _baseline_matrix(n: int, beta: float) -> np.ndarray:
    a, b, nu = TABLE1["inner_radius"], TABLE1["outer_radius"], TABLE1["poisson_ratio"]
    ra = [_baseline_columns(n, beta, a, d) for d in range(2)]
    rb = [_baseline_columns(n, beta, b, d) for d in range(4)]
    n2 = n * n
    moment = rb[2] + nu * (rb[1] / b - n2 * rb[0] / b**2)
    shear = rb[3] + rb[2] / b - (1 + (2 - nu) * n2) * rb[1] / b**2 + (3 - nu) * n2 * rb[0] / b**3
    return np.array([ra[0], ra[1], moment, shear])


def baseline_modes() -> list[tuple[float, float]]:
    """The same 40 (omega, R(r0)^2 / M) pairs by the naive method."""
    a, b = TABLE1["inner_radius"], TABLE1["outer_radius"]
    rho_h = TABLE1["density"] * TABLE1["thickness"]
    plate = AnnularPlate(**TABLE1)
    stiffness = math.sqrt(plate.flexural_rigidity / rho_h)
    step = math.pi / (b - a) / 32  # the grid density fivdisc.model.plate uses
    out = []
    for k, n in PAIRS:

        def det(beta: float, n: int = n) -> float:
            return float(np.linalg.det(_baseline_matrix(n, beta)))

        beta, previous, found = 0.5 * step, det(0.5 * step), -1
        while found < k:
            value = det(beta + step)
            if previous * value < 0:
                found += 1
                root = optimize.brentq(det, beta, beta + step, xtol=1e-14, rtol=1e-15)
            beta, previous = beta + step, value
        _, _, vt = np.linalg.svd(_baseline_matrix(n, root))
        coefficients = vt[-1]

        def shape(r: float, n: int = n, root: float = root, c: np.ndarray = coefficients) -> float:
            return float(_baseline_columns(n, root, r, 0) @ c)

        integral = integrate.quad(lambda r: shape(r) ** 2 * r, a, b, epsrel=1e-10)[0]
        mass = rho_h * math.pi * integral * (2 if n == 0 else 1)
        out.append((root**2 * stiffness, shape(R0) ** 2 / mass))
    return out


def _median_seconds(func, repeats: int) -> tuple[float, list[tuple[float, float]]]:
    times, result = [], []
    for _ in range(repeats):
        start = time.perf_counter()
        result = func()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def main() -> None:
    ours, ours_result = _median_seconds(fivdisc_modes, REPEATS)
    naive, naive_result = _median_seconds(baseline_modes, BASELINE_REPEATS)
    ours_array, naive_array = np.array(ours_result), np.array(naive_result)
    difference = np.max(np.abs(ours_array / naive_array - 1), axis=0)
    print(f"40 modes (k <= 3, l <= 9), Table 1 plate, cold cache, median of {REPEATS} runs")
    print(f"  fivdisc.model.plate     : {ours:.4f} s")
    print(f"  naive baseline    : {naive:.4f} s (median of {BASELINE_REPEATS})")
    print(f"  speed-up          : {naive / ours:.1f}x")
    print(f"  max relative difference, omega       : {difference[0]:.1e}")
    print(f"  max relative difference, R(r0)^2 / M : {difference[1]:.1e}")


if __name__ == "__main__":
    main()
