"""Equations of motion of S sliders on the spinning disc (numba, arrays in and out).

The state layout and the model tuple are described in :mod:`fivdisc._kernels.layout`.
Every function here is written without comparisons on the state's value in the
arithmetic that produces derivatives (phases and signs are passed in), so that it also
compiles for complex arrays: complex-step Jacobians come from the same code.

The accelerations solve a linear system at every evaluation: the disc's is diagonal
(modal masses) plus one row and column per slider in contact (its normal force). The
normal forces are eliminated first: a system of one equation per slider in contact
(its matrix is the capacitance matrix of the Woodbury identity), then the disc's
accelerations follow in O(n S). For one slider this is the closed-form rank-one
elimination, operation for operation.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from fivdisc._kernels.layout import (
    A_F,
    A_FPHI,
    A_GPQ,
    A_GPQD,
    A_KNOWN,
    A_L2GQ,
    A_N,
    A_PHID,
    A_SGF,
    A_SGG,
    A_SGGP,
    A_SMU,
    A_V,
    A_WC,
    A_WCD,
    E_DISC_DAMPING,
    E_DRIVE,
    E_FRICTION,
    E_MOMENT,
    E_SLIDER_DAMPING,
    E_SLOPE,
    F_ALPHA,
    F_DELTA,
    F_LAW,
    F_MU0,
    F_MU1,
    F_MUS,
    F_MUV,
    F_VS,
    LAW_EXPONENTIAL,
    LAW_STRIBECK,
    N_AUX,
    O_DAMPED,
    O_LMAX,
    O_OMDOT,
    SEPARATION,
    SLIP,
    STICK,
    n_dynamic,
    sizes,
)


@njit(cache=True, inline="always")
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


@njit(cache=True, inline="always")
def kinetic_friction(mdl, r, s, v):
    """Kinetic friction coefficient at relative speed ``v`` [rad/s] in slip with sign ``s``.

    The sliding speed is ``u = r s v`` [m/s]; inside a Runge-Kutta step that crosses
    v = 0 it may be slightly negative, where each law is continued smoothly: the
    exponential law analytically, the Stribeck exponent oddly, the table linearly.
    """
    fr = mdl.fric
    law = fr[F_LAW]
    if law == LAW_EXPONENTIAL:
        return fr[F_MU1] + (fr[F_MU0] - fr[F_MU1]) * np.exp(-fr[F_ALPHA] * r * s * v)
    u = r * s * v
    if law == LAW_STRIBECK:
        x = u / fr[F_VS]
        if x.real >= 0.0:
            e = x ** fr[F_DELTA]
        else:
            e = -((-x) ** fr[F_DELTA])
        return fr[F_MU1] + (fr[F_MU0] - fr[F_MU1]) * np.exp(-e) + fr[F_MUV] * u
    xs = mdl.ftab_x
    c = mdl.ftab_c
    k = np.searchsorted(xs, u.real, side="right") - 1
    if k < 0:
        return c[0, 0] + c[0, 1] * u
    tau = u - xs[k]
    return c[k, 0] + tau * (c[k, 1] + tau * (c[k, 2] + tau * c[k, 3]))


@njit(cache=True)
def new_work(mdl, like):
    """Scratch arrays of ``evaluate`` in the dtype of ``like`` (float or complex)."""
    n, ns, _ = sizes(mdl)
    width = int(mdl.opts[O_LMAX]) + 2
    dt = like.dtype
    return (
        np.zeros((ns, n), dt),  # g_j
        np.zeros((ns, n), dt),  # g'_j
        np.zeros(n, dt),  # disc forces without the contacts
        np.zeros(width, dt),  # cos(l psi)
        np.zeros(width, dt),  # sin(l psi)
        np.zeros((N_AUX, ns), dt),  # per-slider quantities (layout.A_*)
        np.zeros((ns, ns), dt),  # the normal forces' system
        np.zeros(ns, dt),  # its right-hand side
        np.zeros(ns, np.int64),  # sliders in contact
    )


@njit(cache=True, inline="always")
def _disc_forces(t, y, om, omd, mdl, fq, dy):
    """Disc forces that do not depend on the contacts: stiffness, spin, damping."""
    n, _, half = sizes(mdl)
    eps = mdl.opts[O_OMDOT]
    damped = mdl.opts[O_DAMPED] != 0.0
    om2 = om * om
    for i in range(n):
        qi = y[i]
        p = mdl.partner[i]
        fi = -(mdl.kd[i] - mdl.ml2[i] * om2) * qi
        if p >= 0:
            fi -= mdl.gyr[i] * (2.0 * om * y[half + p] + eps * omd * y[p] * mdl.omd_fix[i])
        if damped:
            fi -= mdl.cdamp[i] * y[half + i]
            if p >= 0:
                fi -= mdl.cdamp_om[i] * om * y[p]
        fq[i] = fi
        dy[i] = y[half + i]


@njit(cache=True, inline="always")
def _slider_sums(j, y, ph, om, mdl, wk):
    """Mode shapes at slider j (rows j of g, g') and the sums over the modal coordinates
    that its contact needs (rows of ``aux``)."""
    g, gp, fq, cl, sl, aux, _, _, _ = wk
    n, _, half = sizes(mdl)
    phi = y[n + j]
    phid = y[half + n + j]
    if ph[j] == STICK:
        phid = phid * 0.0 + om
    zero = phi * 0.0
    psi = mdl.theta[j] + phi
    lmax = int(mdl.opts[O_LMAX])
    # cos(l psi), sin(l psi) by the Chebyshev recurrence: two trig calls per slider.
    c1 = np.cos(psi)
    s1 = np.sin(psi)
    cl[0] = 1.0 + zero
    sl[0] = zero
    if lmax >= 1:
        cl[1] = c1
        sl[1] = s1
    for k in range(1, lmax):
        cl[k + 1] = 2.0 * c1 * cl[k] - cl[k - 1]
        sl[k + 1] = 2.0 * c1 * sl[k] - sl[k - 1]
    wc = zero
    wcd = zero
    gpq = zero
    gpqd = zero
    l2gq = zero
    s_gf = zero
    s_gg = zero
    s_ggp = zero
    shape = mdl.shape[j]
    for i in range(n):
        li = mdl.l[i]
        # Branch-free g = R cos(l psi) (C, sgn = 1) or R sin(l psi) (D, sgn = -1).
        cs = 0.5 + 0.5 * mdl.sgn[i]
        sn = 0.5 - 0.5 * mdl.sgn[i]
        gi = shape[i] * (cs * cl[li] + sn * sl[li])
        gpi = li * shape[i] * (sn * cl[li] - cs * sl[li])
        g[j, i] = gi
        gp[j, i] = gpi
        qi = y[i]
        qdi = y[half + i]
        wc += gi * qi
        wcd += gi * qdi
        gpq += gpi * qi
        gpqd += gpi * qdi
        l2gq += li * li * gi * qi
        s_gf += gi * fq[i] * mdl.minv[i]
        s_gg += gi * gi * mdl.minv[i]
        s_ggp += gi * gpi * mdl.minv[i]
    wcd += phid * gpq
    aux[A_WC, j] = wc
    aux[A_WCD, j] = wcd
    aux[A_V, j] = om - phid
    aux[A_GPQ, j] = gpq
    aux[A_GPQD, j] = gpqd
    aux[A_L2GQ, j] = l2gq
    aux[A_SGF, j] = s_gf
    aux[A_SGG, j] = s_gg
    aux[A_SGGP, j] = s_ggp
    aux[A_PHID, j] = phid
    aux[A_N, j] = zero
    aux[A_F, j] = zero


@njit(cache=True, inline="always")
def solve_small(a, b, m):
    """Solve the leading ``m x m`` block of ``a x = b`` in place (``b`` becomes x) by
    Gaussian elimination with partial pivoting on the real parts. For m = 1 it is one
    division."""
    for c in range(m):
        piv = c
        best = abs(a[c, c].real)
        for r in range(c + 1, m):
            if abs(a[r, c].real) > best:
                best = abs(a[r, c].real)
                piv = r
        if piv != c:
            for k in range(m):
                tmp = a[c, k]
                a[c, k] = a[piv, k]
                a[piv, k] = tmp
            tmp = b[c]
            b[c] = b[piv]
            b[piv] = tmp
        for r in range(c + 1, m):
            fac = a[r, c] / a[c, c]
            for k in range(c, m):
                a[r, k] -= fac * a[c, k]
            b[r] -= fac * b[c]
    for c in range(m - 1, -1, -1):
        acc = b[c]
        for k in range(c + 1, m):
            acc -= a[c, k] * b[k]
        b[c] = acc / a[c, c]


@njit(cache=True)
def evaluate(t, y, ph, sg, right, mdl, wk, dy):
    """Time derivative ``dy`` of the state, slider j in phase ``ph[j]`` (slip sign
    ``sg[j]``).

    Fills ``wk``'s per-slider rows (``layout.A_*``): normal force [N], friction force
    on the slider [N] (positive along +phi), the disc's w under it [m] and its rate
    [m/s], the relative speed ``Omega - phidot`` [rad/s], ... and rows of g and g' at
    every slider. ``right`` picks the right limit of the speed at a knot.
    """
    g, gp, fq, _, _, aux, amat, bvec, cidx = wk
    n, ns, half = sizes(mdl)
    om, omd = speed_at(t, mdl.knots, mdl.coef, right)
    _disc_forces(t, y, om, omd, mdl, fq, dy)

    nc = 0
    for j in range(ns):
        _slider_sums(j, y, ph, om, mdl, wk)
        phid = aux[A_PHID, j]
        phi = y[n + j]
        dy[n + j] = phid
        if ph[j] == SEPARATION:
            zj = y[n + ns + j]
            zdj = y[half + n + ns + j]
            dy[half + n + j] = (-mdl.cphi[j] * phid - mdl.kphi[j] * phi) / mdl.inertia[j]
            dy[n + ns + j] = zdj
            dy[half + n + ns + j] = (-mdl.sn0[j] - mdl.cz[j] * zdj - mdl.kz[j] * zj) / mdl.mass[j]
            continue
        dy[n + ns + j] = phi * 0.0
        dy[half + n + ns + j] = phi * 0.0
        cidx[nc] = j
        nc += 1
        # The part of N that does not depend on the unknown accelerations.
        aux[A_KNOWN, j] = (
            mdl.n0[j]
            + mdl.smass[j] * (2.0 * phid * aux[A_GPQD, j] - phid * phid * aux[A_L2GQ, j])
            + mdl.scz[j] * aux[A_WCD, j]
            + mdl.skz[j] * aux[A_WC, j]
        )
        if ph[j] == SLIP:
            aux[A_SMU, j] = sg[j] * kinetic_friction(mdl, mdl.radius[j], sg[j], aux[A_V, j])
            aux[A_FPHI, j] = -mdl.cphi[j] * phid - mdl.kphi[j] * phi
        else:
            # Stick: phi'' = Omegadot, friction is the reaction of the in-plane oscillator.
            aux[A_F, j] = (mdl.inertia[j] * omd + mdl.cphi[j] * om + mdl.kphi[j] * phi) / (
                mdl.radius[j]
            )

    # One equation per slider in contact for its normal force: N_j = known_j +
    # sigma_j m_j (g_j.q'' + g'_j.q phi_j''), with q'' = M^-1 (F + sum_k sigma_k (-N_k g_k
    # + h_k f_k g'_k)) and, in slip, phi_j'' = (F_phi + r s mu N_j) / I.
    for a in range(nc):
        j = cidx[a]
        m = mdl.mass[j]
        sm = mdl.smass[j]
        gpq = aux[A_GPQ, j]
        cross = y[n] * 0.0
        for b in range(nc):
            k = cidx[b]
            if k == j:
                continue
            # g_j M^-1 g_k and g_j M^-1 g'_k.
            sgg = cross * 0.0
            sggp = cross * 0.0
            for i in range(n):
                sgg += g[j, i] * g[k, i] * mdl.minv[i]
                sggp += g[j, i] * gp[k, i] * mdl.minv[i]
            sig = mdl.sigma[j] * mdl.sigma[k]
            if ph[k] == SLIP:
                amat[a, b] = sig * m * (sgg - mdl.hh[k] * aux[A_SMU, k] * sggp)
            else:
                amat[a, b] = sig * m * sgg
                cross += mdl.shh[k] * aux[A_F, k] * sggp
        if ph[j] == SLIP:
            smu = aux[A_SMU, j]
            amat[a, a] = (
                1.0
                + m * (aux[A_SGG, j] - mdl.hh[j] * smu * aux[A_SGGP, j])
                - sm * gpq * mdl.radius[j] * smu / mdl.inertia[j]
            )
            bvec[a] = (
                aux[A_KNOWN, j]
                + sm * (aux[A_SGF, j] + cross)
                + sm * gpq * aux[A_FPHI, j] / mdl.inertia[j]
            )
        else:
            amat[a, a] = 1.0 + m * aux[A_SGG, j]
            bvec[a] = (
                aux[A_KNOWN, j]
                + sm * (aux[A_SGF, j] + mdl.shh[j] * aux[A_F, j] * aux[A_SGGP, j] + cross)
                + sm * gpq * omd
            )
    solve_small(amat, bvec, nc)

    for i in range(n):
        acc = fq[i]
        for a in range(nc):
            j = cidx[a]
            sn = mdl.sigma[j] * bvec[a]
            if ph[j] == SLIP:
                acc = acc - sn * (g[j, i] - mdl.hh[j] * aux[A_SMU, j] * gp[j, i])
            else:
                acc = acc + mdl.shh[j] * aux[A_F, j] * gp[j, i]
                acc = acc - sn * g[j, i]
        dy[half + i] = acc * mdl.minv[i]
    for a in range(nc):
        j = cidx[a]
        aux[A_N, j] = bvec[a]
        if ph[j] == SLIP:
            aux[A_F, j] = aux[A_SMU, j] * bvec[a]
            dy[half + n + j] = (aux[A_FPHI, j] + mdl.radius[j] * aux[A_F, j]) / mdl.inertia[j]
        else:
            dy[half + n + j] = omd + y[n + j] * 0.0

    if y.shape[0] > n_dynamic(mdl):
        _powers(y, ph, om, omd, mdl, wk, dy)


@njit(cache=True, inline="always")
def _powers(y, ph, om, omd, mdl, wk, dy):
    """Rates of the energy accumulators (``layout.E_*``) [W]."""
    gp = wk[1]
    aux = wk[5]
    n, ns, half = sizes(mdl)
    e0 = n_dynamic(mdl)
    zero = y[n] * 0.0
    fric = zero
    drive = zero
    moment = zero
    slope = zero
    sdamp = zero
    ddamp = zero
    for j in range(ns):
        phid = aux[A_PHID, j]
        f = aux[A_F, j]
        r = mdl.radius[j]
        fric += f * r * (phid - om)
        drive += f * r * om
        gpqd = zero
        for i in range(n):
            gpqd += gp[j, i] * y[half + i]
        moment += mdl.shh[j] * f * gpqd
        slope += mdl.sigma[j] * aux[A_N, j] * phid * aux[A_GPQ, j]
        if ph[j] == SEPARATION:
            zd = y[half + n + ns + j]
        else:
            zd = aux[A_WCD, j]
        sdamp -= mdl.cz[j] * zd * zd + mdl.cphi[j] * phid * phid
    eps = mdl.opts[O_OMDOT]
    for i in range(n):
        p = mdl.partner[i]
        qdi = y[half + i]
        drive -= mdl.ml2[i] * om * omd * y[i] * y[i]
        if p >= 0:
            drive -= qdi * mdl.gyr[i] * (2.0 * om * y[half + p] + eps * omd * y[p] * mdl.omd_fix[i])
            ddamp -= qdi * mdl.cdamp_om[i] * om * y[p]
        ddamp -= qdi * mdl.cdamp[i] * qdi
    dy[e0 + E_FRICTION] = fric
    dy[e0 + E_DRIVE] = drive
    dy[e0 + E_MOMENT] = moment
    dy[e0 + E_SLOPE] = slope
    dy[e0 + E_SLIDER_DAMPING] = sdamp
    dy[e0 + E_DISC_DAMPING] = ddamp
    for c in range(E_DISC_DAMPING + 1, y.shape[0] - e0):
        dy[e0 + c] = zero


@njit(cache=True, inline="always")
def event_values(ph, sg, y, mdl, wk, out):
    """Event functions of every slider's phase, positive while it holds (3 per slider;
    unused slots +inf). Needs ``wk`` filled by ``evaluate`` at ``y``."""
    aux = wk[5]
    n, ns, _ = sizes(mdl)
    mus = mdl.fric[F_MUS]
    for j in range(ns):
        o = 3 * j
        out[o] = np.inf
        out[o + 1] = np.inf
        out[o + 2] = np.inf
        nf = aux[A_N, j]
        if ph[j] == SLIP:
            out[o] = sg[j] * aux[A_V, j]
            out[o + 1] = nf
        elif ph[j] == STICK:
            f = aux[A_F, j]
            out[o] = mus * nf - f
            out[o + 1] = mus * nf + f
            out[o + 2] = nf
        else:
            out[o] = mdl.sigma[j] * (y[n + ns + j] - aux[A_WC, j])


@njit(cache=True)
def complex_step_jacobian(t, y, ph, sg, mdl):
    """Exact Jacobian d(dy/dt)/dy of the phases ``ph`` by the complex step.

    Each column costs one complex evaluation; the result has no subtractive
    cancellation, so it is exact to rounding (step 1e-30).
    """
    ns = y.shape[0]
    yc = np.empty(ns, dtype=np.complex128)
    dy = np.empty(ns, dtype=np.complex128)
    wk = new_work(mdl, yc)
    jac = np.empty((ns, ns))
    step = 1e-30
    for i in range(ns):
        for j in range(ns):
            yc[j] = y[j]
        yc[i] = y[i] + 1j * step
        evaluate(t, yc, ph, sg, True, mdl, wk, dy)
        for j in range(ns):
            jac[j, i] = dy[j].imag / step
    return jac
