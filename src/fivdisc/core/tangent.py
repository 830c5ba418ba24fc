"""Tangent (variational) dynamics of the non-smooth flow, carried across every switch.

Tangent vectors ``v`` (rows of ``V``, over the dynamic state without the energy
accumulators) follow ``dv/dt = J(t, y) v`` inside each phase, integrated by the same
Dormand-Prince stages as the state, so a step maps them by the exact derivative of the
step the state takes; the step size is controlled by the state alone, and a run with
tangents takes exactly the steps of a run without. ``J v`` is exact to rounding: for one
slider the tangent-linear right-hand side (``dynamics.linearised_one``, which reuses what
the state's evaluation computed), for several the complex step of the right-hand side.

At a switch at time ``t_s`` where event function ``h`` of the old phase crosses zero,
with the old field ``f-`` and, after the jump map ``x+ = G(x-, t)``, the new field
``f+``, a tangent vector ``v`` becomes (Mueller 1995; Leine and Nijmeijer 2004)

    dtau = -(grad h . v) / (grad h . f- + dh/dt)
    v+ = DG (v + f- dtau) + G_t dtau - f+ dtau

which is ``S v`` with the saltation matrix ``S``. ``DG w + G_t dtau`` is computed by
running the switch itself (:mod:`fivdisc.core.switch`) on the complex state
``x- + i eps w`` at the complex time ``t_s + i eps dtau``: the same branches as the real
switch, its imaginary part the derivative of every state change the switch makes (the
stick speed ``phidot = Omega(t)``, a separating slider's start from the disc's surface,
the impact map). A kink of the speed profile is a switch in time alone (dtau = 0).

Coordinates that are not free in the current phases are slaved and their tangent rows
are kept at zero: ``z_j``, ``zdot_j`` of a slider in contact, ``phidot_j`` of a sticking
one. A direction the flow collapses (onto the stick manifold, by a plastic impact) so
has zero image, and a monodromy matrix shows it as a zero multiplier.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from fivdisc.core.dopri5 import A, C, dense_coefficients, dense_eval
from fivdisc.core.dynamics import (
    LEFT,
    RIGHT,
    evaluate,
    event_values,
    linearised_one,
    new_work,
)
from fivdisc.core.sizes import n_dynamic, sizes, work_rows
from fivdisc.core.slots import N_EVI, N_FSTATE, N_ISTATE
from fivdisc.core.switch import MODE_EVENT, _switch
from fivdisc.model.layout import (
    A_WC,
    A_WCD,
    SEPARATION,
    STICK,
)

# Imaginary part of the complex step, for a direction of unit max-norm: far below the
# state's scale so the second-order term is below rounding, far above underflow.
_STEP = 1e-30


@njit(cache=True)
def scratch(mdl, y, n_vectors):
    """Work arrays of the tangent integration: (the complex step's state, derivative and
    work array), complex stages and event values, the tangents at a step's end, a stage's
    tangent, dense-output coefficients, two vectors, a real work array, the state and
    slip signs before a switch (slots 9 and 10), the state's stage states and work
    arrays (slots 11 and 12), which the state's stages fill for :func:`step`, and what
    the switch on the complex state records and changes in :func:`saltation` (slot 13:
    event times and rows, counters, floats, phases and signs).

    The per-step functions (:func:`step`, ``accept``, ...) never allocate and run
    without reference counting; the saltation allocates nothing of its own."""
    nd = n_dynamic(mdl)
    n_sl = sizes(mdl)[1]
    n_ev = 3 * n_sl
    yc = np.empty(nd, np.complex128)
    cplx = (yc, np.empty(nd, np.complex128), new_work(mdl, yc))
    wk = new_work(mdl, y)
    n_rec = 8 * n_sl + 8
    rec = (np.empty(n_rec), np.empty((n_rec, N_EVI), np.int64), np.empty(N_ISTATE, np.int64),
           np.empty(N_FSTATE), np.empty(n_sl, np.int64), np.empty(n_sl, np.int64))
    return (cplx, np.empty((7, nd), np.complex128), np.empty(n_ev, np.complex128),
            np.empty((n_vectors, nd)), np.empty(nd), np.empty((5, nd)), np.empty(nd),
            np.empty(nd), wk, np.empty(nd), np.empty(n_sl, np.int64),
            np.empty((7, y.shape[0])), np.zeros((7, wk.shape[0], wk.shape[1])), rec)


@njit(cache=True, _nrt=False)
def _norm_inf(v):
    acc = 0.0
    for i in range(v.shape[0]):
        acc = max(acc, abs(v[i]))
    return acc


@njit(cache=True, inline="always")
def jvp(t, y, v, ph, sg, right, mdl, wk, cplx, out):
    """``out = J(t, y) v``: the derivative of the right-hand side of phases ``ph`` along
    ``v``, exact to rounding. ``wk`` must hold what ``evaluate`` left at ``(t, y)``: one
    slider takes the tangent-linear right-hand side (about the cost of one evaluation),
    several the complex step of ``evaluate`` (a complex evaluation)."""
    if sizes(mdl)[1] == 1:
        linearised_one(y, v, ph, sg, mdl, wk, out)
        return
    yc, dyc, wkc = cplx
    nd = out.shape[0]
    scale = _norm_inf(v)
    if scale == 0.0:
        for i in range(nd):
            out[i] = 0.0
        return
    h = _STEP / scale
    for i in range(nd):
        yc[i] = complex(y[i], h * v[i])
    evaluate(t, yc, ph, sg, right, mdl, wkc, dyc)
    for i in range(nd):
        out[i] = dyc[i].imag / h


@njit(cache=True, _nrt=False)
def step(t, hs, ph, sg, mdl, ys, wks, V, KV, vn, vs, cplx):
    """Stages 1-6 of every tangent vector over the accepted step ``[t, t + hs]``, at the
    state's stage states ``ys`` with what its evaluations left in ``wks`` (the state's
    stages evaluate into them, ``integrate._stages``); the last stage's combination, the
    tangent at the step's end, is kept in ``vn``.

    A function of its own, called once per accepted step: inlined into the state's
    stages, right after each evaluation, it made their machine code so large that a step
    with one vector cost more, not less (``benchmarks/bench_tangent.py`` measures it)."""
    nd = V.shape[1]
    for r in range(V.shape[0]):
        for st in range(1, 7):
            for i in range(nd):
                vs[i] = V[r, i]
            for j in range(st):
                a = hs * A[st, j]
                if a != 0.0:
                    for i in range(nd):
                        vs[i] += a * KV[r, j, i]
            jvp(t + C[st] * hs, ys[st], vs, ph, sg, LEFT, mdl, wks[st], cplx, KV[r, st])
        for i in range(nd):
            vn[r, i] = vs[i]


@njit(cache=True, _nrt=False)
def accept(V, KV, vn):
    """The step is taken: tangents move to its end ``vn``, the last stage is the next
    first."""
    for r in range(V.shape[0]):
        for i in range(V.shape[1]):
            V[r, i] = vn[r, i]
            KV[r, 0, i] = KV[r, 6, i]


@njit(cache=True, _nrt=False)
def interpolate(theta, hs, V, KV, sc):
    """Tangents at fraction ``theta`` of the step (the state's dense output formula)."""
    vn, rc = sc[3], sc[5]
    for r in range(V.shape[0]):
        dense_coefficients(V[r], vn[r], KV[r], hs, rc)
        dense_eval(rc, theta, V[r])


# Element by element: a slice assignment (``ypre[:] = y[:nd]``) compiles numba's
# shape-mismatch error with its message formatting into the kernel, a few seconds of the
# kernel's first compilation for a check that cannot fail here.
@njit(cache=True, inline="always")
def before_switch(y, sg, sc):
    """Keep the dynamic state and the slip signs before a switch in scratch slots 9 and
    10, for :func:`saltation`."""
    ypre, sgpre = sc[9], sc[10]
    for i in range(ypre.shape[0]):
        ypre[i] = y[i]
    for j in range(sgpre.shape[0]):
        sgpre[j] = sg[j]


@njit(cache=True, _nrt=False)
def slave(ph, mdl, v):
    """Zero the rows of coordinates that are not free in phases ``ph``."""
    n, ns, half = sizes(mdl)
    for j in range(ns):
        if ph[j] != SEPARATION:
            v[n + ns + j] = 0.0
            v[half + n + ns + j] = 0.0
            if ph[j] == STICK:
                v[half + n + j] = 0.0


@njit(cache=True)
def prepare(t, y, ph, sg, mdl, V, KV):
    """Make tangents ``V`` given at a state between steps ready for ``run``: slaved rows
    zeroed, first stages evaluated."""
    sc = scratch(mdl, y, V.shape[0])
    wk = sc[8]
    evaluate(t, y, ph, sg, RIGHT, mdl, wk, np.empty_like(y))
    for r in range(V.shape[0]):
        slave(ph, mdl, V[r])
        jvp(t, y, V[r], ph, sg, RIGHT, mdl, wk, sc[0], KV[r, 0])


@njit(cache=True, _nrt=False)
def _event_rate(e, t, y, ph, sg, mdl, sc, v, dt):
    """Derivative of event function ``e`` along ``(v, dt)`` in (state, time)."""
    yc, dyc, wkc = sc[0]
    evc = sc[2]
    nd = v.shape[0]
    scale = max(_norm_inf(v), abs(dt), 1.0)
    h = _STEP / scale
    for i in range(nd):
        yc[i] = complex(y[i], h * v[i])
    tc = complex(t, h * dt)
    evaluate(tc, yc, ph, sg, LEFT, mdl, wkc, dyc)
    event_values(ph, sg, yc, mdl, wkc, evc)
    return evc[e].imag / h


@njit(cache=True)
def saltation(mode, e, t, ypre, ph_pre, sg_pre, ev_start, y, ph, sg, fplus, wk, mdl, V, KV,
              sc):
    """Map the tangents across the switch that took the state from ``ypre`` (phases
    ``ph_pre``, signs ``sg_pre``) to ``y`` (phases ``ph``) at time ``t``: event ``e`` for
    ``mode`` ``MODE_EVENT``, else a switch at a fixed time (a kink). ``fplus`` is the
    new phases' right-hand side at ``y``, and ``wk`` what its evaluation left (the
    restart's, ``switch._restart``). ``ev_start`` are the event values at the start of
    the step, as the switch had them."""
    yc, dyc, wkc = sc[0]
    kc, evc = sc[1], sc[2]
    fm, w, wkr = sc[6], sc[7], sc[8]
    ev_t, ev_i, ist, fst, phs, sgs = sc[13]
    nd = V.shape[1]
    n_sl = ph.shape[0]
    for i in range(fst.shape[0]):
        fst[i] = np.inf
    hdot = 1.0
    if mode == MODE_EVENT:
        evaluate(t, ypre, ph_pre, sg_pre, LEFT, mdl, wkr, fm)
        hdot = _event_rate(e, t, ypre, ph_pre, sg_pre, mdl, sc, fm, 1.0)
    else:
        for i in range(nd):
            fm[i] = 0.0
    for r in range(V.shape[0]):
        dtau = 0.0
        if mode == MODE_EVENT:
            dtau = -_event_rate(e, t, ypre, ph_pre, sg_pre, mdl, sc, V[r], 0.0) / hdot
        for i in range(nd):
            w[i] = V[r, i] + fm[i] * dtau
        scale = max(_norm_inf(w), abs(dtau), 1.0)
        h = _STEP / scale
        for i in range(nd):
            yc[i] = complex(ypre[i], h * w[i])
        for j in range(n_sl):
            phs[j] = ph_pre[j]
            sgs[j] = sg_pre[j]
        for i in range(ist.shape[0]):
            ist[i] = 0
        _switch(mode, e, complex(t, h * dtau), yc, phs, sgs, ph_pre, ev_start, mdl, wkc, dyc,
                kc, evc, ev_t, ev_i, ist, fst)
        for i in range(nd):
            V[r, i] = yc[i].imag / h - fplus[i] * dtau
        slave(ph, mdl, V[r])
    # The first stages from the new phases' right-hand side at the new state.
    for r in range(V.shape[0]):
        jvp(t, y, V[r], ph, sg, RIGHT, mdl, wk, sc[0], KV[r, 0])


# One vector's scratch; not a literal (see the package docstring).
_ONE_VECTOR = np.int64(1)


@njit(cache=True)
def unslaved(t, y, ph, sg, mdl, V):
    """Tangents with the slaved rows filled in: ``z_j``, ``zdot_j`` of a slider in
    contact follow the disc's surface under it (the values a run's output carries),
    ``phidot_j`` of a sticking one is Omega(t), fixed at fixed t."""
    n, ns, half = sizes(mdl)
    nd = V.shape[1]
    out = V.copy()
    sc = scratch(mdl, y, _ONE_VECTOR)
    yc, dyc, wkc = sc[0]
    aux = work_rows(ns)[3]
    for r in range(V.shape[0]):
        scale = max(_norm_inf(V[r]), 1.0)
        h = _STEP / scale
        for i in range(nd):
            yc[i] = complex(y[i], h * V[r, i])
        evaluate(t, yc, ph, sg, LEFT, mdl, wkc, dyc)
        for j in range(ns):
            if ph[j] != SEPARATION:
                out[r, n + ns + j] = wkc[aux + A_WC, j].imag / h
                out[r, half + n + ns + j] = wkc[aux + A_WCD, j].imag / h
    return out
