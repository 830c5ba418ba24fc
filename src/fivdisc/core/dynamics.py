"""Equations of motion of S sliders on the spinning disc (numba, arrays in and out).

The state layout and the model tuple are described in :mod:`fivdisc.model.layout`.
Phases and slip signs are passed in, and the arithmetic that produces derivatives has
no comparisons on the state's values, so ``evaluate`` also compiles for complex arrays:
complex-step Jacobians come from the same code.

The accelerations solve a linear system at every evaluation: the disc's is diagonal
(modal masses) plus one row and column per slider in contact (its normal force). The
normal forces are eliminated first: a system of one equation per slider (its matrix is
the capacitance matrix of the Woodbury identity; a flying slider's row is the identity),
then the disc's accelerations follow in O(n S). For one slider this is the closed-form
rank-one elimination, operation for operation.

Functions here and in the integrator that never allocate are compiled with
``_nrt=False``: numba then emits no reference counting for their array arguments and
views, whose atomic updates were about a fifth of a step's cost.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from fivdisc.core.sizes import n_dynamic, sizes, work_rows
from fivdisc.model.layout import (
    A_DEN,
    A_F,
    A_FPHI,
    A_GPQ,
    A_GPQD,
    A_KNOWN,
    A_L2GQ,
    A_N,
    A_OM,
    A_OMD,
    A_PHID,
    A_SGGP,
    A_SMU,
    A_V,
    A_WC,
    A_WCD,
    D_CDAMP,
    D_CDAMP_OM,
    D_GYR,
    D_KD,
    D_L,
    D_MINV,
    D_ML2,
    D_OMD_FIX,
    D_PARTNER,
    D_SGN,
    E_DISC_DAMPING,
    E_DRIVE,
    E_FRICTION,
    E_MOMENT,
    E_SLIDER_DAMPING,
    E_SLOPE,
    LAW_EXPONENTIAL,
    LAW_STRIBECK,
    O_ALPHA,
    O_DAMPED,
    O_DELTA,
    O_LAW,
    O_LMAX,
    O_MU0,
    O_MU1,
    O_MUS,
    O_MUV,
    O_OMDOT,
    O_VS,
    S_CPHI,
    S_CZ,
    S_HH,
    S_INERTIA,
    S_KPHI,
    S_KZ,
    S_MASS,
    S_N0,
    S_RADIUS,
    S_SCZ,
    S_SHH,
    S_SIGMA,
    S_SKZ,
    S_SMASS,
    S_SN0,
    S_THETA,
    SEPARATION,
    SLIP,
    STICK,
)

# The side of a speed-profile knot that ``speed_at`` takes (its ``right``); numpy
# scalars, not literals (see the package docstring).
RIGHT = np.bool_(True)
LEFT = np.bool_(False)


@njit(cache=True, _nrt=False)
def speed_at(t, speed, right):
    """Disc speed and acceleration at ``t`` from the piecewise-cubic profile.

    At a knot, ``right`` selects the right limit (start of a step) or the left
    limit (inside or at the end of a step), so a kink is seen from the side the
    step lies on. A complex ``t`` gives the time derivatives in the imaginary part.
    """
    k = _piece(speed, t.real, right)
    tau = t - speed[k, 0]
    c0 = speed[k, 1]
    c1 = speed[k, 2]
    c2 = speed[k, 3]
    c3 = speed[k, 4]
    om = c0 + tau * (c1 + tau * (c2 + tau * c3))
    omd = c1 + tau * (2.0 * c2 + 3.0 * tau * c3)
    return om, omd


@njit(cache=True, _nrt=False)
def _piece(pieces, x, right):
    """Index of the piece of ``pieces`` (starts in column 0, increasing) holding ``x``:
    the last start below ``x``, or at or below it when ``right``; 0 before the first.

    A bisection on the column itself.
    """
    lo = 0
    hi = pieces.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        start = pieces[mid, 0]
        if start < x or (right and start == x):
            lo = mid + 1
        else:
            hi = mid
    return max(lo - 1, 0)


@njit(cache=True, inline="always")
def kinetic_friction(opts, table, r, s, v):
    """Kinetic friction coefficient at relative speed ``v`` [rad/s] in slip with sign ``s``.

    The sliding speed is ``u = r s v`` [m/s]; inside a Runge-Kutta step that crosses
    v = 0 it may be slightly negative, where each law is continued smoothly: the
    exponential law analytically, the Stribeck exponent oddly, the table linearly.
    """
    law = opts[O_LAW]
    if law == LAW_EXPONENTIAL:
        return opts[O_MU1] + (opts[O_MU0] - opts[O_MU1]) * np.exp(-opts[O_ALPHA] * r * s * v)
    u = r * s * v
    if law == LAW_STRIBECK:
        x = u / opts[O_VS]
        if x.real >= 0.0:
            e = x ** opts[O_DELTA]
        else:
            e = -((-x) ** opts[O_DELTA])
        return opts[O_MU1] + (opts[O_MU0] - opts[O_MU1]) * np.exp(-e) + opts[O_MUV] * u
    if u.real < table[0, 0]:
        return table[0, 1] + table[0, 2] * u
    k = _piece(table, u.real, RIGHT)
    tau = u - table[k, 0]
    return table[k, 1] + tau * (table[k, 2] + tau * (table[k, 3] + tau * table[k, 4]))


@njit(cache=True, _nrt=False)
def _law_rate(opts, table, r, s, v, dphid):
    """The rate of ``s mu`` at relative speed ``v`` [rad/s] as phidot changes at
    ``dphid`` (v changes at -dphid): the complex step of the friction law. A function of
    its own so that the laws' code stays out of the tangent stages' hot path."""
    h = 1e-30
    return s * kinetic_friction(opts, table, r, s, complex(v, -h * dphid)).imag / h


@njit(cache=True)
def new_work(mdl, like):
    """Work array of ``evaluate`` in the dtype of ``like`` (float or complex)."""
    n, ns, _ = sizes(mdl)
    rows = work_rows(ns)[5] + n
    width = max(n, int(mdl.opts[O_LMAX]) + 2, ns + 1, 1)
    return np.zeros((rows, width), like.dtype)


@njit(cache=True, _nrt=False)
def solve_small(a, r0, m):
    """Solve the ``m x m`` system in rows ``r0 .. r0 + m`` of ``a`` (matrix in columns
    ``0 .. m``, right-hand side in column m) in place, the solution left in column m, by
    Gaussian elimination with partial pivoting on the real parts (what it leaves below
    the diagonal is scratch). For m = 1 it is one division."""
    for c in range(m):
        piv = c
        best = abs(a[r0 + c, c].real)
        for r in range(c + 1, m):
            if abs(a[r0 + r, c].real) > best:
                best = abs(a[r0 + r, c].real)
                piv = r
        if piv != c:
            for k in range(m + 1):
                tmp = a[r0 + c, k]
                a[r0 + c, k] = a[r0 + piv, k]
                a[r0 + piv, k] = tmp
        if c + 1 < m:
            inv = 1.0 / a[r0 + c, c]
            for r in range(c + 1, m):
                fac = a[r0 + r, c] * inv
                # Column c of the rows below is not read again.
                for k in range(c + 1, m + 1):
                    a[r0 + r, k] -= fac * a[r0 + c, k]
    for c in range(m - 1, -1, -1):
        acc = a[r0 + c, m]
        for k in range(c + 1, m):
            acc -= a[r0 + c, k] * a[r0 + k, m]
        a[r0 + c, m] = acc / a[r0 + c, c]


# The small system's solve inlined where it runs every evaluation (several sliders'
# normal forces, ``_contacts``): a call passes the work array field by field.
_solve_inline = njit(cache=True, inline="always")(solve_small.py_func)


@njit(cache=True, inline="always")
def _disc_force(i, x, om, om2, omd, eps, damped, disc, half):
    """Force on modal coordinate ``i`` from its stiffness, the spin and the damping at
    state ``x`` (``om2 = om^2``): linear in ``x``, so for a tangent vector ``x`` it is
    the force's derivative along it."""
    p = int(disc[D_PARTNER, i])
    f = -(disc[D_KD, i] - disc[D_ML2, i] * om2) * x[i]
    if p >= 0:
        f -= disc[D_GYR, i] * (2.0 * om * x[half + p] + eps * omd * x[p] * disc[D_OMD_FIX, i])
    if damped:
        f -= disc[D_CDAMP, i] * x[half + i]
        if p >= 0:
            f -= disc[D_CDAMP_OM, i] * om * x[p]
    return f


@njit(cache=True, _nrt=False)
def evaluate(t, y, ph, sg, right, mdl, wk, dy):
    """Time derivative ``dy`` of the state, slider j in phase ``ph[j]`` (slip sign
    ``sg[j]``).

    Fills ``wk`` (``layout.work_rows``): g and g' at every slider and, per slider, its
    normal force [N], friction force on the slider [N] (positive along +phi), the
    disc's w under it [m] and its rate [m/s], the relative speed ``Omega - phidot``
    [rad/s], ... ``right`` picks the right limit of the speed at a knot.
    """
    disc = mdl.disc
    sl = mdl.slider
    shape = mdl.shape
    opts = mdl.opts
    n, ns, half = sizes(mdl)
    r_gp, r_fq, r_trig, r_aux, r_sys, r_u = work_rows(ns)
    om, omd = speed_at(t, mdl.speed, right)
    # Kept for the tangent-linear right-hand side, which would otherwise look the speed
    # up again at every stage of every tangent vector.
    wk[r_aux + A_OM, 0] = om
    wk[r_aux + A_OMD, 0] = omd
    zero = y[n] * 0.0

    # Disc forces that do not depend on the contacts: stiffness, spin, damping.
    eps = opts[O_OMDOT]
    damped = opts[O_DAMPED] != 0.0
    om2 = om * om
    for i in range(n):
        wk[r_fq, i] = _disc_force(i, y, om, om2, omd, eps, damped, disc, half)
        dy[i] = y[half + i]

    lmax = int(opts[O_LMAX])
    aux = r_aux
    # The last slider's values stay in these locals: with one slider they give its
    # normal force in closed form below. Phases, signs and slider constants are read
    # into locals once: to the compiler every store to wk or dy may change them.
    known = zero
    smu = zero
    fphi = zero
    f = zero
    phj = SLIP
    for j in range(ns):
        phj = ph[j]
        sj = sg[j]
        phi = y[n + j]
        phid = y[half + n + j]
        if phj == STICK:
            phid = phid * 0.0 + om
        # cos(l psi), sin(l psi) by the Chebyshev recurrence: two trig calls per slider.
        psi = sl[S_THETA, j] + phi
        c1 = np.cos(psi)
        s1 = np.sin(psi)
        rc = r_trig + j
        rs = r_trig + ns + j
        wk[rc, 0] = 1.0 + zero
        wk[rs, 0] = zero
        if lmax >= 1:
            wk[rc, 1] = c1
            wk[rs, 1] = s1
        for k in range(1, lmax):
            wk[rc, k + 1] = 2.0 * c1 * wk[rc, k] - wk[rc, k - 1]
            wk[rs, k + 1] = 2.0 * c1 * wk[rs, k] - wk[rs, k - 1]
        wc = zero
        wcd = zero
        gpq = zero
        gpqd = zero
        l2gq = zero
        s_gf = zero
        s_gg = zero
        s_ggp = zero
        for i in range(n):
            li = int(disc[D_L, i])
            sgn = disc[D_SGN, i]
            minv = disc[D_MINV, i]
            # Branch-free g = R cos(l psi) (C, sgn = 1) or R sin(l psi) (D, sgn = -1).
            cs = 0.5 + 0.5 * sgn
            sn = 0.5 - 0.5 * sgn
            gi = shape[j, i] * (cs * wk[rc, li] + sn * wk[rs, li])
            gpi = li * shape[j, i] * (sn * wk[rc, li] - cs * wk[rs, li])
            wk[j, i] = gi
            wk[r_gp + j, i] = gpi
            qi = y[i]
            qdi = y[half + i]
            wc += gi * qi
            wcd += gi * qdi
            gpq += gpi * qi
            gpqd += gpi * qdi
            l2gq += li * li * gi * qi
            if ns == 1:
                s_gf += gi * wk[r_fq, i] * minv
                s_gg += gi * gi * minv
                s_ggp += gi * gpi * minv
        wcd += phid * gpq
        wk[aux + A_WC, j] = wc
        wk[aux + A_WCD, j] = wcd
        wk[aux + A_V, j] = om - phid
        wk[aux + A_GPQ, j] = gpq
        wk[aux + A_GPQD, j] = gpqd
        wk[aux + A_L2GQ, j] = l2gq
        wk[aux + A_PHID, j] = phid
        wk[aux + A_N, j] = zero
        wk[aux + A_F, j] = zero
        dy[n + j] = phid
        if phj == SEPARATION:
            zj = y[n + ns + j]
            zdj = y[half + n + ns + j]
            dy[half + n + j] = (-sl[S_CPHI, j] * phid - sl[S_KPHI, j] * phi) / sl[S_INERTIA, j]
            dy[n + ns + j] = zdj
            dy[half + n + ns + j] = (-sl[S_SN0, j] - sl[S_CZ, j] * zdj
                                     - sl[S_KZ, j] * zj) / sl[S_MASS, j]
            continue
        dy[n + ns + j] = zero
        dy[half + n + ns + j] = zero
        # The part of N that does not depend on the unknown accelerations.
        known = (
            sl[S_N0, j]
            + sl[S_SMASS, j] * (2.0 * phid * gpqd - phid * phid * l2gq)
            + sl[S_SCZ, j] * wcd
            + sl[S_SKZ, j] * wc
        )
        if phj == SLIP:
            smu = sj * kinetic_friction(opts, mdl.table, sl[S_RADIUS, j], sj, om - phid)
            fphi = -sl[S_CPHI, j] * phid - sl[S_KPHI, j] * phi
            wk[aux + A_SMU, j] = smu
        else:
            # Stick: phi'' = Omegadot, friction is the reaction of the in-plane oscillator.
            f = (sl[S_INERTIA, j] * omd + sl[S_CPHI, j] * om + sl[S_KPHI, j] * phi) / (
                sl[S_RADIUS, j])
            wk[aux + A_F, j] = f
        # For the tangent-linear right-hand side, which needs it with one slider.
        wk[aux + A_SGGP, j] = s_ggp
        if ns > 1:
            wk[aux + A_KNOWN, j] = known
            wk[aux + A_FPHI, j] = fphi

    if ns == 1:
        _one_slider(n, half, phj, known, smu, fphi, f, gpq, s_gf, s_gg, s_ggp, y[n], omd,
                    zero, sl, disc, r_gp, r_fq, aux, wk, dy)
    else:
        _contacts(n, ns, half, y, ph, omd, zero, sl, disc, r_gp, r_fq, aux, r_sys, r_u, wk,
                  dy)

    if y.shape[0] > n_dynamic(mdl):
        _powers(y, ph, om, omd, mdl, wk, dy)


@njit(cache=True, inline="always")
def _one_slider(n, half, phj, known, smu, fphi, f, gpq, s_gf, s_gg, s_ggp, phi, omd,
                zero, sl, disc, r_gp, r_fq, aux, wk, dy):
    """Normal force and accelerations with a single slider: the one equation of
    :func:`_contacts` in closed form (the same operations in the same order, so the same
    numbers), with the slider's values passed in registers."""
    if phj == SEPARATION:
        for i in range(n):
            dy[half + i] = wk[r_fq, i] * disc[D_MINV, i]
        return
    m = sl[S_MASS, 0]
    sm = sl[S_SMASS, 0]
    inertia = sl[S_INERTIA, 0]
    if phj == SLIP:
        den = (1.0 + m * (s_gg - sl[S_HH, 0] * smu * s_ggp)
               - sm * gpq * sl[S_RADIUS, 0] * smu / inertia)
        nf = (known + sm * (s_gf + zero) + sm * gpq * fphi / inertia) / den
        sn = sl[S_SIGMA, 0] * nf
        c = sl[S_HH, 0] * smu
        for i in range(n):
            dy[half + i] = (wk[r_fq, i] - sn * (wk[0, i] - c * wk[r_gp, i])) * disc[D_MINV, i]
        f = smu * nf
        dy[half + n] = (fphi + sl[S_RADIUS, 0] * f) / inertia
    else:
        den = 1.0 + m * s_gg
        nf = (known + sm * (s_gf + sl[S_SHH, 0] * f * s_ggp + zero) + sm * gpq * omd) / den
        sn = sl[S_SIGMA, 0] * nf
        c = sl[S_SHH, 0] * f
        for i in range(n):
            dy[half + i] = (wk[r_fq, i] + c * wk[r_gp, i] - sn * wk[0, i]) * disc[D_MINV, i]
        dy[half + n] = omd + phi * 0.0
    wk[aux + A_N, 0] = nf
    wk[aux + A_F, 0] = f
    # For the tangent-linear right-hand side, which divides by it too.
    wk[aux + A_DEN, 0] = den


@njit(cache=True, _nrt=False)
def _contacts(n, ns, half, y, ph, omd, zero, sl, disc, r_gp, r_fq, aux, r_sys, r_u, wk, dy):
    """Normal forces and accelerations of several sliders.

    Notes
    -----
    Slider k in contact pushes the disc with -sigma_k N_k u_k, where u_k = g_k -
    h_k / (2 r_k) s_k mu_k g'_k in slip and g_k in stick, plus in stick the known
    moment of its friction reaction, sigma_k h_k / (2 r_k) f_k g'_k. With F the disc
    forces known before the contacts (stick moments included),
    q'' = M^-1 (F - sum_k sigma_k N_k u_k). Each contact's condition
    N_j = known_j + sigma_j m_j (g_j . q'' + g'_j . q phi_j''), with
    phi_j'' = (F_phi + r s mu N_j) / I in slip and dOmega/dt in stick, is one row of an
    S x S system (the capacitance matrix of the Woodbury identity) whose entries are
    sigma_j sigma_k m_j g_j M^-1 u_k. A flying slider's row is N_j = 0. F is gathered in
    the accelerations of ``dy``; row ``r_u + i`` holds sigma_k (M^-1 u_k)_i in column k
    (0 for a flying slider), so that the system's rows and the accelerations are sums of
    contiguous rows (which the compiler vectorises) rather than S^2 short dot products.
    """
    for i in range(n):
        dy[half + i] = wk[r_fq, i]
    for k in range(ns):
        if ph[k] == STICK:
            moment = sl[S_SHH, k] * wk[aux + A_F, k]
            for i in range(n):
                dy[half + i] += moment * wk[r_gp + k, i]
    if ns == 2 and ph[0] != SEPARATION and ph[1] != SEPARATION:
        # Two sliders in contact: the general path's operations below in the same order
        # (so the same numbers), but every sum taken in one pass over the modal
        # coordinates, the 2 x 2 system solved in registers and u_k recomputed: at two
        # sliders the general path's passes, its solve's loops and its values' trips
        # through wk cost more than their arithmetic (the step was 1.45 x its floor).
        c0 = sl[S_HH, 0] * wk[aux + A_SMU, 0] if ph[0] == SLIP else zero
        c1 = sl[S_HH, 1] * wk[aux + A_SMU, 1] if ph[1] == SLIP else zero
        sig0 = sl[S_SIGMA, 0]
        sig1 = sl[S_SIGMA, 1]
        gf0 = zero
        gf1 = zero
        a00 = zero
        a01 = zero
        a10 = zero
        a11 = zero
        for i in range(n):
            minv = disc[D_MINV, i]
            g0 = wk[0, i]
            g1 = wk[1, i]
            u0 = sig0 * (g0 - c0 * wk[r_gp, i]) * minv
            u1 = sig1 * (g1 - c1 * wk[r_gp + 1, i]) * minv
            f = dy[half + i]
            gf0 += g0 * minv * f
            gf1 += g1 * minv * f
            a00 += g0 * u0
            a01 += g0 * u1
            a10 += g1 * u0
            a11 += g1 * u1
        # Rows [d_j, e_j | b_j] of the system, as the general path forms them.
        sm0 = sl[S_SMASS, 0]
        sm1 = sl[S_SMASS, 1]
        d0 = a00 * sm0 + 1.0
        d1 = a11 * sm1 + 1.0
        e0 = a01 * sm0
        e1 = a10 * sm1
        gpq0 = wk[aux + A_GPQ, 0]
        gpq1 = wk[aux + A_GPQ, 1]
        if ph[0] == SLIP:
            d0 -= sm0 * gpq0 * sl[S_RADIUS, 0] * wk[aux + A_SMU, 0] / sl[S_INERTIA, 0]
            b0 = (wk[aux + A_KNOWN, 0] + sm0 * gf0
                  + sm0 * gpq0 * wk[aux + A_FPHI, 0] / sl[S_INERTIA, 0])
        else:
            b0 = wk[aux + A_KNOWN, 0] + sm0 * gf0 + sm0 * gpq0 * omd
        if ph[1] == SLIP:
            d1 -= sm1 * gpq1 * sl[S_RADIUS, 1] * wk[aux + A_SMU, 1] / sl[S_INERTIA, 1]
            b1 = (wk[aux + A_KNOWN, 1] + sm1 * gf1
                  + sm1 * gpq1 * wk[aux + A_FPHI, 1] / sl[S_INERTIA, 1])
        else:
            b1 = wk[aux + A_KNOWN, 1] + sm1 * gf1 + sm1 * gpq1 * omd
        # solve_small's elimination for m = 2 written out: partial pivoting on the real
        # parts, the same operations, so as sound as the general solve and the same numbers.
        if abs(e1.real) > abs(d0.real):
            p00, p01, q0, p10, p11, q1 = e1, d1, b1, d0, e0, b0
        else:
            p00, p01, q0, p10, p11, q1 = d0, e0, b0, e1, d1, b1
        fac = p10 * (1.0 / p00)
        p11 -= fac * p01
        q1 -= fac * q0
        n1 = q1 / p11
        n0 = (q0 - p01 * n1) / p00
        wk[aux + A_N, 0] = n0
        wk[aux + A_N, 1] = n1
        for i in range(n):
            minv = disc[D_MINV, i]
            acc = dy[half + i] * minv
            acc -= n0 * (sig0 * (wk[0, i] - c0 * wk[r_gp, i]) * minv)
            acc -= n1 * (sig1 * (wk[1, i] - c1 * wk[r_gp + 1, i]) * minv)
            dy[half + i] = acc
    else:
        for k in range(ns):
            if ph[k] == SEPARATION:
                for i in range(n):
                    wk[r_u + i, k] = zero
                continue
            c = zero
            if ph[k] == SLIP:
                c = sl[S_HH, k] * wk[aux + A_SMU, k]
            sigma = sl[S_SIGMA, k]
            for i in range(n):
                wk[r_u + i, k] = sigma * (wk[k, i] - c * wk[r_gp + k, i]) * disc[D_MINV, i]

        for j in range(ns):
            row = r_sys + j
            if ph[j] == SEPARATION:
                for k in range(ns):
                    wk[row, k] = zero
                wk[row, j] = 1.0 + zero
                wk[row, ns] = zero
                continue
            gf = zero
            for i in range(n):
                gf += wk[j, i] * disc[D_MINV, i] * dy[half + i]
            sm = sl[S_SMASS, j]
            # The entries summed in locals, four at a time: accumulated in wk, every term
            # would be a load and a store of the same element (the compiler cannot tell wk's
            # rows apart), and one at a time, a chain of n dependent additions each. Four
            # chains side by side cost 0.8 x two at eight sliders (each entry's sum is the
            # same, in the same order); the rest one at a time.
            k = 0
            while k + 3 < ns:
                a0 = zero
                a1 = zero
                a2 = zero
                a3 = zero
                for i in range(n):
                    gji = wk[j, i]
                    a0 += gji * wk[r_u + i, k]
                    a1 += gji * wk[r_u + i, k + 1]
                    a2 += gji * wk[r_u + i, k + 2]
                    a3 += gji * wk[r_u + i, k + 3]
                wk[row, k] = a0 * sm
                wk[row, k + 1] = a1 * sm
                wk[row, k + 2] = a2 * sm
                wk[row, k + 3] = a3 * sm
                k += 4
            while k < ns:
                a0 = zero
                for i in range(n):
                    a0 += wk[j, i] * wk[r_u + i, k]
                wk[row, k] = a0 * sm
                k += 1
            gpq = wk[aux + A_GPQ, j]
            wk[row, j] += 1.0
            if ph[j] == SLIP:
                smu = wk[aux + A_SMU, j]
                wk[row, j] -= sm * gpq * sl[S_RADIUS, j] * smu / sl[S_INERTIA, j]
                wk[row, ns] = (wk[aux + A_KNOWN, j] + sm * gf
                               + sm * gpq * wk[aux + A_FPHI, j] / sl[S_INERTIA, j])
            else:
                wk[row, ns] = wk[aux + A_KNOWN, j] + sm * gf + sm * gpq * omd
        _solve_inline(wk, r_sys, ns)
        for k in range(ns):
            if ph[k] != SEPARATION:
                wk[aux + A_N, k] = wk[r_sys + k, ns]
        # A flying slider's normal force is 0 (set by ``evaluate``), and so is its column.
        for i in range(n):
            acc = dy[half + i] * disc[D_MINV, i]
            for k in range(ns):
                acc -= wk[aux + A_N, k] * wk[r_u + i, k]
            dy[half + i] = acc
    # The sliders' own accelerations, from their normal forces (either path).
    for k in range(ns):
        if ph[k] == SEPARATION:
            continue
        nf = wk[aux + A_N, k]
        if ph[k] == SLIP:
            wk[aux + A_F, k] = wk[aux + A_SMU, k] * nf
            dy[half + n + k] = (wk[aux + A_FPHI, k] + sl[S_RADIUS, k] * wk[aux + A_F, k]) / (
                sl[S_INERTIA, k])
        else:
            dy[half + n + k] = omd + y[n + k] * 0.0


@njit(cache=True, _nrt=False)
def _powers(y, ph, om, omd, mdl, wk, dy):
    """Rates of the energy accumulators (``layout.E_*``) [W]."""
    disc = mdl.disc
    sl = mdl.slider
    n, ns, half = sizes(mdl)
    r_gp, _, _, aux, _, _ = work_rows(ns)
    e0 = n_dynamic(mdl)
    zero = y[n] * 0.0
    fric = zero
    drive = zero
    moment = zero
    slope = zero
    sdamp = zero
    ddamp = zero
    for j in range(ns):
        phid = wk[aux + A_PHID, j]
        f = wk[aux + A_F, j]
        r = sl[S_RADIUS, j]
        fric += f * r * (phid - om)
        drive += f * r * om
        gpqd = zero
        for i in range(n):
            gpqd += wk[r_gp + j, i] * y[half + i]
        moment += sl[S_SHH, j] * f * gpqd
        slope += sl[S_SIGMA, j] * wk[aux + A_N, j] * phid * wk[aux + A_GPQ, j]
        if ph[j] == SEPARATION:
            zd = y[half + n + ns + j]
        else:
            zd = wk[aux + A_WCD, j]
        sdamp -= sl[S_CZ, j] * zd * zd + sl[S_CPHI, j] * phid * phid
    eps = mdl.opts[O_OMDOT]
    for i in range(n):
        p = int(disc[D_PARTNER, i])
        qdi = y[half + i]
        drive -= disc[D_ML2, i] * om * omd * y[i] * y[i]
        if p >= 0:
            drive -= qdi * disc[D_GYR, i] * (2.0 * om * y[half + p]
                                             + eps * omd * y[p] * disc[D_OMD_FIX, i])
            ddamp -= qdi * disc[D_CDAMP_OM, i] * om * y[p]
        ddamp -= qdi * disc[D_CDAMP, i] * qdi
    dy[e0 + E_FRICTION] = fric
    dy[e0 + E_DRIVE] = drive
    dy[e0 + E_MOMENT] = moment
    dy[e0 + E_SLOPE] = slope
    dy[e0 + E_SLIDER_DAMPING] = sdamp
    dy[e0 + E_DISC_DAMPING] = ddamp
    for c in range(E_DISC_DAMPING + 1, y.shape[0] - e0):
        dy[e0 + c] = zero


@njit(cache=True, _nrt=False)
def event_values(ph, sg, y, mdl, wk, out):
    """Event functions of every slider's phase, positive while it holds (3 per slider;
    unused slots +inf). Needs ``wk`` filled by ``evaluate`` at ``y``."""
    n, ns, _ = sizes(mdl)
    aux = work_rows(ns)[3]
    mus = mdl.opts[O_MUS]
    for j in range(ns):
        o = 3 * j
        out[o] = np.inf
        out[o + 1] = np.inf
        out[o + 2] = np.inf
        nf = wk[aux + A_N, j]
        if ph[j] == SLIP:
            out[o] = sg[j] * wk[aux + A_V, j]
            out[o + 1] = nf
        elif ph[j] == STICK:
            f = wk[aux + A_F, j]
            out[o] = mus * nf - f
            out[o + 1] = mus * nf + f
            out[o + 2] = nf
        else:
            out[o] = mdl.slider[S_SIGMA, j] * (y[n + ns + j] - wk[aux + A_WC, j])


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
        evaluate(t, yc, ph, sg, RIGHT, mdl, wk, dy)
        for j in range(ns):
            jac[j, i] = dy[j].imag / step
    return jac


@njit(cache=True, inline="always")
def linearised_one(y, v, ph, sg, mdl, wk, out):
    """``out = J(t, y) v`` for a single slider: the tangent-linear form of ``evaluate``
    (forward-mode derivative, operation by operation), using the values ``evaluate``
    left in ``wk`` at the same ``(t, y)``, phases and ``right`` (the speed among them).

    Every intermediate x of ``evaluate`` has its derivative dx along v. The mode shapes
    move with the slider's angle: dg = g' dpsi and dg' = -l^2 g dpsi. The friction law's
    slope is -alpha (mu - mu_1) for the exponential law, else the complex step of the law
    alone. The dynamic state only (no energy
    accumulators); several sliders use the complex step of ``evaluate`` instead.
    """
    disc = mdl.disc
    sl = mdl.slider
    opts = mdl.opts
    n, ns, half = sizes(mdl)
    r_gp, r_fq, _, aux, _, _ = work_rows(ns)
    om = wk[aux + A_OM, 0]
    omd = wk[aux + A_OMD, 0]
    eps = opts[O_OMDOT]
    damped = opts[O_DAMPED] != 0.0
    om2 = om * om
    phj = ph[0]
    sj = sg[0]
    phi = y[n]
    dpsi = v[n]
    phid = wk[aux + A_PHID, 0]
    dphid = 0.0 if phj == STICK else v[half + n]
    out[n] = dphid
    # Disc forces are linear in the state: their derivatives are the forces at v.
    if phj == SEPARATION:
        for i in range(n):
            out[half + i] = _disc_force(i, v, om, om2, omd, eps, damped, disc, half) * (
                disc[D_MINV, i])
            out[i] = v[half + i]
        out[half + n] = (-sl[S_CPHI, 0] * dphid - sl[S_KPHI, 0] * dpsi) / sl[S_INERTIA, 0]
        out[n + 1] = v[half + n + 1]
        out[half + n + 1] = (-sl[S_CZ, 0] * v[half + n + 1]
                             - sl[S_KZ, 0] * v[n + 1]) / sl[S_MASS, 0]
        return
    out[n + 1] = 0.0
    out[half + n + 1] = 0.0
    gpq = wk[aux + A_GPQ, 0]
    gpqd = wk[aux + A_GPQD, 0]
    l2gq = wk[aux + A_L2GQ, 0]
    dwc = 0.0
    dwcd0 = 0.0
    dgpq = 0.0
    dgpqd = 0.0
    dl2gq = 0.0
    s_ggp = wk[aux + A_SGGP, 0]
    ds_gf = 0.0
    ds_ggp = 0.0
    for i in range(n):
        # The force's derivative, turned into the acceleration's below.
        dfi = _disc_force(i, v, om, om2, omd, eps, damped, disc, half)
        out[half + i] = dfi
        out[i] = v[half + i]
        li = disc[D_L, i]
        minv = disc[D_MINV, i]
        gi = wk[0, i]
        gpi = wk[r_gp, i]
        fi = wk[r_fq, i]
        l2 = li * li
        dwc += gi * v[i]
        dwcd0 += gi * v[half + i] + gpi * y[half + i] * dpsi
        dgpq += gpi * v[i]
        dgpqd += gpi * v[half + i] - l2 * gi * y[half + i] * dpsi
        dl2gq += l2 * (gi * v[i] + gpi * y[i] * dpsi)
        ds_gf += (gpi * dpsi * fi + gi * dfi) * minv
        ds_ggp += (gpi * gpi - l2 * gi * gi) * minv
    dwc += gpq * dpsi
    dgpq -= l2gq * dpsi
    ds_gg = 2.0 * s_ggp * dpsi
    ds_ggp *= dpsi
    dwcd = dwcd0 + dphid * gpq + phid * dgpq
    sm = sl[S_SMASS, 0]
    m = sl[S_MASS, 0]
    inertia = sl[S_INERTIA, 0]
    r = sl[S_RADIUS, 0]
    dknown = (sm * (2.0 * (dphid * gpqd + phid * dgpqd) - 2.0 * phid * dphid * l2gq
                    - phid * phid * dl2gq)
              + sl[S_SCZ, 0] * dwcd + sl[S_SKZ, 0] * dwc)
    nf = wk[aux + A_N, 0]
    if phj == SLIP:
        smu = wk[aux + A_SMU, 0]
        vrel = om - phid
        if opts[O_LAW] == LAW_EXPONENTIAL:
            # mu' = -alpha (mu - mu_1), from mu = s smu itself.
            dsmu = opts[O_ALPHA] * (sj * smu - opts[O_MU1]) * r * dphid
        else:
            dsmu = _law_rate(opts, mdl.table, r, sj, vrel, dphid)
        fphi = -sl[S_CPHI, 0] * phid - sl[S_KPHI, 0] * phi
        dfphi = -sl[S_CPHI, 0] * dphid - sl[S_KPHI, 0] * dpsi
        hh = sl[S_HH, 0]
        den = wk[aux + A_DEN, 0]
        dnum = dknown + sm * ds_gf + sm * (dgpq * fphi + gpq * dfphi) / inertia
        dden = (m * (ds_gg - hh * (dsmu * s_ggp + smu * ds_ggp))
                - sm * r * (dgpq * smu + gpq * dsmu) / inertia)
        dnf = (dnum - nf * dden) / den
        # The disc's contact force is -sn g + a g' with a = sn h/(2r) s mu in slip.
        sn = sl[S_SIGMA, 0] * nf
        dsn = sl[S_SIGMA, 0] * dnf
        a = sn * hh * smu
        da = hh * (dsn * smu + sn * dsmu)
        out[half + n] = (dfphi + r * (dsmu * nf + smu * dnf)) / inertia
    else:
        # Stick: a = sigma h/(2r) f with the stick reaction f.
        f = wk[aux + A_F, 0]
        df = sl[S_KPHI, 0] * dpsi / r
        shh = sl[S_SHH, 0]
        dnf = (dknown + sm * (ds_gf + shh * (df * s_ggp + f * ds_ggp)) + sm * dgpq * omd
               - nf * m * ds_gg) / wk[aux + A_DEN, 0]
        sn = sl[S_SIGMA, 0] * nf
        dsn = sl[S_SIGMA, 0] * dnf
        a = shh * f
        da = shh * df
        out[half + n] = 0.0
    for i in range(n):
        gi = wk[0, i]
        gpi = wk[r_gp, i]
        dgi = gpi * dpsi
        dgpi = -disc[D_L, i] * disc[D_L, i] * gi * dpsi
        out[half + i] = (out[half + i] + da * gpi + a * dgpi - dsn * gi - sn * dgi) * (
            disc[D_MINV, i])
