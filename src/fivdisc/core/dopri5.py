"""Dormand-Prince 5(4) coefficients and its fourth-order dense output (Hairer's DOPRI5).

References
----------
J. R. Dormand, P. J. Prince, "A family of embedded Runge-Kutta formulae",
J. Comput. Appl. Math. 6 (1980) 19-26. E. Hairer, S. P. Norsett, G. Wanner,
"Solving Ordinary Differential Equations I", 2nd ed., Springer 1993, II.5-II.6.
"""

from __future__ import annotations

import numpy as np
from numba import njit

C = np.array([0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0])
A = np.array(
    [
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
        [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
        [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0, 0.0],
        [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0, 0.0],
        [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0],
    ]
)
# Fifth-order weights (the last row of A: first same as last) minus fourth-order weights.
E = np.array(
    [
        71.0 / 57600.0,
        0.0,
        -71.0 / 16695.0,
        71.0 / 1920.0,
        -17253.0 / 339200.0,
        22.0 / 525.0,
        -1.0 / 40.0,
    ]
)
# Dense-output weights of the fifth interpolation coefficient.
D = np.array(
    [
        -12715105075.0 / 11282082432.0,
        0.0,
        87487479700.0 / 32700410799.0,
        -10690763975.0 / 1880347072.0,
        701980252875.0 / 199316789632.0,
        -1453857185.0 / 822651844.0,
        69997945.0 / 29380423.0,
    ]
)


@njit(cache=True, _nrt=False)
def dense_coefficients(y0, y1, k, h, rc):
    """Fill ``rc`` (5, n) with the continuous-extension coefficients of one step."""
    n = y0.shape[0]
    for i in range(n):
        ydiff = y1[i] - y0[i]
        bspl = h * k[0, i] - ydiff
        rc[0, i] = y0[i]
        rc[1, i] = ydiff
        rc[2, i] = bspl
        rc[3, i] = ydiff - h * k[6, i] - bspl
        acc = 0.0
        for st in range(7):
            acc += D[st] * k[st, i]
        rc[4, i] = h * acc


@njit(cache=True, inline="always")
def dense_one(rc, theta, i):
    """Coordinate ``i`` at fraction ``theta`` of the step from its dense-output
    coefficients."""
    th1 = 1.0 - theta
    return rc[0, i] + theta * (rc[1, i] + th1 * (rc[2, i] + theta * (rc[3, i] + th1 * rc[4, i])))


@njit(cache=True, _nrt=False)
def dense_eval(rc, theta, out):
    """State at fraction ``theta`` of the step from its dense-output coefficients."""
    for i in range(rc.shape[1]):
        out[i] = dense_one(rc, theta, i)
