"""The non-smooth time integration: adaptive DOPRI5 steps inside a phase machine.

One call of :func:`run` advances the integrator from its saved state until a target
time is passed, the run ends, it fails, the event buffer is nearly full, or it has tried
its budget of steps (so that the caller can report progress, count steps against a
budget and stop on an interrupt however slowly the integration goes); the
caller (``fivdisc.simulate``) loops over calls, which gives progress reporting
without changing the step sequence (the integrator state is carried over exactly).

Switches (slip/stick/separation) are located by bracketing root finding on the
dense output; the point on the far side of the root (where the event function is
already <= 0) is taken, so that the next phase starts in a state that is
consistent with it. The next phase is always chosen from the state at the switch.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from fivdisc.core import tangent
from fivdisc.core.dopri5 import A, C, E, dense_coefficients, dense_eval, dense_one
from fivdisc.core.dynamics import LEFT, evaluate, event_values, new_work, speed_at
from fivdisc.core.sizes import n_dynamic, sizes, work_rows
from fivdisc.core.slots import (
    C_ATOL,
    C_CALL_STEPS,
    C_MAX_STEP,
    C_MAX_SWITCHES,
    C_OUT_DT,
    C_RTOL,
    C_STOP_MASK,
    C_T_FINAL,
    C_ZENO_COUNT,
    C_ZENO_DT,
    EVI_KIND,
    F_ERR_OLD,
    F_H,
    F_H_CAP,
    F_LAST_SWITCH,
    F_T,
    F_W_PEAK,
    I_EVAL_EVENTS,
    I_EVENTS,
    I_OUT_NEXT,
    I_PAUSED,
    I_REJECTED,
    I_RHS,
    I_STARTED,
    I_STATUS,
    I_STEPS,
    I_SWITCHES,
    I_ZENO,
    ST_DONE,
    ST_MAX_SWITCHES,
    ST_NONFINITE,
    ST_RUNNING,
    ST_STOPPED,
    ST_UNDERFLOW,
    ST_ZENO,
)
from fivdisc.core.switch import (
    MODE_EVENT,
    MODE_KINK,
    MODE_START,
    NO_EVENT,
    _restart,
    _switch,
)
from fivdisc.model.layout import (
    A_F,
    A_N,
    A_WC,
    A_WCD,
    SEPARATION,
    SLIP,
    STICK,
)

# Step-size control exponents: 1/5 - 0.75 beta and beta.
_BETA = 0.04
_EXPO1 = 0.2 - 0.75 * _BETA

# Interior points (+1) at which a near-zero event function is probed within a step.
_PROBES = 4


@njit(cache=True, inline="always")
def _kinematic(i, ph):
    """Whether event ``i`` is a function of the state alone: a slipping slider's
    relative speed. The others (normal force, friction against its static limit,
    gap) need the contact solve of a right-hand side."""
    return i % 3 == 0 and ph[i // 3] == SLIP


# The right-hand side inlined where it runs most, the stages of a step (``_stages``) and
# the output samples (``_complete_rows``): a call passes the model's arrays field by
# field, dozens of words on the stack, a large part of a step and of a sample (the
# CHANGELOG gives the profile). Everywhere else ``evaluate`` is called as the compiled
# function.
_stage_rhs = njit(cache=True, inline="always")(evaluate.py_func)
_stage_events = njit(cache=True, inline="always")(event_values.py_func)


@njit(cache=True, _nrt=False)
def _stages(t, hs, y, ph, sg, mdl, wk, k, ytmp, kst, evn, tys, twk):
    """Stages 1-6 of the step ``[t, t + hs]`` from ``y`` into ``k``; ``ytmp`` is left at
    the last stage's state, the step's end, and ``evn`` at the event values there. With
    tangents (``tys``, ``twk`` given) each stage's state and evaluation go to its own
    row of them, for :func:`tangent.step` once the step is accepted; else to ``ytmp``
    and ``wk``."""
    ns = y.shape[0]
    ys = ytmp
    ws = wk
    for st in range(1, 7):
        if tys is not None:
            ys = tys[st]
            ws = twk[st]
        for i in range(ns):
            ys[i] = y[i]
        for j in range(st):
            a = hs * A[st, j]
            if a != 0.0:
                for i in range(ns):
                    ys[i] += a * k[j, i]
        # Into a vector of its own, then copied: a view k[st] would cost two atomic
        # reference-count updates per stage in a caller that counts references.
        _stage_rhs(t + C[st] * hs, ys, ph, sg, LEFT, mdl, ws, kst)
        for i in range(ns):
            k[st, i] = kst[i]
    if tys is not None:
        for i in range(ns):
            ytmp[i] = ys[i]
    _stage_events(ph, sg, ytmp, mdl, ws, evn)


@njit(cache=True, _nrt=False)
def _event_at(theta, i, t, h, rc, ph, sg, mdl, wk, dy, ytmp, evt, ist):
    """Event ``i`` at fraction ``theta`` of the step. A kinematic event is computed
    from the dense output of phidot alone, with the operations ``evaluate`` and
    ``event_values`` use (so the same value); any other fills ``evt`` with every
    event's value there."""
    if _kinematic(i, ph):
        n, _, half = sizes(mdl)
        om, _ = speed_at(t + theta * h, mdl.speed, LEFT)
        return sg[i // 3] * (om - dense_one(rc, theta, half + n + i // 3))
    ist[I_EVAL_EVENTS] += 1
    dense_eval(rc, theta, ytmp)
    evaluate(t + theta * h, ytmp, ph, sg, LEFT, mdl, wk, dy)
    event_values(ph, sg, ytmp, mdl, wk, evt)
    return evt[i]


@njit(cache=True, _nrt=False)
def locate(i, lo, hi, g_lo, g_hi, t, h, rc, ph, sg, mdl, wk, dy, ytmp, evt, ist):
    """Fraction of the step at which event ``i`` crosses zero, taken on the far side.

    Illinois false position on the bracket [lo, hi] with g(lo) > 0 >= g(hi): the kept
    end's value is halved when the same end survives twice, which closes the bracket
    superlinearly; a bisection steps in if the bracket fails to shrink fourfold in
    four iterations. Stops when the bracket is below 1e-12 s (the switches must be
    located to 1e-9 s).
    """
    tol = max(1e-12 / h, 1e-15)
    side = 0
    width_ref = hi - lo
    for it in range(200):
        width = hi - lo
        if width <= tol:
            break
        if it % 4 == 3:
            if width > 0.25 * width_ref:
                mid = 0.5 * (lo + hi)
            else:
                mid = lo + width * g_lo / (g_lo - g_hi)
            width_ref = width
        else:
            mid = lo + width * g_lo / (g_lo - g_hi)
        # Keep the trial point strictly inside so that the bracket always shrinks.
        mid = min(max(mid, lo + 0.5 * tol), hi - 0.5 * tol)
        gm = _event_at(mid, i, t, h, rc, ph, sg, mdl, wk, dy, ytmp, evt, ist)
        if gm > 0.0:
            lo = mid
            g_lo = gm
            if side == 1:
                g_hi *= 0.5
            side = 1
        else:
            hi = mid
            g_hi = gm
            if side == -1:
                g_lo *= 0.5
            side = -1
    return hi


@njit(cache=True, inline="always")
def _predicted_dip(a, b, c, r):
    """Where the parabola through an event function's values ``a``, ``b``, ``c`` at the
    fractions ``-r``, 0 and 1 of the step (the previous step's start, this step's ends)
    has its minimum, if inside the step and deep enough that the function may cross zero
    there although both ends are positive: the fraction, else 2."""
    if not r > 0.0 or not np.isfinite(r):
        return 2.0  # no previous step to fit (a step of zero length, or one too long)
    gamma = (a - b + (c - b) * r) / (r * (1.0 + r))
    if not gamma > 0.0:
        return 2.0
    beta = c - b - gamma
    vertex = -beta / (2.0 * gamma)
    if not 0.0 < vertex < 1.0:
        return 2.0
    low = b - beta * beta / (4.0 * gamma)
    # The parabola is an estimate: the function is searched if its predicted minimum is
    # below the depth of the predicted dip, not only below zero.
    if low < min(b, c) - low:
        return vertex
    return 2.0


@njit(cache=True, _nrt=False)
def _dip(i, vertex, g0, g1, t, h, rc, ph, sg, mdl, wk, dy, ytmp, evt, ist):
    """Search the dense output of event ``i``, positive at both ends of the step, for a
    dip below zero: successive parabolic interpolation on its minimum from ``vertex``.
    Returns the fraction where it crosses zero (on the far side, by :func:`locate`), or
    2 if its minimum inside the step is positive."""
    # The bracket (xa, ga) < (xm, gm) > (xb, gb): the lowest point and its neighbours.
    xa, xm, xb = 0.0, vertex, 1.0
    ga, gb = g0, g1
    gm = _event_at(xm, i, t, h, rc, ph, sg, mdl, wk, dy, ytmp, evt, ist)
    for _ in range(12):
        if gm <= 0.0:
            return locate(i, xa, xm, ga, gm, t, h, rc, ph, sg, mdl, wk, dy, ytmp, evt, ist)
        if gm > ga or gm > gb:
            return 2.0  # no minimum between the outer points
        da = (xm - xa) * (gm - gb)
        db = (xm - xb) * (gm - ga)
        den = 2.0 * (da - db)
        if den == 0.0:
            return 2.0
        x = xm - ((xm - xa) * da - (xm - xb) * db) / den
        if not xa < x < xb or abs(x - xm) < 1e-12 / h:
            return 2.0
        g = _event_at(x, i, t, h, rc, ph, sg, mdl, wk, dy, ytmp, evt, ist)
        if g <= 0.0:
            if x < xm:
                return locate(i, xa, x, ga, g, t, h, rc, ph, sg, mdl, wk, dy, ytmp, evt,
                              ist)
            return locate(i, xm, x, gm, g, t, h, rc, ph, sg, mdl, wk, dy, ytmp, evt, ist)
        if x < xm:
            if g < gm:
                xb, gb, xm, gm = xm, gm, x, g
            else:
                xa, ga = x, g
        elif g < gm:
            xa, ga, xm, gm = xm, gm, x, g
        else:
            xb, gb = x, g
    return 2.0


@njit(cache=True, _nrt=False)
def _sample_states(t0, t1, h, rc, ph, sg, ctl, out_y, out_aux, ist):
    """Sample the dense output of the step [t0, t0 + h] at output times in (t0, t1]: the
    state, and each slider's phase and slip sign (in the columns of its phase and of its
    normal force), from which :func:`_complete_rows` makes the rows."""
    i = ist[I_OUT_NEXT]
    n_out = out_y.shape[0]
    out_dt = ctl[C_OUT_DT]
    t_final = ctl[C_T_FINAL]
    while i < n_out:
        ti = min(i * out_dt, t_final)
        if ti > t1:
            break
        theta = (ti - t0) / h
        for c in range(rc.shape[1]):
            out_y[i, c] = dense_one(rc, theta, c)
        _begin_row(i, ph, sg, out_aux)
        i += 1
    ist[I_OUT_NEXT] = i


@njit(cache=True, inline="always")
def _begin_row(i, ph, sg, out_aux):
    """Keep each slider's phase and slip sign in output row ``i`` for
    :func:`_complete_rows`."""
    n_sl = ph.shape[0]
    for j in range(n_sl):
        out_aux[i, j] = sg[j]
        out_aux[i, 2 * n_sl + j] = ph[j]


@njit(cache=True, _nrt=False)
def _complete_rows(first, last, ctl, mdl, wk, ys, dy, ph, sg, out_y, out_aux, fst):
    """Complete the output rows ``first`` to ``last - 1`` that :func:`_sample_states`
    began, from the right-hand side at each: the state's contact kinematics (a sticking
    slider's phidot, and z, zdot of one in contact), per slider N, f, w under it
    (columns j, S + j, 3 S + j; the phase is in 2 S + j), then Omega. ``ys``, ``ph``,
    ``sg`` are scratch. ``fst[F_W_PEAK]`` keeps the largest |w| under the sliders (a nan
    stays), which the caller checks against the range of plate theory after each call
    of :func:`run` without reading the samples again.

    Done once the steps are taken, not at each sample: interleaved with the steps, the
    samples cost more (the CHANGELOG gives the figures)."""
    n, n_sl, half = sizes(mdl)
    # Rows of wk, not the view _aux gives: a function compiled without reference counts
    # (_nrt=False) may not take an array view from a callee.
    r_aux = work_rows(n_sl)[3]
    for i in range(first, last):
        ti = min(i * ctl[C_OUT_DT], ctl[C_T_FINAL])
        for j in range(n_sl):
            sg[j] = np.int64(out_aux[i, j])
            ph[j] = np.int64(out_aux[i, 2 * n_sl + j])
        for c in range(ys.shape[0]):
            ys[c] = out_y[i, c]
        _stage_rhs(ti, ys, ph, sg, LEFT, mdl, wk, dy)
        om, _ = speed_at(ti, mdl.speed, LEFT)
        for j in range(n_sl):
            if ph[j] == STICK:
                out_y[i, half + n + j] = om
            if ph[j] != SEPARATION:
                out_y[i, n + n_sl + j] = wk[r_aux + A_WC, j]
                out_y[i, half + n + n_sl + j] = wk[r_aux + A_WCD, j]
            out_aux[i, j] = wk[r_aux + A_N, j]
            out_aux[i, n_sl + j] = wk[r_aux + A_F, j]
            w = abs(wk[r_aux + A_WC, j])
            out_aux[i, 3 * n_sl + j] = wk[r_aux + A_WC, j]
            if not w <= fst[F_W_PEAK] and fst[F_W_PEAK] == fst[F_W_PEAK]:
                fst[F_W_PEAK] = w
        out_aux[i, 4 * n_sl] = om


@njit(cache=True, _nrt=False)
def _rms_scaled(a, y0, y1, atol, rtol, m):
    """RMS of ``a[:m]`` scaled by ``atol + rtol max(|y0|, |y1|)``."""
    acc = 0.0
    for i in range(m):
        sc = atol + rtol * max(abs(y0[i]), abs(y1[i]))
        acc += (a[i] / sc) ** 2
    return np.sqrt(acc / m)


@njit(cache=True, inline="always")
def _initial_step(t, y, f0, ph, sg, mdl, wk, ctl, ytmp, dy, m):
    """Starting step size (Hairer, Norsett & Wanner, Sec. II.4)."""
    rtol = ctl[C_RTOL]
    atol = ctl[C_ATOL]
    d0 = _rms_scaled(y, y, y, atol, rtol, m)
    d1 = _rms_scaled(f0, y, y, atol, rtol, m)
    if d0 < 1e-5 or d1 < 1e-5:
        h0 = 1e-6
    else:
        h0 = 0.01 * d0 / d1
    for i in range(y.shape[0]):
        ytmp[i] = y[i] + h0 * f0[i]
    evaluate(t + h0, ytmp, ph, sg, LEFT, mdl, wk, dy)
    for i in range(y.shape[0]):
        dy[i] = (dy[i] - f0[i]) / h0
    d2 = _rms_scaled(dy, y, y, atol, rtol, m)
    if max(d1, d2) <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** 0.2
    return min(100.0 * h0, h1)


# nogil: the caller may import what it needs next in another thread meanwhile
# (fivdisc.engine.preload).
@njit(cache=True, nogil=True)
def run(t_target, mdl, ctl, fst, ist, y, ph, sg, k, ev_prev, breaks, out_y, out_aux, ev_t,
        ev_i, tan=None):
    """Advance the integration until ``t >= t_target``, the end, a failure, or a nearly
    full event buffer. All arrays are updated in place (``ph``/``sg``: every slider's
    phase and slip sign); returns the status.

    ``tan``, if given, is ``(V, KV)``, shapes ``(k, nd)`` and ``(k, 7, nd)`` for the
    dynamic state's ``nd`` coordinates: tangent vectors carried along (rows of ``V``)
    with their stage derivatives: given at the start, they
    are carried across it; given later, :func:`tangent.prepare` makes them ready. Without
    it no tangent code is compiled in.
    """
    ns = y.shape[0]
    nd = n_dynamic(mdl)
    n_ev = ev_prev.shape[0]
    wk = new_work(mdl, y)
    n_sl = sizes(mdl)[1]
    ynew = np.empty(ns)
    ytmp = np.empty(ns)
    yout = np.empty(ns)
    dy = np.empty(ns)
    kst = np.empty(ns)
    rc = np.empty((5, ns))
    evn = np.empty(n_ev)
    evt = np.empty(n_ev)
    probes = np.empty((_PROBES, n_ev))
    # Event values at the previous step's start, for the dip predicted from three values
    # (inf: none since the start of this call, a switch or a kink).
    ev_old = np.full(n_ev, np.inf)
    h_old = 0.0
    err_vec = np.empty(ns)
    rtol = ctl[C_RTOL]
    atol = ctl[C_ATOL]
    max_step = ctl[C_MAX_STEP]
    t_final = ctl[C_T_FINAL]
    cap = ev_t.shape[0]

    if tan is not None:
        tv, tk = tan
        tsc = tangent.scratch(mdl, y, tv.shape[0])
        tcx, tvn, tvs, ypre, sgpre = tsc[0], tsc[3], tsc[4], tsc[9], tsc[10]
        tys, twk = tsc[11], tsc[12]

    t = fst[F_T]
    h = fst[F_H]
    first_row = ist[I_OUT_NEXT]
    if ist[I_STARTED] == 0:
        if tan is not None:
            ph_start = ph.copy()
            tangent.before_switch(y, sg, tsc)
        _switch(MODE_START, NO_EVENT, t, y, ph, sg, ph, ev_prev, mdl, wk, dy, k, ev_prev, ev_t,
                ev_i, ist, fst)
        _restart(t, y, ph, sg, mdl, wk, k, ev_prev)
        if tan is not None:
            tangent.saltation(MODE_START, NO_EVENT, t, ypre, ph_start, sgpre, ev_prev, y, ph, sg,
                              k[0], wk, mdl, tv, tk, tsc)
        if h <= 0.0:
            h = _initial_step(t, y, k[0], ph, sg, mdl, wk, ctl, ytmp, dy, nd)
        if ist[I_OUT_NEXT] == 0 and out_y.shape[0] > 0:
            for i in range(ns):
                out_y[0, i] = y[i]
            _begin_row(0, ph, sg, out_aux)
            ist[I_OUT_NEXT] = 1
        ist[I_STARTED] = 1
        ist[I_RHS] += 2

    status = ST_RUNNING
    after_reject = ist[I_PAUSED] == 2
    err_old = fst[F_ERR_OLD] if ist[I_PAUSED] else 1e-4
    ist[I_PAUSED] = 0
    call_steps = ctl[C_CALL_STEPS]
    tried = 0
    while True:
        if t >= t_final:
            status = ST_DONE
            break
        if t >= t_target or ist[I_EVENTS] > cap - 4 * n_sl - 4:
            break
        if tried >= call_steps > 0:
            ist[I_PAUSED] = 2 if after_reject else 1
            fst[F_ERR_OLD] = err_old
            break
        tried += 1
        kb = np.searchsorted(breaks, t, side="right")
        tb = breaks[kb] if kb < breaks.shape[0] else t_final
        tb = min(tb, t_final)
        hs = h
        if max_step > 0.0:
            hs = min(hs, max_step)
        land = False
        if t + hs >= tb or (tb - t - hs) < 1e-3 * hs:
            hs = tb - t
            land = True

        if tan is not None:
            _stages(t, hs, y, ph, sg, mdl, wk, k, ytmp, kst, evn, tys, twk)
        else:
            _stages(t, hs, y, ph, sg, mdl, wk, k, ytmp, kst, evn, None, None)
        for i in range(ns):
            ynew[i] = ytmp[i]
        ist[I_RHS] += 6
        for i in range(ns):
            err_vec[i] = 0.0
        for st in range(7):
            a = hs * E[st]
            if a != 0.0:
                for i in range(ns):
                    err_vec[i] += a * k[st, i]
        err = _rms_scaled(err_vec, y, ynew, atol, rtol, nd)

        if not np.isfinite(err) or err > 1.0:
            if np.isfinite(err):
                h = hs / min(5.0, err**_EXPO1 / 0.9)
            else:
                h = 0.25 * hs
            ist[I_REJECTED] += 1
            after_reject = True
            if h < 1e-14 * max(1.0, abs(t)):
                status = ST_UNDERFLOW if np.isfinite(err) else ST_NONFINITE
                break
            continue

        ist[I_STEPS] += 1
        t_new = tb if land else t + hs
        if tan is not None:
            tangent.step(t, hs, ph, sg, mdl, tys, twk, tv, tk, tvn, tvs, tcx)

        have_rc = False
        probed = 0
        which = NO_EVENT
        theta = 2.0
        for i in range(n_ev):
            if evn[i] == np.inf:
                continue
            if ev_prev[i] > 0.0 and evn[i] <= 0.0:
                if not have_rc:
                    dense_coefficients(y, ynew, k, hs, rc)
                    have_rc = True
                th = locate(i, 0.0, 1.0, ev_prev[i], evn[i], t, hs, rc, ph, sg, mdl, wk,
                            dy, ytmp, evt, ist)
            elif (ev_prev[i] > 0.0 and ev_old[i] < np.inf and hs > 0.0
                  and _predicted_dip(ev_old[i], ev_prev[i], evn[i], h_old / hs) <= 1.0):
                # Positive at both ends, but the parabola through this and the previous
                # step's values dips inside the step: an excursion through zero narrower
                # than the step (a brief slip inside a stick, a grazing), which the ends
                # and the probes below can miss. Its minimum is searched for.
                if not have_rc:
                    dense_coefficients(y, ynew, k, hs, rc)
                    have_rc = True
                th = _dip(i, _predicted_dip(ev_old[i], ev_prev[i], evn[i], h_old / hs),
                          ev_prev[i], evn[i], t, hs, rc, ph, sg, mdl, wk, dy, ytmp, evt, ist)
                if th > 1.0:
                    continue
            elif ev_prev[i] > 0.0 and min(ev_prev[i], evn[i]) < 2.0 * abs(evn[i] - ev_prev[i]):
                # Both ends positive but close to zero for the change over the step: the
                # function may dip below zero and back inside it (a brief separation or
                # stick), so probe the dense output at interior points.
                if not have_rc:
                    dense_coefficients(y, ynew, k, hs, rc)
                    have_rc = True
                th = 2.0
                g_lo = ev_prev[i]
                kinematic = _kinematic(i, ph)
                for p in range(1, _PROBES):
                    tp = p / _PROBES
                    # One right-hand side at a probe serves every event probed there.
                    if kinematic or (probed >> p) & 1 == 0:
                        gp = _event_at(tp, i, t, hs, rc, ph, sg, mdl, wk, dy, ytmp,
                                       probes[p], ist)
                        if not kinematic:
                            probed |= 1 << p
                    else:
                        gp = probes[p, i]
                    if gp <= 0.0:
                        th = locate(i, (p - 1) / _PROBES, tp, g_lo, gp, t, hs, rc, ph, sg,
                                    mdl, wk, dy, ytmp, evt, ist)
                        break
                    g_lo = gp
                if th > 1.0:
                    continue
            elif ev_prev[i] <= 0.0 and evn[i] < min(ev_prev[i], 0.0):
                # A phase entered exactly on its boundary is already leaving it.
                th = 1.0
            else:
                continue
            if th < theta:
                theta = th
                which = i

        # PI control (Gustafsson; Hairer, Norsett & Wanner II.4): damps the step-size
        # oscillation that plain error-per-step control shows, and so rejections.
        pi = err**_EXPO1 / err_old**_BETA if err > 0.0 else 0.0
        fac = min(5.0, max(0.1, 0.9 / pi)) if pi > 0.0 else 5.0
        err_old = max(err, 1e-4)
        if after_reject:
            fac = min(fac, 1.0)
        after_reject = False

        if which >= 0:
            if not have_rc:
                dense_coefficients(y, ynew, k, hs, rc)
            t_e = t_new if theta >= 1.0 else t + theta * hs
            _sample_states(t, t_e, hs, rc, ph, sg, ctl, out_y, out_aux, ist)
            dense_eval(rc, theta, y)
            first_new = ist[I_EVENTS]
            fst[F_H_CAP] = np.inf
            ph_start = ph.copy()
            ev_start = ev_prev.copy()
            if tan is not None:
                tangent.interpolate(theta, hs, tv, tk, tsc)
                tangent.before_switch(y, sg, tsc)
            _switch(MODE_EVENT, which, t_e, y, ph, sg, ph_start, ev_start, mdl, wk, dy, k,
                    ev_prev, ev_t, ev_i, ist, fst)
            t = t_e
            _restart(t, y, ph, sg, mdl, wk, k, ev_prev)
            ev_old[:] = np.inf
            ist[I_RHS] += 1
            if tan is not None:
                tangent.saltation(MODE_EVENT, which, t, ypre, ph_start, sgpre, ev_start, y,
                                  ph, sg, k[0], wk, mdl, tv, tk, tsc)
            stop_mask = int(ctl[C_STOP_MASK])
            for e in range(first_new, ist[I_EVENTS]):
                if stop_mask & (1 << ev_i[e, EVI_KIND]):
                    status = ST_STOPPED
            ist[I_SWITCHES] += 1
            if t - fst[F_LAST_SWITCH] < ctl[C_ZENO_DT]:
                ist[I_ZENO] += 1
            else:
                ist[I_ZENO] = 0
            fst[F_LAST_SWITCH] = t
            h = hs * min(fac, 1.0)
            if fst[F_H_CAP] < np.inf:
                h = min(h, 0.25 * fst[F_H_CAP])
            if status == ST_STOPPED:
                break
            if ist[I_ZENO] >= ctl[C_ZENO_COUNT]:
                status = ST_ZENO
                break
            if ist[I_SWITCHES] >= ctl[C_MAX_SWITCHES]:
                status = ST_MAX_SWITCHES
                break
            continue

        for i in range(ns):
            if not np.isfinite(ynew[i]):
                status = ST_NONFINITE
        if status != ST_RUNNING:
            break
        next_out = min(ist[I_OUT_NEXT] * ctl[C_OUT_DT], t_final)
        if ist[I_OUT_NEXT] < out_y.shape[0] and next_out <= t_new:
            if not have_rc:
                dense_coefficients(y, ynew, k, hs, rc)
            _sample_states(t, t_new, hs, rc, ph, sg, ctl, out_y, out_aux, ist)
        for i in range(ns):
            y[i] = ynew[i]
        for i in range(ns):
            k[0, i] = k[6, i]
        for i in range(n_ev):
            ev_old[i] = ev_prev[i]
            ev_prev[i] = evn[i]
        h_old = hs
        if tan is not None:
            tangent.accept(tv, tk, tvn)
        t = t_new
        h = hs * fac
        if land and t < t_final:
            if tan is not None:
                ph_start = ph.copy()
                tangent.before_switch(y, sg, tsc)
            _switch(MODE_KINK, NO_EVENT, t, y, ph, sg, ph, ev_prev, mdl, wk, dy, k, ev_prev, ev_t,
                    ev_i, ist, fst)
            _restart(t, y, ph, sg, mdl, wk, k, ev_prev)
            ev_old[:] = np.inf
            ist[I_RHS] += 1
            if tan is not None:
                tangent.saltation(MODE_KINK, NO_EVENT, t, ypre, ph_start, sgpre, ev_prev, y, ph, sg,
                                  k[0], wk, mdl, tv, tk, tsc)

    _complete_rows(first_row, ist[I_OUT_NEXT], ctl, mdl, wk, yout, dy, ph.copy(), sg.copy(),
                   out_y, out_aux, fst)
    fst[F_T] = t
    fst[F_H] = h
    ist[I_STATUS] = status
    return status
