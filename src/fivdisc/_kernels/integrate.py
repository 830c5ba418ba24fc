"""The non-smooth time integration: adaptive DOPRI5 steps inside a phase machine.

One call of :func:`run` advances the integrator from its saved state until a target
time is passed, the run ends, it fails, or the event buffer is nearly full; the
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

from fivdisc._kernels.dopri5 import A, C, E, dense_coefficients, dense_eval
from fivdisc._kernels.dynamics import (
    M_COEF,
    M_KNOTS,
    P_IMPACT,
    P_LMAX,
    P_MUS,
    SEPARATION,
    SLIP,
    STICK,
    evaluate,
    event_values,
    plastic_impact,
    speed_at,
)

# Status codes (``ist[I_STATUS]``).
ST_RUNNING = 0
ST_DONE = 1
ST_NONFINITE = 2
ST_UNDERFLOW = 3
ST_ZENO = 4
ST_MAX_SWITCHES = 5
ST_STOPPED = 6

# Step-size control exponents: 1/5 - 0.75 beta and beta.
_BETA = 0.04
_EXPO1 = 0.2 - 0.75 * _BETA

# Interior points (+1) at which a near-zero event function is probed within a step.
_PROBES = 4

# Event kinds.
EV_STICK = 0
EV_SLIP = 1
EV_REVERSAL = 2
EV_SEPARATION = 3
EV_RECONTACT = 4

# Integer state slots.
I_PHASE = 0
I_SIGN = 1
I_STATUS = 2
I_STEPS = 3
I_REJECTED = 4
I_RHS = 5
I_OUT_NEXT = 6
I_EVENTS = 7
I_SWITCHES = 8
I_ZENO = 9
I_STARTED = 10
I_FAIL_PHASE = 11
I_EVAL_EVENTS = 12
N_ISTATE = 13

# Float state slots.
F_T = 0
F_H = 1
F_LAST_SWITCH = 2
N_FSTATE = 3

# Control slots.
C_RTOL = 0
C_ATOL = 1
C_MAX_STEP = 2
C_T_FINAL = 3
C_OUT_DT = 4
C_MAX_SWITCHES = 5
C_ZENO_DT = 6
C_ZENO_COUNT = 7
C_STOP_MASK = 8
N_CONTROL = 9


@njit(cache=True)
def _contact_kinematics_into_slider(y, wc, wcd):
    n = (y.shape[0] - 4) // 2
    y[n + 1] = wc
    y[2 * n + 3] = wcd


@njit(cache=True)
def choose_contact_phase(t, y, s_hint, mdl, work, dy):
    """Phase of a slider in contact at state ``y``: stick, slip (with its sign) or,
    where contact would need a pulling normal force, separation."""
    par = mdl[0]
    knots = mdl[M_KNOTS]
    coef = mdl[M_COEF]
    n = (y.shape[0] - 4) // 2
    om, _ = speed_at(t, knots, coef, True)
    v = om - y[2 * n + 2]
    s = s_hint
    if v == 0.0:
        nf, f, wc, wcd, _ = evaluate(t, y, STICK, s, True, mdl, work, dy)
        if nf > 0.0 and abs(f) < par[P_MUS] * nf:
            return STICK, s
        if f > 0.0:
            s = 1
        elif f < 0.0:
            s = -1
    elif v > 0.0:
        s = 1
    else:
        s = -1
    nf, f, wc, wcd, _ = evaluate(t, y, SLIP, s, True, mdl, work, dy)
    if nf < 0.0:
        _contact_kinematics_into_slider(y, wc, wcd)
        return SEPARATION, s
    return SLIP, s


@njit(cache=True)
def _record(t, kind, frm, to, ev_t, ev_i, ist):
    i = ist[I_EVENTS]
    if i < ev_t.shape[0]:
        ev_t[i] = t
        ev_i[i, 0] = kind
        ev_i[i, 1] = frm
        ev_i[i, 2] = to
        ist[I_EVENTS] = i + 1


@njit(cache=True)
def _record_change(t, old_phase, old_s, new_phase, new_s, ev_t, ev_i, ist):
    if old_phase == new_phase:
        if new_phase == SLIP and old_s != new_s:
            _record(t, EV_REVERSAL, old_phase, new_phase, ev_t, ev_i, ist)
        return
    if new_phase == SEPARATION:
        kind = EV_SEPARATION
    elif old_phase == SEPARATION:
        kind = EV_RECONTACT
    elif new_phase == STICK:
        kind = EV_STICK
    else:
        kind = EV_SLIP
    _record(t, kind, old_phase, new_phase, ev_t, ev_i, ist)


@njit(cache=True)
def apply_switch(which, t, y, phase, s, mdl, work, dy, ev_t, ev_i, ist):
    """Carry the state across the switch triggered by event ``which`` of ``phase``."""
    par = mdl[0]
    knots = mdl[M_KNOTS]
    coef = mdl[M_COEF]
    n = (y.shape[0] - 4) // 2
    if phase == SEPARATION:
        # Re-contact: fill g, g' for the impact map, then pick the contact phase.
        evaluate(t, y, SEPARATION, s, True, mdl, work, dy)
        if par[P_IMPACT] != 0.0:
            plastic_impact(y, mdl, work)
        _record(t, EV_RECONTACT, SEPARATION, SLIP, ev_t, ev_i, ist)
        new_phase, new_s = choose_contact_phase(t, y, s, mdl, work, dy)
        if new_phase == SEPARATION:
            _record(t, EV_SEPARATION, SLIP, SEPARATION, ev_t, ev_i, ist)
        else:
            ev_i[ist[I_EVENTS] - 1, 2] = new_phase
        return new_phase, new_s
    is_normal_force_event = (phase == SLIP and which == 1) or (phase == STICK and which == 2)
    if is_normal_force_event:
        _, _, wc, wcd, _ = evaluate(t, y, phase, s, True, mdl, work, dy)
        if phase == STICK:
            om, _ = speed_at(t, knots, coef, True)
            y[2 * n + 2] = om
        _contact_kinematics_into_slider(y, wc, wcd)
        _record(t, EV_SEPARATION, phase, SEPARATION, ev_t, ev_i, ist)
        return SEPARATION, s
    # Relative velocity reached zero (slip) or the static limit was reached (stick):
    # the slider moves with the disc at this instant; decide from the forces.
    om, _ = speed_at(t, knots, coef, True)
    y[2 * n + 2] = om
    new_phase, new_s = choose_contact_phase(t, y, s, mdl, work, dy)
    _record_change(t, phase, s, new_phase, new_s, ev_t, ev_i, ist)
    return new_phase, new_s


@njit(cache=True)
def _event_at(theta, i, t, h, rc, phase, s, mdl, work, dy, ytmp, evt, ist):
    ist[I_EVAL_EVENTS] += 1
    dense_eval(rc, theta, ytmp)
    nf, f, wc, _, v = evaluate(t + theta * h, ytmp, phase, s, False, mdl, work, dy)
    event_values(phase, s, nf, f, wc, v, ytmp, mdl[0], evt)
    return evt[i]


@njit(cache=True)
def locate(i, lo, hi, g_lo, g_hi, t, h, rc, phase, s, mdl, work, dy, ytmp, evt, ist):
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
        gm = _event_at(mid, i, t, h, rc, phase, s, mdl, work, dy, ytmp, evt, ist)
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


@njit(cache=True)
def _write_outputs(t0, t1, h, rc, phase, s, mdl, work, dy, ytmp, ctl, out_y, out_aux, ist):
    """Sample the dense output of the step [t0, t0 + h] at output times in (t0, t1]."""
    i = ist[I_OUT_NEXT]
    n_out = out_y.shape[0]
    out_dt = ctl[C_OUT_DT]
    t_final = ctl[C_T_FINAL]
    while i < n_out:
        ti = min(i * out_dt, t_final)
        if ti > t1:
            break
        dense_eval(rc, (ti - t0) / h, ytmp)
        _write_sample(i, ti, ytmp, phase, s, mdl, work, dy, out_y, out_aux)
        i += 1
    ist[I_OUT_NEXT] = i


@njit(cache=True)
def _write_sample(i, ti, ys, phase, s, mdl, work, dy, out_y, out_aux):
    n = (ys.shape[0] - 4) // 2
    nf, f, wc, wcd, _ = evaluate(ti, ys, phase, s, False, mdl, work, dy)
    om, _ = speed_at(ti, mdl[M_KNOTS], mdl[M_COEF], False)
    if phase == STICK:
        ys[2 * n + 2] = om
    if phase != SEPARATION:
        ys[n + 1] = wc
        ys[2 * n + 3] = wcd
    out_y[i, :] = ys
    out_aux[i, 0] = nf
    out_aux[i, 1] = f
    out_aux[i, 2] = phase
    out_aux[i, 3] = wc
    out_aux[i, 4] = om


@njit(cache=True)
def _rms_scaled(a, y0, y1, atol, rtol):
    acc = 0.0
    for i in range(a.shape[0]):
        sc = atol + rtol * max(abs(y0[i]), abs(y1[i]))
        acc += (a[i] / sc) ** 2
    return np.sqrt(acc / a.shape[0])


@njit(cache=True)
def _initial_step(t, y, f0, phase, s, mdl, work, ctl, ytmp, dy):
    """Starting step size (Hairer, Norsett & Wanner, Sec. II.4)."""
    rtol = ctl[C_RTOL]
    atol = ctl[C_ATOL]
    d0 = _rms_scaled(y, y, y, atol, rtol)
    d1 = _rms_scaled(f0, y, y, atol, rtol)
    if d0 < 1e-5 or d1 < 1e-5:
        h0 = 1e-6
    else:
        h0 = 0.01 * d0 / d1
    for i in range(y.shape[0]):
        ytmp[i] = y[i] + h0 * f0[i]
    evaluate(t + h0, ytmp, phase, s, False, mdl, work, dy)
    for i in range(y.shape[0]):
        dy[i] = (dy[i] - f0[i]) / h0
    d2 = _rms_scaled(dy, y, y, atol, rtol)
    if max(d1, d2) <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** 0.2
    return min(100.0 * h0, h1)


@njit(cache=True)
def _restart(t, y, phase, s, mdl, work, k, ev_prev):
    nf, f, wc, _, v = evaluate(t, y, phase, s, True, mdl, work, k[0])
    event_values(phase, s, nf, f, wc, v, y, mdl[0], ev_prev)


@njit(cache=True)
def run(t_target, mdl, ctl, fst, ist, y, k, ev_prev, breaks, out_y, out_aux, ev_t, ev_i):
    """Advance the integration until ``t >= t_target``, the end, a failure, or a nearly
    full event buffer. All arrays are updated in place; returns the status."""
    ns = y.shape[0]
    width = max(ns, int(mdl[0][P_LMAX]) + 2)
    work = np.zeros((5, width))
    ynew = np.empty(ns)
    ytmp = np.empty(ns)
    yout = np.empty(ns)
    dy = np.empty(ns)
    rc = np.empty((5, ns))
    evn = np.empty(3)
    evt = np.empty(3)
    err_vec = np.empty(ns)
    rtol = ctl[C_RTOL]
    atol = ctl[C_ATOL]
    max_step = ctl[C_MAX_STEP]
    t_final = ctl[C_T_FINAL]
    cap = ev_t.shape[0]

    t = fst[F_T]
    h = fst[F_H]
    phase = ist[I_PHASE]
    s = ist[I_SIGN]
    if ist[I_STARTED] == 0:
        if phase != SEPARATION:
            phase, s = choose_contact_phase(t, y, s, mdl, work, dy)
        _restart(t, y, phase, s, mdl, work, k, ev_prev)
        if h <= 0.0:
            h = _initial_step(t, y, k[0], phase, s, mdl, work, ctl, ytmp, dy)
        if ist[I_OUT_NEXT] == 0 and out_y.shape[0] > 0:
            yout[:] = y
            _write_sample(0, t, yout, phase, s, mdl, work, dy, out_y, out_aux)
            ist[I_OUT_NEXT] = 1
        ist[I_STARTED] = 1
        ist[I_RHS] += 2

    status = ST_RUNNING
    after_reject = False
    err_old = 1e-4
    while True:
        if t >= t_final:
            status = ST_DONE
            break
        if t >= t_target or ist[I_EVENTS] > cap - 4:
            break
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

        for st in range(1, 7):
            ytmp[:] = y
            for j in range(st):
                a = hs * A[st, j]
                if a != 0.0:
                    for i in range(ns):
                        ytmp[i] += a * k[j, i]
            nf, f, wc, _, v = evaluate(t + C[st] * hs, ytmp, phase, s, False, mdl, work, k[st])
        ynew[:] = ytmp
        ist[I_RHS] += 6
        err_vec[:] = 0.0
        for st in range(7):
            a = hs * E[st]
            if a != 0.0:
                for i in range(ns):
                    err_vec[i] += a * k[st, i]
        err = _rms_scaled(err_vec, y, ynew, atol, rtol)

        if not np.isfinite(err) or err > 1.0:
            if np.isfinite(err):
                h = hs / min(5.0, err**_EXPO1 / 0.9)
            else:
                h = 0.25 * hs
            ist[I_REJECTED] += 1
            after_reject = True
            if h < 1e-14 * max(1.0, abs(t)):
                status = ST_UNDERFLOW if np.isfinite(err) else ST_NONFINITE
                ist[I_FAIL_PHASE] = phase
                break
            continue

        ist[I_STEPS] += 1
        t_new = tb if land else t + hs
        event_values(phase, s, nf, f, wc, v, ynew, mdl[0], evn)

        have_rc = False
        which = -1
        theta = 2.0
        for i in range(3):
            if evn[i] == np.inf:
                continue
            if ev_prev[i] > 0.0 and evn[i] <= 0.0:
                if not have_rc:
                    dense_coefficients(y, ynew, k, hs, rc)
                    have_rc = True
                th = locate(i, 0.0, 1.0, ev_prev[i], evn[i], t, hs, rc, phase, s, mdl, work,
                            dy, ytmp, evt, ist)
            elif ev_prev[i] > 0.0 and min(ev_prev[i], evn[i]) < 2.0 * abs(evn[i] - ev_prev[i]):
                # Both ends positive but close to zero for the change over the step: the
                # function may dip below zero and back inside it (a brief separation or
                # stick), so probe the dense output at interior points.
                if not have_rc:
                    dense_coefficients(y, ynew, k, hs, rc)
                    have_rc = True
                th = 2.0
                g_lo = ev_prev[i]
                for p in range(1, _PROBES):
                    tp = p / _PROBES
                    gp = _event_at(tp, i, t, hs, rc, phase, s, mdl, work, dy, ytmp, evt, ist)
                    if gp <= 0.0:
                        th = locate(i, (p - 1) / _PROBES, tp, g_lo, gp, t, hs, rc, phase, s,
                                    mdl, work, dy, ytmp, evt, ist)
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
            _write_outputs(t, t_e, hs, rc, phase, s, mdl, work, dy, yout, ctl, out_y, out_aux, ist)
            dense_eval(rc, theta, y)
            first_new = ist[I_EVENTS]
            phase, s = apply_switch(which, t_e, y, phase, s, mdl, work, dy, ev_t, ev_i, ist)
            stop_mask = int(ctl[C_STOP_MASK])
            for e in range(first_new, ist[I_EVENTS]):
                if stop_mask & (1 << ev_i[e, 0]):
                    status = ST_STOPPED
            t = t_e
            _restart(t, y, phase, s, mdl, work, k, ev_prev)
            ist[I_RHS] += 1
            ist[I_SWITCHES] += 1
            if t - fst[F_LAST_SWITCH] < ctl[C_ZENO_DT]:
                ist[I_ZENO] += 1
            else:
                ist[I_ZENO] = 0
            fst[F_LAST_SWITCH] = t
            h = hs * min(fac, 1.0)
            if status == ST_STOPPED:
                break
            if ist[I_ZENO] >= ctl[C_ZENO_COUNT]:
                status = ST_ZENO
                ist[I_FAIL_PHASE] = phase
                break
            if ist[I_SWITCHES] >= ctl[C_MAX_SWITCHES]:
                status = ST_MAX_SWITCHES
                ist[I_FAIL_PHASE] = phase
                break
            continue

        for i in range(ns):
            if not np.isfinite(ynew[i]):
                status = ST_NONFINITE
        if status != ST_RUNNING:
            ist[I_FAIL_PHASE] = phase
            break
        next_out = min(ist[I_OUT_NEXT] * ctl[C_OUT_DT], t_final)
        if ist[I_OUT_NEXT] < out_y.shape[0] and next_out <= t_new:
            if not have_rc:
                dense_coefficients(y, ynew, k, hs, rc)
            _write_outputs(t, t_new, hs, rc, phase, s, mdl, work, dy, yout, ctl, out_y, out_aux,
                           ist)
        y[:] = ynew
        for i in range(ns):
            k[0, i] = k[6, i]
        for i in range(3):
            ev_prev[i] = evn[i]
        t = t_new
        h = hs * fac
        if land and t < t_final:
            # Speed-profile kink: Omegadot jumps, so the stick reaction does too.
            if phase != SEPARATION:
                old_phase = phase
                old_s = s
                if phase == STICK:
                    om, _ = speed_at(t, mdl[M_KNOTS], mdl[M_COEF], True)
                    y[ns - 2] = om
                phase, s = choose_contact_phase(t, y, s, mdl, work, dy)
                _record_change(t, old_phase, old_s, phase, s, ev_t, ev_i, ist)
            _restart(t, y, phase, s, mdl, work, k, ev_prev)
            ist[I_RHS] += 1

    fst[F_T] = t
    fst[F_H] = h
    ist[I_PHASE] = phase
    ist[I_SIGN] = s
    ist[I_STATUS] = status
    return status
