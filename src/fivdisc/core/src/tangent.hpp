// Tangent (variational) dynamics of the non-smooth flow, carried across every switch.
//
// Tangent vectors v (rows of V, over the dynamic state without the energy accumulators)
// follow dv/dt = J(t, y) v inside each phase, integrated by the same Dormand-Prince
// stages as the state, so a step maps them by the exact derivative of the step the state
// takes; the step size is controlled by the state alone. J v is exact to rounding: for
// one slider the tangent-linear right-hand side (linearised_one, which reuses what the
// state's evaluation computed), for several the complex step of the right-hand side.
//
// At a switch at time t_s where event function h of the old phase crosses zero, with the
// old field f-, the jump map x+ = G(x-, t) and the new field f+, a tangent vector v
// becomes (Mueller 1995; Leine and Nijmeijer 2004)
//     dtau = -(grad h . v) / (grad h . f- + dh/dt)
//     v+ = DG (v + f- dtau) + G_t dtau - f+ dtau
// which is S v with the saltation matrix S. DG w + G_t dtau comes from running the switch
// itself (switch.hpp) on the complex state x- + i eps w at the complex time
// t_s + i eps dtau. A kink of the speed profile is a switch in time alone (dtau = 0).
//
// Coordinates that are not free in the current phases are slaved and their tangent rows
// kept at zero: z_j, zdot_j of a slider in contact, phidot_j of a sticking one.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "dopri5.hpp"
#include "layout.hpp"
#include "rhs.hpp"
#include "switch.hpp"

namespace fivdisc {

// Imaginary part of the complex step, for a direction of unit max-norm.
inline constexpr double CSTEP = 1e-30;

inline double norm_inf(const double* v, int n) {
    double acc = 0.0;
    for (int i = 0; i < n; ++i) acc = pmax(acc, std::fabs(v[i]));
    return acc;
}

// out = J(t, y) v for a single slider: the tangent-linear form of evaluate (forward-mode
// derivative, operation by operation), using what evaluate left in wk at the same
// (t, y), phases and side of a knot. The mode shapes move with the slider's angle:
// dg = g' dpsi and dg' = -l^2 g dpsi. The friction law's slope is -alpha (mu - mu_1)
// for the exponential law, else the complex step of the law alone. The dynamic state
// only (no energy accumulators).
inline void linearised_one(const Model& M, const double* y, const double* v, const int* ph,
                           const int* sg, const Work<double>& wk, double* out) {
    const Disc& disc = M.disc;
    const Sliders& sl = M.sl;
    const int n = M.n, half = n + 2;
    const SliderAux<double>& aux = wk.aux;
    const double om = wk.om, omd = wk.omd;
    const double eps = M.omdot;
    const bool damped = M.damped;
    const double om2 = om * om;
    const int phj = ph[0];
    const int sj = sg[0];
    const double phi = y[n];
    const double dpsi = v[n];
    const double phid = aux.phid[0];
    const double dphid = phj == STICK ? 0.0 : v[half + n];
    out[n] = dphid;
    // Disc forces are linear in the state: their derivatives are the forces at v.
    if (phj == SEPARATION) {
        for (int i = 0; i < n; ++i) {
            out[half + i] = disc_force(disc, i, v, om, om2, omd, eps, damped, half) * disc.minv[i];
            out[i] = v[half + i];
        }
        out[half + n] = (-sl.cphi[0] * dphid - sl.kphi[0] * dpsi) / sl.inertia[0];
        out[n + 1] = v[half + n + 1];
        out[half + n + 1] = (-sl.cz[0] * v[half + n + 1] - sl.kz[0] * v[n + 1]) / sl.mass[0];
        return;
    }
    out[n + 1] = 0.0;
    out[half + n + 1] = 0.0;
    const double gpq = aux.gpq[0];
    const double gpqd = aux.gpqd[0];
    const double l2gq = aux.l2gq[0];
    double dwc = 0.0, dwcd0 = 0.0, dgpq = 0.0, dgpqd = 0.0, dl2gq = 0.0;
    const double s_ggp = aux.sggp[0];
    double ds_gf = 0.0, ds_ggp = 0.0;
    const double* g = wk.g.data();
    const double* gp = wk.gp.data();
    for (int i = 0; i < n; ++i) {
        // The force's derivative, turned into the acceleration's below.
        const double dfi = disc_force(disc, i, v, om, om2, omd, eps, damped, half);
        out[half + i] = dfi;
        out[i] = v[half + i];
        const double li = disc.l[i];
        const double minv = disc.minv[i];
        const double gi = g[i];
        const double gpi = gp[i];
        const double fi = wk.fq[i];
        const double l2 = li * li;
        dwc += gi * v[i];
        dwcd0 += gi * v[half + i] + gpi * y[half + i] * dpsi;
        dgpq += gpi * v[i];
        dgpqd += gpi * v[half + i] - l2 * gi * y[half + i] * dpsi;
        dl2gq += l2 * (gi * v[i] + gpi * y[i] * dpsi);
        ds_gf += (gpi * dpsi * fi + gi * dfi) * minv;
        ds_ggp += (gpi * gpi - l2 * gi * gi) * minv;
    }
    dwc += gpq * dpsi;
    dgpq -= l2gq * dpsi;
    const double ds_gg = 2.0 * s_ggp * dpsi;
    ds_ggp *= dpsi;
    const double dwcd = dwcd0 + dphid * gpq + phid * dgpq;
    const double sm = sl.smass[0];
    const double m = sl.mass[0];
    const double inertia = sl.inertia[0];
    const double r = sl.radius[0];
    const double dknown = (sm * (2.0 * (dphid * gpqd + phid * dgpqd) - 2.0 * phid * dphid * l2gq
                                 - phid * phid * dl2gq)
                           + sl.scz[0] * dwcd + sl.skz[0] * dwc);
    const double nf = aux.N[0];
    double sn, dsn, a, da;
    if (phj == SLIP) {
        const double smu = aux.smu[0];
        const double vrel = om - phid;
        double dsmu;
        if (M.fr.law == LAW_EXPONENTIAL)
            // mu' = -alpha (mu - mu_1), from mu = s smu itself.
            dsmu = M.fr.alpha * (static_cast<double>(sj) * smu - M.fr.mu1) * r * dphid;
        else
            dsmu = law_rate(M.fr, r, sj, vrel, dphid);
        const double fphi = -sl.cphi[0] * phid - sl.kphi[0] * phi;
        const double dfphi = -sl.cphi[0] * dphid - sl.kphi[0] * dpsi;
        const double hh = sl.hh[0];
        const double den = aux.den[0];
        const double dnum = dknown + sm * ds_gf + sm * (dgpq * fphi + gpq * dfphi) / inertia;
        const double dden = (m * (ds_gg - hh * (dsmu * s_ggp + smu * ds_ggp))
                             - sm * r * (dgpq * smu + gpq * dsmu) / inertia);
        const double dnf = (dnum - nf * dden) / den;
        // The disc's contact force is -sn g + a g' with a = sn h/(2r) s mu in slip.
        sn = sl.sigma[0] * nf;
        dsn = sl.sigma[0] * dnf;
        a = sn * hh * smu;
        da = hh * (dsn * smu + sn * dsmu);
        out[half + n] = (dfphi + r * (dsmu * nf + smu * dnf)) / inertia;
    } else {
        // Stick: a = sigma h/(2r) f with the stick reaction f.
        const double f = aux.F[0];
        const double df = sl.kphi[0] * dpsi / r;
        const double shh = sl.shh[0];
        const double dnf = (dknown + sm * (ds_gf + shh * (df * s_ggp + f * ds_ggp)) + sm * dgpq * omd
                            - nf * m * ds_gg) / aux.den[0];
        sn = sl.sigma[0] * nf;
        dsn = sl.sigma[0] * dnf;
        a = shh * f;
        da = shh * df;
        out[half + n] = 0.0;
    }
    for (int i = 0; i < n; ++i) {
        const double gi = g[i];
        const double gpi = gp[i];
        const double dgi = gpi * dpsi;
        const double dgpi = -disc.l[i] * disc.l[i] * gi * dpsi;
        out[half + i] = (out[half + i] + da * gpi + a * dgpi - dsn * gi - sn * dgi) * disc.minv[i];
    }
}

// The complex-step scratch: a complex state, its derivative and work.
struct ComplexScratch {
    std::vector<Cx> y, dy;
    Work<Cx> wk;
    ComplexScratch() = default;
    ComplexScratch(const Model& m, int nd) : y(nd), dy(nd), wk(m) {}
};

// out = J(t, y) v: the derivative of the right-hand side of phases ph along v, exact to
// rounding. wk must hold what evaluate left at (t, y): one slider takes the
// tangent-linear right-hand side, several the complex step of evaluate.
inline void jvp(const Model& M, double t, const double* y, const double* v, int nd, const int* ph,
                const int* sg, bool right, const Work<double>& wk, ComplexScratch& cx, double* out) {
    if (M.S == 1) {
        linearised_one(M, y, v, ph, sg, wk, out);
        return;
    }
    const double scale = norm_inf(v, nd);
    if (scale == 0.0) {
        for (int i = 0; i < nd; ++i) out[i] = 0.0;
        return;
    }
    const double h = CSTEP / scale;
    for (int i = 0; i < nd; ++i) cx.y[i] = Cx(y[i], h * v[i]);
    evaluate<Cx, double>(M, t, cx.y.data(), nd, ph, sg, right, cx.wk, cx.dy.data());
    for (int i = 0; i < nd; ++i) out[i] = cx.dy[i].im / h;
}

// Zero the rows of coordinates that are not free in phases ph.
inline void slave(const Model& M, const int* ph, double* v) {
    const int n = M.n, ns = M.S, half = n + 2 * ns;
    for (int j = 0; j < ns; ++j) {
        if (ph[j] != SEPARATION) {
            v[n + ns + j] = 0.0;
            v[half + n + ns + j] = 0.0;
            if (ph[j] == STICK) v[half + n + j] = 0.0;
        }
    }
}

// Tangent vectors with their stage derivatives and everything their integration needs.
struct Tangents {
    int k = 0;    // vectors
    int nd = 0;   // dynamic state
    std::vector<double> V;   // (k, nd)
    std::vector<double> KV;  // (k, 7, nd)
    std::vector<double> vn;  // (k, nd): at the step's end
    std::vector<double> vs, rc, fm, w, ypre;
    std::vector<int> sgpre;
    Work<double> wkr;
    ComplexScratch cx;
    std::vector<Cx> kc, evc;  // the complex switch's restart
    EventLog rec_log;         // what the complex switch records (discarded)
    std::vector<int> phs, sgs;
    // The state's stage states and evaluations (the state's stages fill them).
    std::vector<double> tys;  // (7, size)
    std::vector<Work<double>> twk;
    int size = 0;

    Tangents() = default;
    Tangents(const Model& m, int size_, int k_) { init(m, size_, k_); }
    void init(const Model& m, int size_, int k_) {
        k = k_;
        nd = 2 * (m.n + 2 * m.S);
        size = size_;
        V.assign(static_cast<size_t>(k) * nd, 0.0);
        KV.assign(static_cast<size_t>(k) * 7 * nd, 0.0);
        vn.assign(static_cast<size_t>(k) * nd, 0.0);
        vs.assign(nd, 0.0);
        rc.assign(static_cast<size_t>(5) * nd, 0.0);
        fm.assign(nd, 0.0);
        w.assign(nd, 0.0);
        ypre.assign(nd, 0.0);
        sgpre.assign(m.S, 1);
        wkr.init(m);
        cx = ComplexScratch(m, nd);
        kc.assign(static_cast<size_t>(7) * nd, Cx());
        evc.assign(static_cast<size_t>(3) * m.S, Cx());
        phs.assign(m.S, 0);
        sgs.assign(m.S, 1);
        tys.assign(static_cast<size_t>(7) * size, 0.0);
        twk.assign(7, Work<double>(m));
    }
    double* v(int r) { return &V[static_cast<size_t>(r) * nd]; }
    double* kv(int r, int st) { return &KV[(static_cast<size_t>(r) * 7 + st) * nd]; }
    double* ys(int st) { return &tys[static_cast<size_t>(st) * size]; }
};

// Stages 1-6 of every tangent vector over the accepted step [t, t + hs], at the state's
// stage states with what its evaluations left; the tangent at the step's end goes to vn.
inline void tangent_step(const Model& M, double t, double hs, const int* ph, const int* sg, Tangents& T) {
    const int nd = T.nd;
    double* vs = T.vs.data();
    for (int r = 0; r < T.k; ++r) {
        const double* vr = T.v(r);
        for (int st = 1; st < 7; ++st) {
            for (int i = 0; i < nd; ++i) vs[i] = vr[i];
            for (int j = 0; j < st; ++j) {
                const double a = hs * dp5::A[st][j];
                if (a != 0.0) {
                    const double* kj = T.kv(r, j);
                    for (int i = 0; i < nd; ++i) vs[i] += a * kj[i];
                }
            }
            jvp(M, t + dp5::C[st] * hs, T.ys(st), vs, nd, ph, sg, false, T.twk[st], T.cx, T.kv(r, st));
        }
        double* vnr = &T.vn[static_cast<size_t>(r) * nd];
        for (int i = 0; i < nd; ++i) vnr[i] = vs[i];
    }
}

// The step is taken: tangents move to its end, the last stage is the next first.
inline void tangent_accept(Tangents& T) {
    const int nd = T.nd;
    for (int r = 0; r < T.k; ++r) {
        double* vr = T.v(r);
        const double* vnr = &T.vn[static_cast<size_t>(r) * nd];
        double* k0 = T.kv(r, 0);
        const double* k6 = T.kv(r, 6);
        for (int i = 0; i < nd; ++i) {
            vr[i] = vnr[i];
            k0[i] = k6[i];
        }
    }
}

// Tangents at fraction theta of the step (the state's dense output formula).
inline void tangent_interpolate(double theta, double hs, Tangents& T) {
    const int nd = T.nd;
    for (int r = 0; r < T.k; ++r) {
        double* vr = T.v(r);
        dp5::dense_coefficients(vr, &T.vn[static_cast<size_t>(r) * nd], T.kv(r, 0), nd, hs,
                                T.rc.data(), nd);
        dp5::dense_eval(T.rc.data(), nd, theta, vr);
    }
}

// Keep the dynamic state and the slip signs before a switch, for the saltation.
inline void before_switch(const double* y, const int* sg, int S, Tangents& T) {
    for (int i = 0; i < T.nd; ++i) T.ypre[i] = y[i];
    for (int j = 0; j < S; ++j) T.sgpre[j] = sg[j];
}

// Make tangents given at a state between steps ready: slaved rows zeroed, first stages
// evaluated.
inline void tangent_prepare(const Model& M, double t, const double* y, int ylen, const int* ph,
                            const int* sg, Tangents& T) {
    std::vector<double> dy(ylen);
    evaluate<double, double>(M, t, y, ylen, ph, sg, true, T.wkr, dy.data());
    for (int r = 0; r < T.k; ++r) {
        slave(M, ph, T.v(r));
        jvp(M, t, y, T.v(r), T.nd, ph, sg, true, T.wkr, T.cx, T.kv(r, 0));
    }
}

// Derivative of event function e along (v, dt) in (state, time).
inline double event_rate(const Model& M, int e, double t, const double* y, const int* ph, const int* sg,
                         Tangents& T, const double* v, double dt) {
    const int nd = T.nd;
    const double scale = pmax(pmax(norm_inf(v, nd), std::fabs(dt)), 1.0);
    const double h = CSTEP / scale;
    for (int i = 0; i < nd; ++i) T.cx.y[i] = Cx(y[i], h * v[i]);
    const Cx tc(t, h * dt);
    evaluate<Cx, Cx>(M, tc, T.cx.y.data(), nd, ph, sg, false, T.cx.wk, T.cx.dy.data());
    event_values(M, ph, sg, T.cx.y.data(), T.cx.wk, T.evc.data());
    return T.evc[e].im / h;
}

// Map the tangents across the switch that took the state from ypre (phases ph_pre, signs
// sg_pre) to y (phases ph) at time t: event e for MODE_EVENT, else a switch at a fixed
// time. fplus is the new phases' right-hand side at y and wk what its evaluation left.
// ev_start are the event values at the start of the step, as the switch had them.
inline void saltation(const Model& M, int mode, int e, double t, const int* ph_pre, const double* ev_start,
                      const double* y, const int* ph, const int* sg, const double* fplus,
                      const Work<double>& wk, Tangents& T) {
    const int nd = T.nd;
    const int S = M.S;
    double hdot = 1.0;
    double* fm = T.fm.data();
    if (mode == MODE_EVENT) {
        evaluate<double, double>(M, t, T.ypre.data(), nd, ph_pre, T.sgpre.data(), false, T.wkr, fm);
        hdot = event_rate(M, e, t, T.ypre.data(), ph_pre, T.sgpre.data(), T, fm, 1.0);
    } else {
        for (int i = 0; i < nd; ++i) fm[i] = 0.0;
    }
    double h_cap = INFINITY;
    int64_t rhs = 0;
    for (int r = 0; r < T.k; ++r) {
        double* vr = T.v(r);
        double dtau = 0.0;
        if (mode == MODE_EVENT)
            dtau = -event_rate(M, e, t, T.ypre.data(), ph_pre, T.sgpre.data(), T, vr, 0.0) / hdot;
        for (int i = 0; i < nd; ++i) T.w[i] = vr[i] + fm[i] * dtau;
        const double scale = pmax(pmax(norm_inf(T.w.data(), nd), std::fabs(dtau)), 1.0);
        const double h = CSTEP / scale;
        for (int i = 0; i < nd; ++i) T.cx.y[i] = Cx(T.ypre[i], h * T.w[i]);
        for (int j = 0; j < S; ++j) {
            T.phs[j] = ph_pre[j];
            T.sgs[j] = T.sgpre[j];
        }
        T.rec_log.clear();
        h_cap = INFINITY;
        Switcher<Cx> sw{M, Cx(t, h * dtau), T.cx.y.data(), nd, T.phs.data(), T.sgs.data(),
                        T.cx.wk, T.cx.dy.data(), T.rec_log, rhs, h_cap};
        sw.run(mode, e, ph_pre, ev_start, T.kc.data(), T.evc.data());
        for (int i = 0; i < nd; ++i) vr[i] = T.cx.y[i].im / h - fplus[i] * dtau;
        slave(M, ph, vr);
    }
    // The first stages from the new phases' right-hand side at the new state.
    for (int r = 0; r < T.k; ++r)
        jvp(M, t, y, T.v(r), nd, ph, sg, true, wk, T.cx, T.kv(r, 0));
}

// Tangents with the slaved rows filled in: z_j, zdot_j of a slider in contact follow the
// disc's surface under it (as a run's output carries them); phidot_j of a sticking one
// is Omega(t), fixed at fixed t. V is (k, nd); out receives the same shape.
inline void unslaved(const Model& M, double t, const double* y, const int* ph, const int* sg,
                     const double* V, int k, double* out) {
    const int n = M.n, ns = M.S, half = n + 2 * ns, nd = 2 * half;
    ComplexScratch cx(M, nd);
    for (int r = 0; r < k; ++r) {
        const double* vr = V + static_cast<size_t>(r) * nd;
        double* o = out + static_cast<size_t>(r) * nd;
        for (int i = 0; i < nd; ++i) o[i] = vr[i];
        const double scale = pmax(norm_inf(vr, nd), 1.0);
        const double h = CSTEP / scale;
        for (int i = 0; i < nd; ++i) cx.y[i] = Cx(y[i], h * vr[i]);
        evaluate<Cx, double>(M, t, cx.y.data(), nd, ph, sg, false, cx.wk, cx.dy.data());
        for (int j = 0; j < ns; ++j) {
            if (ph[j] != SEPARATION) {
                o[n + ns + j] = cx.wk.aux.wc[j].im / h;
                o[half + n + ns + j] = cx.wk.aux.wcd[j].im / h;
            }
        }
    }
}

}  // namespace fivdisc
