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
from fivdisc._kernels.dynamics import evaluate, event_values, new_work, speed_at
from fivdisc._kernels.impact import contact_impact, contact_velocity, single_impact
from fivdisc._kernels.layout import (
    A_F,
    A_GPQ,
    A_GPQD,
    A_L2GQ,
    A_N,
    A_PHID,
    A_WC,
    A_WCD,
    E_IMPACT,
    EV_RECONTACT,
    EV_REVERSAL,
    EV_SEPARATION,
    EV_SLIP,
    EV_STICK,
    O_IMPACT,
    O_MIN_FLIGHT,
    O_MUS,
    S_KZ,
    S_MASS,
    S_N0,
    S_SIGMA,
    SEPARATION,
    SLIP,
    STICK,
    n_dynamic,
    sizes,
    work_rows,
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

# Integer state slots.
I_STATUS = 0
I_STEPS = 1
I_REJECTED = 2
I_RHS = 3
I_OUT_NEXT = 4
I_EVENTS = 5
I_SWITCHES = 6
I_ZENO = 7
I_STARTED = 8
I_EVAL_EVENTS = 9
N_ISTATE = 10

# Float state slots.
F_T = 0
F_H = 1
F_LAST_SWITCH = 2
F_H_CAP = 3
N_FSTATE = 4

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

# Columns of the event table's integer part.
EVI_KIND = 0
EVI_FROM = 1
EVI_TO = 2
EVI_SLIDER = 3
N_EVI = 4


@njit(cache=True)
def _aux(mdl, wk):
    """The per-slider block of the work array: row ``A_*``, column j."""
    return wk[work_rows(mdl.slider.shape[1])[3]:]


@njit(cache=True)
def _separate(j, y, ph, mdl, wk):
    """Slider j leaves the disc: its own z, zdot start from the contact kinematics that
    the last ``evaluate`` left in ``wk``."""
    aux = _aux(mdl, wk)
    n, ns, half = sizes(mdl)
    y[n + ns + j] = aux[A_WC, j]
    y[half + n + ns + j] = aux[A_WCD, j]
    ph[j] = SEPARATION


@njit(cache=True)
def choose_phase(j, t, y, ph, sg, mdl, wk, dy):
    """Phase of slider j in contact at state ``y``, the others' phases held: stick, slip
    (with its sign) or, where contact would need a pulling normal force, separation."""
    aux = _aux(mdl, wk)
    n, _, half = sizes(mdl)
    om, _ = speed_at(t, mdl.speed, True)
    v = om - y[half + n + j]
    s = sg[j]
    if v == 0.0:
        ph[j] = STICK
        evaluate(t, y, ph, sg, True, mdl, wk, dy)
        nf = aux[A_N, j]
        f = aux[A_F, j]
        if nf > 0.0 and abs(f) < mdl.opts[O_MUS] * nf:
            return
        if f > 0.0:
            s = 1
        elif f < 0.0:
            s = -1
    elif v > 0.0:
        s = 1
    else:
        s = -1
    ph[j] = SLIP
    sg[j] = s
    evaluate(t, y, ph, sg, True, mdl, wk, dy)
    if aux[A_N, j] < 0.0:
        _separate(j, y, ph, mdl, wk)


@njit(cache=True)
def _record(t, kind, frm, to, j, ev_t, ev_i, ist):
    i = ist[I_EVENTS]
    if i < ev_t.shape[0]:
        ev_t[i] = t
        ev_i[i, EVI_KIND] = kind
        ev_i[i, EVI_FROM] = frm
        ev_i[i, EVI_TO] = to
        ev_i[i, EVI_SLIDER] = j
        ist[I_EVENTS] = i + 1


@njit(cache=True)
def _record_change(t, old_phase, old_s, new_phase, new_s, j, ev_t, ev_i, ist):
    if old_phase == new_phase:
        if new_phase == SLIP and old_s != new_s:
            _record(t, EV_REVERSAL, old_phase, new_phase, j, ev_t, ev_i, ist)
        return
    if new_phase == SEPARATION:
        kind = EV_SEPARATION
    elif old_phase == SEPARATION:
        kind = EV_RECONTACT
    elif new_phase == STICK:
        kind = EV_STICK
    else:
        kind = EV_SLIP
    _record(t, kind, old_phase, new_phase, j, ev_t, ev_i, ist)


@njit(cache=True)
def settle(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist):
    """After a switch, re-check every slider in contact (several sliders only): one that
    would need N < 0 separates, a sticking one beyond the static limit slips; violators
    switch one at a time, lowest index first, until none is left."""
    aux = _aux(mdl, wk)
    n, ns, half = sizes(mdl)
    if ns == 1:
        return
    om, _ = speed_at(t, mdl.speed, True)
    for _ in range(4 * ns + 4):
        evaluate(t, y, ph, sg, True, mdl, wk, dy)
        changed = False
        for k in range(ns):
            if ph[k] == SEPARATION:
                continue
            nf = aux[A_N, k]
            f = aux[A_F, k]
            if nf < 0.0:
                old = ph[k]
                if old == STICK:
                    y[half + n + k] = om
                _separate(k, y, ph, mdl, wk)
                _record(t, EV_SEPARATION, old, SEPARATION, k, ev_t, ev_i, ist)
                changed = True
                break
            if ph[k] == STICK and abs(f) > mdl.opts[O_MUS] * nf:
                ph[k] = SLIP
                sg[k] = 1 if f > 0.0 else -1
                _record(t, EV_SLIP, STICK, SLIP, k, ev_t, ev_i, ist)
                changed = True
                break
        if not changed:
            return


@njit(cache=True)
def _surface_acceleration(k, y, mdl, wk, dy):
    """Normal acceleration of the disc's surface under slider k, from ``evaluate``'s
    derivatives ``dy`` at ``y`` [m/s^2]."""
    g = wk
    aux = _aux(mdl, wk)
    n, _, half = sizes(mdl)
    phid = aux[A_PHID, k]
    acc = 2.0 * phid * aux[A_GPQD, k] - phid * phid * aux[A_L2GQ, k]
    acc += dy[half + n + k] * aux[A_GPQ, k]
    for i in range(n):
        acc += g[k, i] * dy[half + i]
    return acc


@njit(cache=True)
def _impact(j, t, y, ph, sg, mdl, wk, dy, fst, released):
    """Plastic impact of slider j landing while others are in contact.

    Contacts the impact releases are returned in ``released`` (count returned). A
    release whose flight would last less than the minimum flight time, or whose peak
    gap is below round-off, is closed instead (the contact is made bilateral and the
    impact solved again): this ends an impact cascade. Shorter steps are asked for
    (``fst[F_H_CAP]``) so that the flights that remain are resolved.
    """
    n, ns, half = sizes(mdl)
    members = np.empty(ns, np.int64)
    members[0] = j
    count = 1
    for k in range(ns):
        if k != j and ph[k] != SEPARATION:
            members[count] = k
            count += 1
    if count == 1:
        single_impact(j, y, mdl, wk)
        return 0
    aux = _aux(mdl, wk)
    for a in range(1, count):
        k = members[a]
        y[half + n + ns + k] = contact_velocity(k, y, mdl, wk)
    y_pre = y.copy()
    forced = np.zeros(count, np.bool_)
    w = np.empty(count)
    old_ph = ph.copy()
    min_flight = mdl.opts[O_MIN_FLIGHT]
    nrel = 0
    for _ in range(count + 1):
        for i in range(y.shape[0]):
            y[i] = y_pre[i]
        contact_impact(members[:count], count, y, mdl, wk, forced, w)
        nrel = 0
        for a in range(count):
            if w[a] > 0.0:
                released[nrel] = members[a]
                nrel += 1
        if nrel == 0:
            break
        # Predict each flight from the gap's velocity and acceleration just after, with
        # the landing slider in contact unless it leaves too.
        for a in range(count):
            k = members[a]
            if w[a] > 0.0:
                ph[k] = SEPARATION
                y[n + ns + k] = aux[A_WC, k]
            elif k == j:
                ph[k] = SLIP
        evaluate(t, y, ph, sg, True, mdl, wk, dy)
        again = False
        for a in range(count):
            if w[a] <= 0.0:
                continue
            k = members[a]
            gdd = mdl.slider[S_SIGMA, k] * (dy[half + n + ns + k]
                                             - _surface_acceleration(k, y, mdl, wk, dy))
            if gdd >= 0.0:
                continue
            flight = 2.0 * w[a] / -gdd
            peak = 0.5 * w[a] * w[a] / -gdd
            # Round-off of z: its size, or the preload's compression of the slider's
            # spring where z itself is small.
            zscale = max(abs(aux[A_WC, k]), abs(mdl.slider[S_N0, k] / mdl.slider[S_KZ, k]))
            if flight < min_flight or peak < 8.0 * 2.220446049250313e-16 * zscale:
                forced[a] = True
                again = True
            else:
                fst[F_H_CAP] = min(fst[F_H_CAP], flight)
        for a in range(count):
            ph[members[a]] = old_ph[members[a]]
        if not again:
            break
        nrel = 0
    return nrel


@njit(cache=True)
def apply_switch(e, t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist, fst):
    """Carry the state across the switch triggered by event ``e`` (slider e // 3)."""
    aux = _aux(mdl, wk)
    n, ns, half = sizes(mdl)
    j = e // 3
    which = e % 3
    if ph[j] == SEPARATION:
        # Re-contact: g, g' at the landing state for the impact map, then the phases.
        evaluate(t, y, ph, sg, True, mdl, wk, dy)
        released = np.empty(ns, np.int64)
        nrel = 0
        if mdl.opts[O_IMPACT] != 0.0:
            nrel = _impact(j, t, y, ph, sg, mdl, wk, dy, fst, released)
        else:
            # Velocities are kept; the slider takes the disc's normal velocity.
            zd_old = y[half + n + ns + j]
            zd_new = contact_velocity(j, y, mdl, wk)
            y[half + n + ns + j] = zd_new
            e0 = n_dynamic(mdl)
            if y.shape[0] > e0:
                y[e0 + E_IMPACT] += 0.5 * mdl.slider[S_MASS, j] * (zd_new * zd_new
                                                                   - zd_old * zd_old)
        # Contacts the impact released fly from where they are.
        before = ph.copy()
        landing_leaves = False
        for a in range(nrel):
            k = released[a]
            landing_leaves = landing_leaves or k == j
            ph[k] = SEPARATION
            y[n + ns + k] = aux[A_WC, k]
        _record(t, EV_RECONTACT, SEPARATION, SLIP, j, ev_t, ev_i, ist)
        first = ist[I_EVENTS] - 1
        if landing_leaves:
            _record(t, EV_SEPARATION, SLIP, SEPARATION, j, ev_t, ev_i, ist)
        else:
            choose_phase(j, t, y, ph, sg, mdl, wk, dy)
            if ph[j] == SEPARATION:
                _record(t, EV_SEPARATION, SLIP, SEPARATION, j, ev_t, ev_i, ist)
            elif first >= 0:
                ev_i[first, EVI_TO] = ph[j]
        for a in range(nrel):
            k = released[a]
            if k != j:
                _record(t, EV_SEPARATION, before[k], SEPARATION, k, ev_t, ev_i, ist)
        settle(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist)
        return
    is_normal_force_event = (ph[j] == SLIP and which == 1) or (ph[j] == STICK and which == 2)
    if is_normal_force_event:
        evaluate(t, y, ph, sg, True, mdl, wk, dy)
        old = ph[j]
        if old == STICK:
            om, _ = speed_at(t, mdl.speed, True)
            y[half + n + j] = om
        _separate(j, y, ph, mdl, wk)
        _record(t, EV_SEPARATION, old, SEPARATION, j, ev_t, ev_i, ist)
        settle(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist)
        return
    # Relative velocity reached zero (slip) or the static limit was reached (stick):
    # the slider moves with the disc at this instant; decide from the forces.
    om, _ = speed_at(t, mdl.speed, True)
    y[half + n + j] = om
    old = ph[j]
    old_s = sg[j]
    choose_phase(j, t, y, ph, sg, mdl, wk, dy)
    _record_change(t, old, old_s, ph[j], sg[j], j, ev_t, ev_i, ist)
    settle(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist)


@njit(cache=True)
def _simultaneous(first, t, y, ph, sg, ph_start, ev_start, mdl, wk, dy, k, ev_prev, ev_t, ev_i,
                  ist, fst):
    """Switches of other sliders whose events crossed zero at the same instant as event
    ``first`` (identical sliders, say), taken one after the other in slider order; without
    this they would be seen only at the end of the next step."""
    n_sl = ph.shape[0]
    handled = np.zeros(n_sl, np.bool_)
    handled[first // 3] = True
    for _ in range(n_sl):
        nxt = -1
        for i in range(ev_prev.shape[0]):
            j = i // 3
            if (not handled[j] and ph[j] == ph_start[j] and ev_start[i] > 0.0
                    and ev_prev[i] <= 0.0):
                nxt = i
                break
        if nxt < 0:
            return
        handled[nxt // 3] = True
        apply_switch(nxt, t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist, fst)
        _restart(t, y, ph, sg, mdl, wk, k, ev_prev)
        ist[I_RHS] += 1


@njit(cache=True)
def _event_at(theta, i, t, h, rc, ph, sg, mdl, wk, dy, ytmp, evt, ist):
    ist[I_EVAL_EVENTS] += 1
    dense_eval(rc, theta, ytmp)
    evaluate(t + theta * h, ytmp, ph, sg, False, mdl, wk, dy)
    event_values(ph, sg, ytmp, mdl, wk, evt)
    return evt[i]


@njit(cache=True)
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


@njit(cache=True)
def _write_outputs(t0, t1, h, rc, ph, sg, mdl, wk, dy, ytmp, ctl, out_y, out_aux, ist):
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
        _write_sample(i, ti, ytmp, ph, sg, mdl, wk, dy, out_y, out_aux)
        i += 1
    ist[I_OUT_NEXT] = i


@njit(cache=True)
def _write_sample(i, ti, ys, ph, sg, mdl, wk, dy, out_y, out_aux):
    """One output row: the state with the contact kinematics filled in, and per slider
    N, f, phase, w under it (columns j, S + j, 2 S + j, 3 S + j), then Omega."""
    aux = _aux(mdl, wk)
    n, ns, half = sizes(mdl)
    evaluate(ti, ys, ph, sg, False, mdl, wk, dy)
    om, _ = speed_at(ti, mdl.speed, False)
    for j in range(ns):
        if ph[j] == STICK:
            ys[half + n + j] = om
        if ph[j] != SEPARATION:
            ys[n + ns + j] = aux[A_WC, j]
            ys[half + n + ns + j] = aux[A_WCD, j]
        out_aux[i, j] = aux[A_N, j]
        out_aux[i, ns + j] = aux[A_F, j]
        out_aux[i, 2 * ns + j] = ph[j]
        out_aux[i, 3 * ns + j] = aux[A_WC, j]
    for c in range(ys.shape[0]):
        out_y[i, c] = ys[c]
    out_aux[i, 4 * ns] = om


@njit(cache=True)
def _rms_scaled(a, y0, y1, atol, rtol, m):
    """RMS of ``a[:m]`` scaled by ``atol + rtol max(|y0|, |y1|)``."""
    acc = 0.0
    for i in range(m):
        sc = atol + rtol * max(abs(y0[i]), abs(y1[i]))
        acc += (a[i] / sc) ** 2
    return np.sqrt(acc / m)


@njit(cache=True)
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
    evaluate(t + h0, ytmp, ph, sg, False, mdl, wk, dy)
    for i in range(y.shape[0]):
        dy[i] = (dy[i] - f0[i]) / h0
    d2 = _rms_scaled(dy, y, y, atol, rtol, m)
    if max(d1, d2) <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** 0.2
    return min(100.0 * h0, h1)


@njit(cache=True)
def _restart(t, y, ph, sg, mdl, wk, k, ev_prev):
    evaluate(t, y, ph, sg, True, mdl, wk, k[0])
    event_values(ph, sg, y, mdl, wk, ev_prev)


@njit(cache=True)
def start(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist):
    """Phases at the start: each slider in contact takes the phase its state allows, in
    slider order; one whose contact would need N < 0 starts separated (recorded)."""
    ns = ph.shape[0]
    for j in range(ns):
        if ph[j] != SEPARATION:
            choose_phase(j, t, y, ph, sg, mdl, wk, dy)
            if ph[j] == SEPARATION:
                _record(t, EV_SEPARATION, SLIP, SEPARATION, j, ev_t, ev_i, ist)
    settle(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist)


# What _switch does.
MODE_START = 0
MODE_EVENT = 1
MODE_KINK = 2


@njit(cache=True)
def _switch(mode, e, t, y, ph, sg, ph_start, ev_start, mdl, wk, dy, k, ev_prev, ev_t, ev_i,
            ist, fst):
    """Every change of phase, in one function: the start (``MODE_START``), the switch of
    event ``e`` with the switches at the same instant (``MODE_EVENT``; ``ph_start`` and
    ``ev_start`` are the phases and event values at the start of the step), or a kink of
    the speed profile (``MODE_KINK``). The right-hand side is compiled into this one
    function only, not into each helper."""
    n, n_sl, half = sizes(mdl)
    if mode == MODE_START:
        start(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist)
        return
    if mode == MODE_EVENT:
        apply_switch(e, t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist, fst)
        if n_sl > 1:
            _restart(t, y, ph, sg, mdl, wk, k, ev_prev)
            ist[I_RHS] += 1
            _simultaneous(e, t, y, ph, sg, ph_start, ev_start, mdl, wk, dy, k, ev_prev,
                          ev_t, ev_i, ist, fst)
        return
    # Speed-profile kink: Omegadot jumps, so the stick reaction does too.
    om, _ = speed_at(t, mdl.speed, True)
    for j in range(n_sl):
        if ph[j] == SEPARATION:
            continue
        old = ph[j]
        old_s = sg[j]
        if old == STICK:
            y[half + n + j] = om
        choose_phase(j, t, y, ph, sg, mdl, wk, dy)
        _record_change(t, old, old_s, ph[j], sg[j], j, ev_t, ev_i, ist)
    settle(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist)


@njit(cache=True)
def run(t_target, mdl, ctl, fst, ist, y, ph, sg, k, ev_prev, breaks, out_y, out_aux, ev_t,
        ev_i):
    """Advance the integration until ``t >= t_target``, the end, a failure, or a nearly
    full event buffer. All arrays are updated in place (``ph``/``sg``: every slider's
    phase and slip sign); returns the status."""
    ns = y.shape[0]
    nd = n_dynamic(mdl)
    n_ev = ev_prev.shape[0]
    wk = new_work(mdl, y)
    n_sl = sizes(mdl)[1]
    ynew = np.empty(ns)
    ytmp = np.empty(ns)
    yout = np.empty(ns)
    dy = np.empty(ns)
    rc = np.empty((5, ns))
    evn = np.empty(n_ev)
    evt = np.empty(n_ev)
    err_vec = np.empty(ns)
    rtol = ctl[C_RTOL]
    atol = ctl[C_ATOL]
    max_step = ctl[C_MAX_STEP]
    t_final = ctl[C_T_FINAL]
    cap = ev_t.shape[0]

    t = fst[F_T]
    h = fst[F_H]
    if ist[I_STARTED] == 0:
        _switch(MODE_START, -1, t, y, ph, sg, ph, ev_prev, mdl, wk, dy, k, ev_prev, ev_t, ev_i,
                ist, fst)
        _restart(t, y, ph, sg, mdl, wk, k, ev_prev)
        if h <= 0.0:
            h = _initial_step(t, y, k[0], ph, sg, mdl, wk, ctl, ytmp, dy, nd)
        if ist[I_OUT_NEXT] == 0 and out_y.shape[0] > 0:
            for i in range(ns):
                yout[i] = y[i]
            _write_sample(0, t, yout, ph, sg, mdl, wk, dy, out_y, out_aux)
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
        if t >= t_target or ist[I_EVENTS] > cap - 4 * n_sl - 4:
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
            for i in range(ns):
                ytmp[i] = y[i]
            for j in range(st):
                a = hs * A[st, j]
                if a != 0.0:
                    for i in range(ns):
                        ytmp[i] += a * k[j, i]
            evaluate(t + C[st] * hs, ytmp, ph, sg, False, mdl, wk, k[st])
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
        # The last stage is at the step's end: its evaluation left the event data there.
        event_values(ph, sg, ynew, mdl, wk, evn)

        have_rc = False
        which = -1
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
                    gp = _event_at(tp, i, t, hs, rc, ph, sg, mdl, wk, dy, ytmp, evt, ist)
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
            _write_outputs(t, t_e, hs, rc, ph, sg, mdl, wk, dy, yout, ctl, out_y, out_aux, ist)
            dense_eval(rc, theta, y)
            first_new = ist[I_EVENTS]
            fst[F_H_CAP] = np.inf
            ph_start = ph.copy()
            ev_start = ev_prev.copy()
            _switch(MODE_EVENT, which, t_e, y, ph, sg, ph_start, ev_start, mdl, wk, dy, k,
                    ev_prev, ev_t, ev_i, ist, fst)
            t = t_e
            _restart(t, y, ph, sg, mdl, wk, k, ev_prev)
            ist[I_RHS] += 1
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
            _write_outputs(t, t_new, hs, rc, ph, sg, mdl, wk, dy, yout, ctl, out_y, out_aux,
                           ist)
        for i in range(ns):
            y[i] = ynew[i]
        for i in range(ns):
            k[0, i] = k[6, i]
        for i in range(n_ev):
            ev_prev[i] = evn[i]
        t = t_new
        h = hs * fac
        if land and t < t_final:
            _switch(MODE_KINK, -1, t, y, ph, sg, ph, ev_prev, mdl, wk, dy, k, ev_prev, ev_t,
                    ev_i, ist, fst)
            _restart(t, y, ph, sg, mdl, wk, k, ev_prev)
            ist[I_RHS] += 1

    fst[F_T] = t
    fst[F_H] = h
    ist[I_STATUS] = status
    return status
