"""Every change of phase: the start, slip/stick/separation switches, re-contact with its
impact, the speed profile's kinks.

The functions take the state in real or complex arithmetic: every decision is taken on
real parts, so a complex call with the real state plus a small imaginary perturbation
follows the same branches and carries, in its imaginary part, the derivative of what the
switch does to the state (the Jacobian of the jump map, used for the saltation matrices
of :mod:`fivdisc.core.tangent`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from fivdisc.core.dynamics import RIGHT, evaluate, event_values, speed_at
from fivdisc.core.impact import contact_impact, contact_velocity, single_impact
from fivdisc.core.sizes import n_dynamic, sizes, work_rows
from fivdisc.core.slots import EVI_FROM, EVI_KIND, EVI_SLIDER, EVI_TO, F_H_CAP, I_EVENTS, I_RHS
from fivdisc.model.layout import (
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
)


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
    om, _ = speed_at(t, mdl.speed, RIGHT)
    v = (om - y[half + n + j]).real
    s = sg[j]
    if v == 0.0:
        ph[j] = STICK
        evaluate(t, y, ph, sg, RIGHT, mdl, wk, dy)
        nf = aux[A_N, j].real
        f = aux[A_F, j].real
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
    evaluate(t, y, ph, sg, RIGHT, mdl, wk, dy)
    if aux[A_N, j].real < 0.0:
        _separate(j, y, ph, mdl, wk)


# Inlined: its callers pass the event kinds and phases as literals, which would otherwise
# compile it once per combination.
@njit(cache=True, inline="always")
def _record(t, kind, frm, to, j, ev_t, ev_i, ist):
    i = ist[I_EVENTS]
    if i < ev_t.shape[0]:
        ev_t[i] = t.real
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


@njit(cache=True, inline="always")
def settle(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist):
    """After a switch, re-check every slider in contact (several sliders only): one that
    would need N < 0 separates, a sticking one beyond the static limit slips; violators
    switch one at a time, lowest index first, until none is left."""
    aux = _aux(mdl, wk)
    n, ns, half = sizes(mdl)
    if ns == 1:
        return
    om, _ = speed_at(t, mdl.speed, RIGHT)
    for _ in range(4 * ns + 4):
        evaluate(t, y, ph, sg, RIGHT, mdl, wk, dy)
        changed = False
        for k in range(ns):
            if ph[k] == SEPARATION:
                continue
            nf = aux[A_N, k].real
            f = aux[A_F, k].real
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


@njit(cache=True, inline="always")
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
    count = np.int64(1)
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
    w = np.empty(count, y.dtype)
    old_ph = ph.copy()
    min_flight = mdl.opts[O_MIN_FLIGHT]
    nrel = 0
    for _ in range(count + 1):
        for i in range(y.shape[0]):
            y[i] = y_pre[i]
        contact_impact(members[:count], count, y, mdl, wk, forced, w)
        nrel = 0
        for a in range(count):
            if w[a].real > 0.0:
                released[nrel] = members[a]
                nrel += 1
        if nrel == 0:
            break
        # Predict each flight from the gap's velocity and acceleration just after, with
        # the landing slider in contact unless it leaves too.
        for a in range(count):
            k = members[a]
            if w[a].real > 0.0:
                ph[k] = SEPARATION
                y[n + ns + k] = aux[A_WC, k]
            elif k == j:
                ph[k] = SLIP
        evaluate(t, y, ph, sg, RIGHT, mdl, wk, dy)
        again = False
        for a in range(count):
            wa = w[a].real
            if wa <= 0.0:
                continue
            k = members[a]
            gdd = mdl.slider[S_SIGMA, k] * (dy[half + n + ns + k]
                                             - _surface_acceleration(k, y, mdl, wk, dy)).real
            if gdd >= 0.0:
                continue
            flight = 2.0 * wa / -gdd
            peak = 0.5 * wa * wa / -gdd
            # Round-off of z: its size, or the preload's compression of the slider's
            # spring where z itself is small.
            zscale = max(abs(aux[A_WC, k].real), abs(mdl.slider[S_N0, k] / mdl.slider[S_KZ, k]))
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


@njit(cache=True, inline="always")
def apply_switch(e, t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist, fst):
    """Carry the state across the switch triggered by event ``e`` (slider e // 3); the
    caller settles the other sliders."""
    aux = _aux(mdl, wk)
    n, ns, half = sizes(mdl)
    j = e // 3
    which = e % 3
    if ph[j] == SEPARATION:
        # Re-contact: g, g' at the landing state for the impact map, then the phases.
        evaluate(t, y, ph, sg, RIGHT, mdl, wk, dy)
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
        return
    is_normal_force_event = (ph[j] == SLIP and which == 1) or (ph[j] == STICK and which == 2)
    if is_normal_force_event:
        evaluate(t, y, ph, sg, RIGHT, mdl, wk, dy)
        old = ph[j]
        if old == STICK:
            om, _ = speed_at(t, mdl.speed, RIGHT)
            y[half + n + j] = om
        _separate(j, y, ph, mdl, wk)
        _record(t, EV_SEPARATION, old, SEPARATION, j, ev_t, ev_i, ist)
        return
    # Relative velocity reached zero (slip) or the static limit was reached (stick):
    # the slider moves with the disc at this instant; decide from the forces.
    om, _ = speed_at(t, mdl.speed, RIGHT)
    y[half + n + j] = om
    old = ph[j]
    old_s = sg[j]
    choose_phase(j, t, y, ph, sg, mdl, wk, dy)
    _record_change(t, old, old_s, ph[j], sg[j], j, ev_t, ev_i, ist)


@njit(cache=True, inline="always")
def _simultaneous(handled, ph, ph_start, ev_start, ev_prev):
    """The first event of a slider not yet handled whose function crossed zero at the
    same instant as the switch just made (identical sliders, say), or ``NO_EVENT``;
    without this it would be seen only at the end of the next step."""
    for i in range(ev_prev.shape[0]):
        j = i // 3
        if (not handled[j] and ph[j] == ph_start[j] and ev_start[i] > 0.0
                and ev_prev[i].real <= 0.0):
            return i
    return NO_EVENT


@njit(cache=True, inline="always")
def _restart(t, y, ph, sg, mdl, wk, k, ev_prev):
    evaluate(t, y, ph, sg, RIGHT, mdl, wk, k[0])
    event_values(ph, sg, y, mdl, wk, ev_prev)


@njit(cache=True, inline="always")
def start(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist):
    """Phases at the start: each slider in contact takes the phase its state allows, in
    slider order; one whose contact would need N < 0 starts separated (recorded).
    The caller settles them."""
    ns = ph.shape[0]
    for j in range(ns):
        if ph[j] != SEPARATION:
            choose_phase(j, t, y, ph, sg, mdl, wk, dy)
            if ph[j] == SEPARATION:
                _record(t, EV_SEPARATION, SLIP, SEPARATION, j, ev_t, ev_i, ist)


# What _switch does, and the event index of a switch no event triggered; numpy scalars,
# not literals (see the package docstring).
MODE_START = np.int64(0)
MODE_EVENT = np.int64(1)
MODE_KINK = np.int64(2)
NO_EVENT = np.int64(-1)


@njit(cache=True)
def _switch(mode, e, t, y, ph, sg, ph_start, ev_start, mdl, wk, dy, k, ev_prev, ev_t, ev_i,
            ist, fst):
    """Every change of phase, in one function: the start (``MODE_START``), the switch of
    event ``e`` with the switches at the same instant (``MODE_EVENT``; ``ph_start`` and
    ``ev_start`` are the phases and event values at the start of the step), or a kink of
    the speed profile (``MODE_KINK``). The right-hand side is compiled into this one
    function only, not into each helper."""
    n_sl = sizes(mdl)[1]
    handled = np.zeros(n_sl, np.bool_)
    # One pass per switch: event e's, then those of other sliders at the same instant, one
    # after the other in slider order. The helpers have one call site each, inlined here.
    while True:
        if mode == MODE_START:
            start(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist)
        elif mode == MODE_EVENT:
            handled[e // 3] = True
            apply_switch(e, t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist, fst)
        else:
            _kink(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist)
        settle(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist)
        if mode != MODE_EVENT or n_sl == 1:
            return
        _restart(t, y, ph, sg, mdl, wk, k, ev_prev)
        ist[I_RHS] += 1
        e = _simultaneous(handled, ph, ph_start, ev_start, ev_prev)
        if e == NO_EVENT:
            return


@njit(cache=True, inline="always")
def _kink(t, y, ph, sg, mdl, wk, dy, ev_t, ev_i, ist):
    """Speed-profile kink: Omegadot jumps, so the stick reaction does too; every slider
    in contact takes the phase its state now allows. The caller settles them."""
    n, n_sl, half = sizes(mdl)
    om, _ = speed_at(t, mdl.speed, RIGHT)
    for j in range(n_sl):
        if ph[j] == SEPARATION:
            continue
        old = ph[j]
        old_s = sg[j]
        if old == STICK:
            y[half + n + j] = om
        choose_phase(j, t, y, ph, sg, mdl, wk, dy)
        _record_change(t, old, old_s, ph[j], sg[j], j, ev_t, ev_i, ist)
