"""Re-contact: the perfectly plastic impact on every active contact (Moreau's law).

Velocities ``u = (qdot, zdot_1 .. zdot_S)`` with mass matrix ``W = diag(M, m_1 .. m_S)``
jump by ``W^-1 sum_i lambda_i a_i`` where contact i's gap velocity is
``gammadot_i = a_i.u - b_i = sigma_i (zdot_i - g_i.qdot - phidot_i g'_i.q)`` and the
compressive impulses solve the linear complementarity problem

    lambda >= 0,  gammadot+ = gammadot- + D lambda >= 0,  lambda.gammadot+ = 0,
    D = A W^-1 A^T  (symmetric positive definite).

A contact that would need a tensile impulse is released. With a single contact the
problem has the closed form of the paper's Eqs. 54-56, used as such. Positions and
phidot never jump. The maps take real or complex states (decisions on real parts), so
that their Jacobians come from the complex step.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from fivdisc.core.dynamics import solve_small
from fivdisc.core.sizes import n_dynamic, sizes
from fivdisc.model.layout import (
    D_MINV,
    E_IMPACT,
    E_SURFACE,
    S_MASS,
    S_SIGMA,
)


@njit(cache=True)
def contact_velocity(j, y, mdl, wk):
    """Normal velocity of the disc's surface under slider j [m/s]; the work array ``wk``
    must hold the mode shapes at ``y`` (rows j and S + j)."""
    n, ns, half = sizes(mdl)
    phid = y[half + n + j]
    acc = 0.0
    for i in range(n):
        acc += wk[j, i] * y[half + i] + phid * wk[ns + j, i] * y[i]
    return acc


@njit(cache=True)
def _kinetic(y, mdl, members, count):
    """Kinetic energy of the disc modes and of the normal motion of ``members`` [J]."""
    n, ns, half = sizes(mdl)
    acc = 0.0
    for i in range(n):
        acc += 0.5 * y[half + i] * y[half + i] / mdl.disc[D_MINV, i]
    for a in range(count):
        j = members[a]
        zd = y[half + n + ns + j]
        acc += 0.5 * mdl.slider[S_MASS, j] * zd * zd
    return acc


@njit(cache=True)
def _book(y, mdl, before, u_minus, members, count):
    """Add the impact's kinetic energy loss and the surface's work to the accumulators.

    ``before`` is the kinetic energy before, ``u_minus`` the velocities before (the
    layout of ``y``): the loss is 1/2 |du|_W^2, the rest of the change is lambda.b.
    """
    e0 = n_dynamic(mdl)
    if y.shape[0] <= e0:
        return
    n, ns, half = sizes(mdl)
    loss = 0.0
    for i in range(n):
        du = y[half + i] - u_minus[half + i]
        loss += 0.5 * du * du / mdl.disc[D_MINV, i]
    for a in range(count):
        j = members[a]
        du = y[half + n + ns + j] - u_minus[half + n + ns + j]
        loss += 0.5 * mdl.slider[S_MASS, j] * du * du
    change = _kinetic(y, mdl, members, count) - before
    y[e0 + E_IMPACT] -= loss
    y[e0 + E_SURFACE] += change + loss


@njit(cache=True)
def single_impact(j, y, mdl, wk):
    """Plastic impact of slider j alone (paper Eqs. 47-56): slider and disc leave with one
    normal velocity. The work array ``wk`` must hold the mode shapes at ``y``."""
    n, ns, half = sizes(mdl)
    minv = mdl.disc[D_MINV]
    members = np.array([j])
    u_minus = y.copy()
    before = _kinetic(y, mdl, members, members.shape[0])
    m = mdl.slider[S_MASS, j]
    zd_minus = y[half + n + ns + j]
    phid = y[half + n + j]
    ratio = 0.0
    disc = 0.0
    for i in range(n):
        ratio += m * wk[j, i] * wk[j, i] * minv[i]
        disc += wk[j, i] * y[half + i] + phid * wk[ns + j, i] * y[i]
    zd_plus = (disc + ratio * zd_minus) / (1.0 + ratio)
    for i in range(n):
        y[half + i] -= m * wk[j, i] * minv[i] * (zd_plus - zd_minus)
    y[half + n + ns + j] = zd_plus
    _book(y, mdl, before, u_minus, members, members.shape[0])


# The active system's first row in its own array; not a literal (see the package docstring).
_FIRST_ROW = np.int64(0)


@njit(cache=True)
def _solve_active(a, b, x, act, m):
    """x[act] = solution of a[act, act] x = b[act]; x = 0 elsewhere."""
    idx = np.empty(m, np.int64)
    k = np.int64(0)
    for i in range(m):
        x[i] = 0.0
        if act[i]:
            idx[k] = i
            k += 1
    if k == 0:
        return
    sub = np.empty((k, k + 1), b.dtype)
    for r in range(k):
        sub[r, k] = b[idx[r]]
        for c in range(k):
            sub[r, c] = a[idx[r], idx[c]]
    solve_small(sub, _FIRST_ROW, k)
    for r in range(k):
        x[idx[r]] = sub[r, k]


@njit(cache=True)
def solve_lcp(dmat, gam, forced, lam, m):
    """Solve ``lam >= 0, w = gam + D lam >= 0, lam.w = 0`` exactly (Murty's least-index
    principal pivoting, finite for the positive definite D). ``forced[i]`` makes contact
    i bilateral (``w_i = 0``, any sign of ``lam_i``). Returns ``w``."""
    act = np.ones(m, np.bool_)
    w = np.empty(m, gam.dtype)
    neg = np.empty(m, gam.dtype)
    scale = 0.0
    for i in range(m):
        scale = max(scale, abs(gam[i].real))
    tol_w = 1e-13 * scale
    for _ in range(4 * (1 << m) + 4):
        for i in range(m):
            neg[i] = -gam[i]
        _solve_active(dmat, neg, lam, act, m)
        lam_scale = 0.0
        for i in range(m):
            lam_scale = max(lam_scale, abs(lam[i].real))
        tol_l = 1e-13 * lam_scale
        flip = -1
        for i in range(m):
            acc = gam[i]
            for k in range(m):
                acc += dmat[i, k] * lam[k]
            w[i] = acc
        for i in range(m):
            if act[i] and not forced[i] and lam[i].real < -tol_l:
                flip = i
                break
            if not act[i] and w[i].real < -tol_w:
                flip = i
                break
        if flip < 0:
            for i in range(m):
                if act[i]:
                    w[i] = 0.0
            return w
        act[flip] = not act[flip]
    return w


@njit(cache=True)
def contact_impact(members, count, y, mdl, wk, forced, w_out):
    """Plastic impact on the contacts ``members[:count]`` (the landing slider and those
    in contact), by the complementarity problem. Rows of g, g' in ``wk`` must hold the
    mode shapes at ``y`` (work array ``wk``); the contacts' ``zdot`` must hold their contact
    velocities.

    ``forced`` marks contacts that must stay closed. On return ``w_out[a]`` is the gap
    velocity of member a after the impact (> 0: it leaves the disc).
    """
    n, ns, half = sizes(mdl)
    minv = mdl.disc[D_MINV]
    sigma = mdl.slider[S_SIGMA]
    mass = mdl.slider[S_MASS]
    u_minus = y.copy()
    before = _kinetic(y, mdl, members, count)
    dmat = np.zeros((count, count), y.dtype)
    gam = np.empty(count, y.dtype)
    lam = np.empty(count, y.dtype)
    for a in range(count):
        ja = members[a]
        for b in range(count):
            jb = members[b]
            acc = 0.0
            for i in range(n):
                acc += wk[ja, i] * wk[jb, i] * minv[i]
            if ja == jb:
                acc += 1.0 / mass[ja]
            dmat[a, b] = sigma[ja] * sigma[jb] * acc
        gam[a] = sigma[ja] * (y[half + n + ns + ja] - contact_velocity(ja, y, mdl, wk))
    w = solve_lcp(dmat, gam, forced, lam, count)
    for a in range(count):
        ja = members[a]
        sl = lam[a] * sigma[ja]
        for i in range(n):
            y[half + i] -= sl * wk[ja, i] * minv[i]
        y[half + n + ns + ja] += sl / mass[ja]
        w_out[a] = w[a]
    _book(y, mdl, before, u_minus, members, count)
