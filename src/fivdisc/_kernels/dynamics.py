"""Equations of motion of the slider-on-disc system (numba, arrays in and out).

State vector ``y`` of length ``2 n + 4`` for ``n`` modal coordinates::

    y = [q_0 .. q_{n-1}, phi, z, qdot_0 .. qdot_{n-1}, phidot, zdot]

``z`` and ``zdot`` are the slider's own normal displacement and velocity; they are
integrated only in separation (in contact the slider follows the disc and they are
held constant). Every function here is written without comparisons on the state so
that it also compiles for complex arrays (complex-step Jacobians).

The model tuple ``mdl`` is ``(par, li, R0, minv, kd, ml2, gyr, sgn, partner, knots,
coef)``: ``par`` scalar parameters indexed by the ``P_*`` constants; per modal
coordinate the nodal-diameter count ``li``, the mode shape at the track ``R0``, the
inverse modal mass ``minv = 1/M``, the modal stiffness ``kd = M omega^2``,
``ml2 = M l^2``, the gyroscopic factor ``gyr = sgn l M``, ``sgn`` = +1 for a cosine (C)
and -1 for a sine (D) coordinate, and ``partner`` = index of the other member of a
doublet (-1 for l = 0); ``knots``/``coef`` are the piecewise-cubic speed profile
(positions ``M_*`` below).
"""

from __future__ import annotations

import numpy as np
from numba import njit

SLIP = 0
STICK = 1
SEPARATION = 2

P_MASS = 0
P_INERTIA = 1
P_KZ = 2
P_CZ = 3
P_KPHI = 4
P_CPHI = 5
P_N0 = 6
P_R0 = 7
P_HALF_H_OVER_R0 = 8
P_MUS = 9
P_MU0 = 10
P_MU1 = 11
P_ALPHA = 12
P_OMDOT = 13
P_IMPACT = 14
P_LMAX = 15
N_PAR = 16

M_PAR = 0
M_MINV = 3
M_KNOTS = 9
M_COEF = 10


@njit(cache=True)
def speed_at(t, knots, coef, right):
    """Disc speed and acceleration at ``t`` from the piecewise-cubic profile.

    At a knot, ``right`` selects the right limit (start of a step) or the left
    limit (inside or at the end of a step), so a kink is seen from the side the
    step lies on.
    """
    if right:
        k = np.searchsorted(knots, t, side="right") - 1
    else:
        k = np.searchsorted(knots, t, side="left") - 1
    if k < 0:
        k = 0
    tau = t - knots[k]
    c0 = coef[k, 0]
    c1 = coef[k, 1]
    c2 = coef[k, 2]
    c3 = coef[k, 3]
    om = c0 + tau * (c1 + tau * (c2 + tau * c3))
    omd = c1 + tau * (2.0 * c2 + 3.0 * tau * c3)
    return om, omd


@njit(cache=True)
def evaluate(t, y, phase, s, right, mdl, work, dy):
    """Time derivative ``dy`` of the state in the given phase.

    Returns ``(N, f, w_c, wdot_c, v)``: normal force [N], friction force on the
    slider [N] (positive along +phi), the disc's transverse displacement [m] and
    velocity [m/s] under the slider, and the relative speed ``Omega - phidot``
    [rad/s]. ``work`` is a ``(5, m)`` scratch array of the state's dtype.
    """
    par, li, R0, minv, kd, ml2, gyr, sgn, partner, knots, coef = mdl
    n = li.shape[0]
    m = par[P_MASS]
    inertia = par[P_INERTIA]
    om, omd = speed_at(t, knots, coef, right)
    eps = par[P_OMDOT]

    phi = y[n]
    phid = y[2 * n + 2]
    if phase == STICK:
        phid = phid * 0.0 + om
    zero = phi * 0.0

    g = work[0]
    gp = work[1]
    fq = work[2]
    cl = work[3]
    sl = work[4]
    lmax = int(par[P_LMAX])
    # cos(l phi), sin(l phi) by the Chebyshev recurrence: two trig calls per evaluation.
    c1 = np.cos(phi)
    s1 = np.sin(phi)
    cl[0] = 1.0 + zero
    sl[0] = zero
    if lmax >= 1:
        cl[1] = c1
        sl[1] = s1
    for k in range(1, lmax):
        cl[k + 1] = 2.0 * c1 * cl[k] - cl[k - 1]
        sl[k + 1] = 2.0 * c1 * sl[k] - sl[k - 1]

    om2 = om * om
    wc = zero
    wcd = zero
    gpq = zero
    gpqd = zero
    l2gq = zero
    s_gf = zero
    s_gg = zero
    s_ggp = zero
    for j in range(n):
        lj = li[j]
        # Branch-free g = R cos(l phi) (C, sgn = 1) or R sin(l phi) (D, sgn = -1).
        cs = 0.5 + 0.5 * sgn[j]
        sn = 0.5 - 0.5 * sgn[j]
        gj = R0[j] * (cs * cl[lj] + sn * sl[lj])
        gpj = lj * R0[j] * (sn * cl[lj] - cs * sl[lj])
        g[j] = gj
        gp[j] = gpj
        qj = y[j]
        qdj = y[n + 2 + j]
        wc += gj * qj
        wcd += gj * qdj
        gpq += gpj * qj
        gpqd += gpj * qdj
        l2gq += lj * lj * gj * qj
        p = partner[j]
        fj = -(kd[j] - ml2[j] * om2) * qj
        if p >= 0:
            fj -= gyr[j] * (2.0 * om * y[n + 2 + p] + eps * omd * y[p])
        fq[j] = fj
        s_gf += gj * fj * minv[j]
        s_gg += gj * gj * minv[j]
        s_ggp += gj * gpj * minv[j]
        dy[j] = qdj
    wcd += phid * gpq
    v = om - phid

    dy[n] = phid
    if phase == SEPARATION:
        for j in range(n):
            dy[n + 2 + j] = fq[j] * minv[j]
        dy[2 * n + 2] = (-par[P_CPHI] * phid - par[P_KPHI] * phi) / inertia
        dy[n + 1] = y[2 * n + 3]
        dy[2 * n + 3] = (-par[P_N0] - par[P_CZ] * y[2 * n + 3] - par[P_KZ] * y[n + 1]) / m
        return zero, zero, wc, wcd, v

    dy[n + 1] = zero
    dy[2 * n + 3] = zero
    # Normal force without the slider-acceleration terms that depend on the unknowns.
    n_known = (
        par[P_N0]
        + m * (2.0 * phid * gpqd - phid * phid * l2gq)
        + par[P_CZ] * wcd
        + par[P_KZ] * wc
    )
    hh = par[P_HALF_H_OVER_R0]
    r0 = par[P_R0]
    if phase == SLIP:
        mu = par[P_MU1] + (par[P_MU0] - par[P_MU1]) * np.exp(-par[P_ALPHA] * r0 * s * v)
        smu = s * mu
        fphi = -par[P_CPHI] * phid - par[P_KPHI] * phi
        # Rank-one elimination of N from [M q'' + N e = Fq; I phi'' = Fphi + r0 s mu N;
        # N = n_known + m (g.q'' + g'.q phi'')] with e = g - hh s mu g': O(n), no solve.
        nf = (n_known + m * s_gf + m * gpq * fphi / inertia) / (
            1.0 + m * (s_gg - hh * smu * s_ggp) - m * gpq * r0 * smu / inertia
        )
        f = smu * nf
        for j in range(n):
            dy[n + 2 + j] = (fq[j] - nf * (g[j] - hh * smu * gp[j])) * minv[j]
        dy[2 * n + 2] = (fphi + r0 * f) / inertia
        return nf, f, wc, wcd, v

    # Stick: phi'' = Omegadot, friction is the reaction of the in-plane oscillator.
    f = (inertia * omd + par[P_CPHI] * om + par[P_KPHI] * phi) / r0
    nf = (n_known + m * (s_gf + hh * f * s_ggp) + m * gpq * omd) / (1.0 + m * s_gg)
    for j in range(n):
        dy[n + 2 + j] = (fq[j] + hh * f * gp[j] - nf * g[j]) * minv[j]
    dy[2 * n + 2] = omd + zero
    return nf, f, wc, wcd, v


@njit(cache=True)
def event_values(phase, s, nf, f, wc, v, y, par, out):
    """Event functions of a phase, positive while the phase holds; unused slots +inf."""
    n = (y.shape[0] - 4) // 2
    out[0] = np.inf
    out[1] = np.inf
    out[2] = np.inf
    if phase == SLIP:
        out[0] = s * v
        out[1] = nf
    elif phase == STICK:
        mus = par[P_MUS]
        out[0] = mus * nf - f
        out[1] = mus * nf + f
        out[2] = nf
    else:
        out[0] = y[n + 1] - wc


@njit(cache=True)
def plastic_impact(y, mdl, work):
    """Perfectly plastic re-contact (paper Eqs. 47-56): positions kept, slider and disc
    leave with one normal velocity. ``work[0]``/``work[1]`` must hold g, g' at ``y``."""
    par = mdl[M_PAR]
    minv = mdl[M_MINV]
    n = minv.shape[0]
    m = par[P_MASS]
    g = work[0]
    gp = work[1]
    zd_minus = y[2 * n + 3]
    ratio = 0.0
    disc = 0.0
    for j in range(n):
        ratio += m * g[j] * g[j] * minv[j]
        disc += g[j] * y[n + 2 + j] + y[2 * n + 2] * gp[j] * y[j]
    zd_plus = (disc + ratio * zd_minus) / (1.0 + ratio)
    for j in range(n):
        y[n + 2 + j] -= m * g[j] * minv[j] * (zd_plus - zd_minus)
    y[2 * n + 3] = zd_plus


@njit(cache=True)
def complex_step_jacobian(t, y, phase, s, mdl):
    """Exact Jacobian d(dy/dt)/dy of a contact or separation phase by the complex step.

    Each column costs one complex evaluation; the result has no subtractive
    cancellation, so it is exact to rounding (step 1e-30).
    """
    ns = y.shape[0]
    width = max(ns, int(mdl[0][P_LMAX]) + 2)
    work = np.zeros((5, width), dtype=np.complex128)
    yc = np.empty(ns, dtype=np.complex128)
    dy = np.empty(ns, dtype=np.complex128)
    jac = np.empty((ns, ns))
    step = 1e-30
    for i in range(ns):
        for j in range(ns):
            yc[j] = y[j]
        yc[i] = y[i] + 1j * step
        evaluate(t, yc, phase, s, True, mdl, work, dy)
        for j in range(ns):
            jac[j, i] = dy[j].imag / step
    return jac
