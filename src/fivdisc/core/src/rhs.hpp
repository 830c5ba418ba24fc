// Equations of motion of S sliders on the spinning disc (docs/model.md), one source for
// the real right-hand side and its complex step: every function is a template on the
// scalar T (double or Cx), every decision is taken on real parts, so a complex state
// x + i eps v follows the real branches and carries J v in its imaginary part.
//
// The accelerations solve a linear system at every evaluation: the disc's is diagonal
// (modal masses) plus one row and column per slider in contact (its normal force). The
// normal forces are eliminated first: a system of one equation per slider (the
// capacitance matrix of the Woodbury identity; a flying slider's row is the identity),
// then the disc's accelerations follow in O(n S). One slider has it in closed form, two
// in registers; the arithmetic of each path is the same operations in the same order as
// the general one where they overlap.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "layout.hpp"
#include "model.hpp"
#include "scalar.hpp"

namespace fivdisc {

// Per-slider results of an evaluation (one value per slider).
template <class T>
struct SliderAux {
    std::vector<T> N;      // normal force [N]
    std::vector<T> F;      // friction force on the slider, positive along +phi [N]
    std::vector<T> wc;     // the disc's w under it [m]
    std::vector<T> wcd;    // its rate following the slider [m/s]
    std::vector<T> v;      // relative speed Omega - phidot [rad/s]
    std::vector<T> gpq;    // g'.q
    std::vector<T> gpqd;   // g'.qdot
    std::vector<T> l2gq;   // sum l^2 g q
    std::vector<T> sggp;   // g M^-1 g'
    std::vector<T> phid;   // phidot (Omega in stick)
    std::vector<T> smu;    // s mu in slip
    std::vector<T> fphi;   // in-plane spring and damper force
    std::vector<T> known;  // the part of N that does not depend on the accelerations
    std::vector<T> den;    // one slider in contact: the divisor of its N in closed form
    void resize(int S) {
        for (auto* a : {&N, &F, &wc, &wcd, &v, &gpq, &gpqd, &l2gq, &sggp, &phid, &smu, &fphi,
                        &known, &den})
            a->assign(S, T(0.0));
    }
};

// What an evaluation leaves behind: the mode shapes at every slider, the disc forces,
// the per-slider results, and the scratch of the normal forces' system.
template <class T>
struct Work {
    int n = 0, S = 0, lw = 0;
    std::vector<T> g, gp;      // (S, n): g and g' at each slider
    std::vector<T> fq;         // (n): disc forces before the contacts
    std::vector<T> trc, trs;   // (S, lmax + 2): cos(l psi_j), sin(l psi_j)
    SliderAux<T> aux;
    T om = T(0.0), omd = T(0.0);  // Omega and dOmega/dt at the evaluation
    std::vector<T> sys;        // (S, S + 1): the normal forces' system, right-hand side last
    std::vector<T> u;          // (n, S): each contact's force on the disc per unit N, times M^-1
    Work() = default;
    explicit Work(const Model& m) { init(m); }
    void init(const Model& m) {
        n = m.n;
        S = m.S;
        lw = m.lmax + 2;
        g.assign(static_cast<size_t>(S) * n, T(0.0));
        gp.assign(static_cast<size_t>(S) * n, T(0.0));
        fq.assign(n, T(0.0));
        trc.assign(static_cast<size_t>(S) * lw, T(0.0));
        trs.assign(static_cast<size_t>(S) * lw, T(0.0));
        aux.resize(S);
        sys.assign(static_cast<size_t>(S) * (S + 1), T(0.0));
        u.assign(static_cast<size_t>(n) * S, T(0.0));
    }
    T& G(int j, int i) { return g[static_cast<size_t>(j) * n + i]; }
    T& GP(int j, int i) { return gp[static_cast<size_t>(j) * n + i]; }
    const T& G(int j, int i) const { return g[static_cast<size_t>(j) * n + i]; }
    const T& GP(int j, int i) const { return gp[static_cast<size_t>(j) * n + i]; }
};

// Index of the piece holding x: the last start below x (at or below it when right);
// 0 before the first. A bisection on the starts.
inline int piece(const Pieces& p, double x, bool right) {
    if (p.count <= 1) return 0;  // one piece (a ramp, a one-piece table): no search
    int lo = 0, hi = p.count;
    while (lo < hi) {
        const int mid = (lo + hi) / 2;
        const double start = p.start(mid);
        if (start < x || (right && start == x))
            lo = mid + 1;
        else
            hi = mid;
    }
    return std::max(lo - 1, 0);
}

// Disc speed Omega and its rate at t from the piecewise-cubic profile; at a knot, right
// takes the right limit (a step's start), else the left (inside or at a step's end). A
// complex t gives the time derivatives in the imaginary part.
template <class TT>
inline void speed_at(const Pieces& sp, TT t, bool right, TT& om, TT& omd) {
    if (sp.flat) {
        // A constant speed, at every evaluation: what the cubic below gives at a finite
        // t, c0 and +0 exactly, without its arithmetic.
        om = TT(sp.c(0, 0));
        omd = TT(0.0);
        return;
    }
    const int k = piece(sp, re(t), right);
    const TT tau = t - sp.start(k);
    const double c0 = sp.c(k, 0), c1 = sp.c(k, 1), c2 = sp.c(k, 2), c3 = sp.c(k, 3);
    om = c0 + tau * (c1 + tau * (c2 + tau * c3));
    omd = c1 + tau * (2.0 * c2 + 3.0 * tau * c3);
}

// Kinetic friction coefficient at relative speed v [rad/s] in slip with sign s; the
// sliding speed is u = r s v [m/s]. Inside a step that crosses v = 0 it may be slightly
// negative, where each law is continued smoothly: the exponential law analytically, the
// Stribeck exponent oddly, the table linearly.
template <class T>
inline T kinetic_friction(const Friction& fr, double r, int s, T v) {
    if (fr.law == LAW_EXPONENTIAL)
        return fr.mu1 + (fr.mu0 - fr.mu1) * exp(-fr.alpha * r * static_cast<double>(s) * v);
    const T u = r * static_cast<double>(s) * v;
    if (fr.law == LAW_STRIBECK) {
        const T x = u / fr.vs;
        T e;
        if (re(x) >= 0.0)
            e = pow(x, fr.delta);
        else
            e = -pow(-x, fr.delta);
        return fr.mu1 + (fr.mu0 - fr.mu1) * exp(-e) + fr.muv * u;
    }
    const Pieces& tb = fr.table;
    if (re(u) < tb.start(0)) return tb.c(0, 0) + tb.c(0, 1) * u;
    const int k = piece(tb, re(u), true);
    const T tau = u - tb.start(k);
    return tb.c(k, 0) + tau * (tb.c(k, 1) + tau * (tb.c(k, 2) + tau * tb.c(k, 3)));
}

// The rate of s mu at relative speed v [rad/s] as phidot changes at dphid (v at
// -dphid): the complex step of the friction law alone.
inline double law_rate(const Friction& fr, double r, int s, double v, double dphid) {
    const double h = 1e-30;
    const Cx k = kinetic_friction<Cx>(fr, r, s, Cx(v, -h * dphid));
    return static_cast<double>(s) * k.im / h;
}

// Force on modal coordinate i from its stiffness, the spin and the damping at state x
// (om2 = om^2): linear in x, so for a tangent vector x it is the force's derivative.
template <class T, class TT>
inline T disc_force(const Disc& d, int i, const T* x, TT om, TT om2, TT omd, double eps,
                    bool damped, int half) {
    const int p = d.partner[i];
    T f = -(d.kd[i] - d.ml2[i] * om2) * x[i];
    if (p >= 0) f -= d.gyr[i] * (2.0 * om * x[half + p] + eps * omd * x[p] * d.omd_fix[i]);
    if (damped) {
        f -= d.cdamp[i] * x[half + i];
        if (p >= 0) f -= d.cdamp_om[i] * om * x[p];
    }
    return f;
}

template <class T>
inline void one_slider(const Model& M, int n, int half, int phj, T known, T smu, T fphi, T f,
                       T gpq, T s_gf, T s_gg, T s_ggp, T phi, T omd, T zero, Work<T>& wk, T* dy);
template <class T>
inline void contacts(const Model& M, int n, int ns, int half, const T* y, const int* ph, T omd,
                     T zero, Work<T>& wk, T* dy);
template <class T, class TT>
inline void powers(const Model& M, const T* y, int ylen, const int* ph, TT om, TT omd,
                   const Work<T>& wk, T* dy);

// Time derivative dy of the state y (ylen values: the dynamic state, with or without the
// energy accumulators), slider j in phase ph[j] with slip sign sg[j]. Fills wk. right
// picks the right limit of the speed at a knot. The time may be real while the state is
// complex (TT = double), which keeps the speed's arithmetic real.
template <class T, class TT>
void evaluate(const Model& M, TT t, const T* y, int ylen, const int* ph, const int* sg,
              bool right, Work<T>& wk, T* dy) {
    const Disc& disc = M.disc;
    const Sliders& sl = M.sl;
    const int n = M.n, ns = M.S, half = n + 2 * ns;
    TT om, omd;
    speed_at(M.speed, t, right, om, omd);
    wk.om = om;
    wk.omd = omd;
    const T zero = y[n] * 0.0;

    // Disc forces that do not depend on the contacts: stiffness, spin, damping.
    const double eps = M.omdot;
    const bool damped = M.damped;
    const TT om2 = om * om;
    for (int i = 0; i < n; ++i) {
        wk.fq[i] = disc_force(disc, i, y, om, om2, omd, eps, damped, half);
        dy[i] = y[half + i];
    }

    const int lmax = M.lmax;
    const int lw = wk.lw;
    SliderAux<T>& aux = wk.aux;
    // The last slider's values stay in these locals: with one slider they give its normal
    // force in closed form below.
    T known = zero, smu = zero, fphi = zero, f = zero;
    T gpq = zero, s_gf = zero, s_gg = zero, s_ggp = zero;
    int phj = SLIP;
    for (int j = 0; j < ns; ++j) {
        phj = ph[j];
        const int sj = sg[j];
        const T phi = y[n + j];
        T phid = y[half + n + j];
        if (phj == STICK) phid = phid * 0.0 + om;
        // cos(l psi), sin(l psi) by the Chebyshev recurrence: two trig calls per slider.
        const T psi = sl.theta[j] + phi;
        const T c1 = cos(psi);
        const T s1 = sin(psi);
        T* rc = &wk.trc[static_cast<size_t>(j) * lw];
        T* rs = &wk.trs[static_cast<size_t>(j) * lw];
        rc[0] = 1.0 + zero;
        rs[0] = zero;
        if (lmax >= 1) {
            rc[1] = c1;
            rs[1] = s1;
        }
        // The last two terms kept in registers: the chain waits on arithmetic, not on
        // reloading what it just stored.
        const T two_c1 = 2.0 * c1;
        T c_prev = rc[0], c_cur = c1, s_prev = rs[0], s_cur = s1;
        for (int k = 1; k < lmax; ++k) {
            const T c_next = two_c1 * c_cur - c_prev;
            const T s_next = two_c1 * s_cur - s_prev;
            rc[k + 1] = c_next;
            rs[k + 1] = s_next;
            c_prev = c_cur;
            c_cur = c_next;
            s_prev = s_cur;
            s_cur = s_next;
        }
        T wc = zero, wcd = zero, l2gq = zero, gpqd = zero;
        gpq = zero;
        s_gf = zero;
        s_gg = zero;
        s_ggp = zero;
        T* gj = &wk.g[static_cast<size_t>(j) * n];
        T* gpj = &wk.gp[static_cast<size_t>(j) * n];
        const double* shj = &M.shape[static_cast<size_t>(j) * n];
        for (int i = 0; i < n; ++i) {
            const int li = disc.li[i];
            const double minv = disc.minv[i];
            // Branch-free g = R cos(l psi) (C: cs = 1, sn = 0) or R sin(l psi) (D).
            const double cs = disc.cs[i];
            const double sn = disc.sn[i];
            const T gi = shj[i] * (cs * rc[li] + sn * rs[li]);
            const T gpi = disc.l[i] * shj[i] * (sn * rc[li] - cs * rs[li]);
            gj[i] = gi;
            gpj[i] = gpi;
            const T qi = y[i];
            const T qdi = y[half + i];
            wc += gi * qi;
            wcd += gi * qdi;
            gpq += gpi * qi;
            gpqd += gpi * qdi;
            l2gq += disc.l2[i] * gi * qi;
            if (ns == 1) {
                s_gf += gi * wk.fq[i] * minv;
                s_gg += gi * gi * minv;
                s_ggp += gi * gpi * minv;
            }
        }
        wcd += phid * gpq;
        aux.wc[j] = wc;
        aux.wcd[j] = wcd;
        aux.v[j] = om - phid;
        aux.gpq[j] = gpq;
        aux.gpqd[j] = gpqd;
        aux.l2gq[j] = l2gq;
        aux.phid[j] = phid;
        aux.N[j] = zero;
        aux.F[j] = zero;
        dy[n + j] = phid;
        if (phj == SEPARATION) {
            const T zj = y[n + ns + j];
            const T zdj = y[half + n + ns + j];
            dy[half + n + j] = (-sl.cphi[j] * phid - sl.kphi[j] * phi) / sl.inertia[j];
            dy[n + ns + j] = zdj;
            dy[half + n + ns + j] = (-sl.sn0[j] - sl.cz[j] * zdj - sl.kz[j] * zj) / sl.mass[j];
            continue;
        }
        dy[n + ns + j] = zero;
        dy[half + n + ns + j] = zero;
        // The part of N that does not depend on the unknown accelerations.
        known = sl.n0[j] + sl.smass[j] * (2.0 * phid * gpqd - phid * phid * l2gq)
                + sl.scz[j] * wcd + sl.skz[j] * wc;
        if (phj == SLIP) {
            smu = static_cast<double>(sj) * kinetic_friction<T>(M.fr, sl.radius[j], sj, om - phid);
            fphi = -sl.cphi[j] * phid - sl.kphi[j] * phi;
            aux.smu[j] = smu;
        } else {
            // Stick: phi'' = Omegadot, friction is the reaction of the in-plane oscillator.
            f = (sl.inertia[j] * omd + sl.cphi[j] * om + sl.kphi[j] * phi) / sl.radius[j];
            aux.F[j] = f;
        }
        // For the tangent-linear right-hand side, which needs it with one slider.
        aux.sggp[j] = s_ggp;
        if (ns > 1) {
            aux.known[j] = known;
            aux.fphi[j] = fphi;
        }
    }

    if (ns == 1)
        one_slider<T>(M, n, half, phj, known, smu, fphi, f, gpq, s_gf, s_gg, s_ggp, y[n],
                      T(omd), zero, wk, dy);
    else
        contacts<T>(M, n, ns, half, y, ph, T(omd), zero, wk, dy);

    if (ylen > 2 * half) powers<T, TT>(M, y, ylen, ph, om, omd, wk, dy);
}

// Normal force and accelerations with a single slider: the one equation of contacts()
// in closed form, with the slider's values passed in registers.
template <class T>
inline void one_slider(const Model& M, int n, int half, int phj, T known, T smu, T fphi, T f,
                       T gpq, T s_gf, T s_gg, T s_ggp, T phi, T omd, T zero, Work<T>& wk, T* dy) {
    const Disc& disc = M.disc;
    const Sliders& sl = M.sl;
    if (phj == SEPARATION) {
        for (int i = 0; i < n; ++i) dy[half + i] = wk.fq[i] * disc.minv[i];
        return;
    }
    const double m = sl.mass[0];
    const double sm = sl.smass[0];
    const double inertia = sl.inertia[0];
    T den, nf;
    const T* g0 = wk.g.data();
    const T* gp0 = wk.gp.data();
    if (phj == SLIP) {
        den = (1.0 + m * (s_gg - sl.hh[0] * smu * s_ggp)
               - sm * gpq * sl.radius[0] * smu / inertia);
        nf = (known + sm * (s_gf + zero) + sm * gpq * fphi / inertia) / den;
        const T sn = sl.sigma[0] * nf;
        const T c = sl.hh[0] * smu;
        for (int i = 0; i < n; ++i)
            dy[half + i] = (wk.fq[i] - sn * (g0[i] - c * gp0[i])) * disc.minv[i];
        f = smu * nf;
        dy[half + n] = (fphi + sl.radius[0] * f) / inertia;
    } else {
        den = 1.0 + m * s_gg;
        nf = (known + sm * (s_gf + sl.shh[0] * f * s_ggp + zero) + sm * gpq * omd) / den;
        const T sn = sl.sigma[0] * nf;
        const T c = sl.shh[0] * f;
        for (int i = 0; i < n; ++i)
            dy[half + i] = (wk.fq[i] + c * gp0[i] - sn * g0[i]) * disc.minv[i];
        dy[half + n] = omd + phi * 0.0;
    }
    wk.aux.N[0] = nf;
    wk.aux.F[0] = f;
    // For the tangent-linear right-hand side, which divides by it too.
    wk.aux.den[0] = den;
}

// Solve the m x m system in rows r0 .. r0 + m of a (row stride lda: the matrix in
// columns 0 .. m, the right-hand side in column m) in place, the solution left in column
// m, by Gaussian elimination with partial pivoting on the real parts.
template <class T>
inline void solve_small(T* a, int lda, int r0, int m) {
    auto A = [&](int r, int c) -> T& { return a[static_cast<size_t>(r0 + r) * lda + c]; };
    for (int c = 0; c < m; ++c) {
        int piv = c;
        double best = std::fabs(re(A(c, c)));
        for (int r = c + 1; r < m; ++r) {
            if (std::fabs(re(A(r, c))) > best) {
                best = std::fabs(re(A(r, c)));
                piv = r;
            }
        }
        if (piv != c)
            for (int k = 0; k < m + 1; ++k) std::swap(A(c, k), A(piv, k));
        if (c + 1 < m) {
            const T inv = 1.0 / A(c, c);
            for (int r = c + 1; r < m; ++r) {
                const T fac = A(r, c) * inv;
                // Column c of the rows below is not read again.
                for (int k = c + 1; k < m + 1; ++k) A(r, k) -= fac * A(c, k);
            }
        }
    }
    for (int c = m - 1; c >= 0; --c) {
        T acc = A(c, m);
        for (int k = c + 1; k < m; ++k) acc -= A(c, k) * A(k, m);
        A(c, m) = acc / A(c, c);
    }
}

// Normal forces and accelerations of several sliders.
//
// Slider k in contact pushes the disc with -sigma_k N_k u_k, where u_k = g_k -
// h_k / (2 r_k) s_k mu_k g'_k in slip and g_k in stick, plus in stick the known moment of
// its friction reaction, sigma_k h_k / (2 r_k) f_k g'_k. With F the disc forces known
// before the contacts, q'' = M^-1 (F - sum_k sigma_k N_k u_k). Each contact's condition
// (its N from the accelerations) is one row of an S x S system in the N_k.
template <class T>
inline void contacts(const Model& M, int n, int ns, int half, const T* y, const int* ph, T omd,
                     T zero, Work<T>& wk, T* dy) {
    const Disc& disc = M.disc;
    const Sliders& sl = M.sl;
    SliderAux<T>& aux = wk.aux;
    for (int i = 0; i < n; ++i) dy[half + i] = wk.fq[i];
    for (int k = 0; k < ns; ++k) {
        if (ph[k] == STICK) {
            const T moment = sl.shh[k] * aux.F[k];
            const T* gpk = &wk.gp[static_cast<size_t>(k) * n];
            for (int i = 0; i < n; ++i) dy[half + i] += moment * gpk[i];
        }
    }
    if (ns == 2 && ph[0] != SEPARATION && ph[1] != SEPARATION) {
        // Two sliders in contact: the general path's operations below in the same order,
        // every sum taken in one pass over the modal coordinates, the 2 x 2 system solved
        // in registers.
        const T c0 = ph[0] == SLIP ? sl.hh[0] * aux.smu[0] : zero;
        const T c1 = ph[1] == SLIP ? sl.hh[1] * aux.smu[1] : zero;
        const double sig0 = sl.sigma[0], sig1 = sl.sigma[1];
        const T* gg0 = &wk.g[0];
        const T* gg1 = &wk.g[static_cast<size_t>(n)];
        const T* gq0 = &wk.gp[0];
        const T* gq1 = &wk.gp[static_cast<size_t>(n)];
        T gf0 = zero, gf1 = zero, a00 = zero, a01 = zero, a10 = zero, a11 = zero;
        for (int i = 0; i < n; ++i) {
            const double minv = disc.minv[i];
            const T g0 = gg0[i];
            const T g1 = gg1[i];
            const T u0 = sig0 * (g0 - c0 * gq0[i]) * minv;
            const T u1 = sig1 * (g1 - c1 * gq1[i]) * minv;
            const T fi = dy[half + i];
            gf0 += g0 * minv * fi;
            gf1 += g1 * minv * fi;
            a00 += g0 * u0;
            a01 += g0 * u1;
            a10 += g1 * u0;
            a11 += g1 * u1;
        }
        const double sm0 = sl.smass[0], sm1 = sl.smass[1];
        T d0 = a00 * sm0 + 1.0;
        T d1 = a11 * sm1 + 1.0;
        const T e0 = a01 * sm0;
        const T e1 = a10 * sm1;
        const T gpq0 = aux.gpq[0];
        const T gpq1 = aux.gpq[1];
        T b0, b1;
        if (ph[0] == SLIP) {
            d0 -= sm0 * gpq0 * sl.radius[0] * aux.smu[0] / sl.inertia[0];
            b0 = aux.known[0] + sm0 * gf0 + sm0 * gpq0 * aux.fphi[0] / sl.inertia[0];
        } else {
            b0 = aux.known[0] + sm0 * gf0 + sm0 * gpq0 * omd;
        }
        if (ph[1] == SLIP) {
            d1 -= sm1 * gpq1 * sl.radius[1] * aux.smu[1] / sl.inertia[1];
            b1 = aux.known[1] + sm1 * gf1 + sm1 * gpq1 * aux.fphi[1] / sl.inertia[1];
        } else {
            b1 = aux.known[1] + sm1 * gf1 + sm1 * gpq1 * omd;
        }
        // solve_small's elimination for m = 2 written out.
        T p00, p01, q0, p10, p11, q1;
        if (std::fabs(re(e1)) > std::fabs(re(d0))) {
            p00 = e1; p01 = d1; q0 = b1; p10 = d0; p11 = e0; q1 = b0;
        } else {
            p00 = d0; p01 = e0; q0 = b0; p10 = e1; p11 = d1; q1 = b1;
        }
        const T fac = p10 * (1.0 / p00);
        p11 -= fac * p01;
        q1 -= fac * q0;
        const T n1 = q1 / p11;
        const T n0 = (q0 - p01 * n1) / p00;
        aux.N[0] = n0;
        aux.N[1] = n1;
        for (int i = 0; i < n; ++i) {
            const double minv = disc.minv[i];
            T acc = dy[half + i] * minv;
            acc -= n0 * (sig0 * (gg0[i] - c0 * gq0[i]) * minv);
            acc -= n1 * (sig1 * (gg1[i] - c1 * gq1[i]) * minv);
            dy[half + i] = acc;
        }
    } else {
        T* U = wk.u.data();  // (n, ns)
        for (int k = 0; k < ns; ++k) {
            if (ph[k] == SEPARATION) {
                for (int i = 0; i < n; ++i) U[static_cast<size_t>(i) * ns + k] = zero;
                continue;
            }
            T c = zero;
            if (ph[k] == SLIP) c = sl.hh[k] * aux.smu[k];
            const double sigma = sl.sigma[k];
            const T* gk = &wk.g[static_cast<size_t>(k) * n];
            const T* gpk = &wk.gp[static_cast<size_t>(k) * n];
            for (int i = 0; i < n; ++i)
                U[static_cast<size_t>(i) * ns + k] = sigma * (gk[i] - c * gpk[i]) * disc.minv[i];
        }
        const int lda = ns + 1;
        T* sys = wk.sys.data();
        for (int j = 0; j < ns; ++j) {
            T* row = sys + static_cast<size_t>(j) * lda;
            if (ph[j] == SEPARATION) {
                for (int k = 0; k < ns; ++k) row[k] = zero;
                row[j] = 1.0 + zero;
                row[ns] = zero;
                continue;
            }
            const T* gj = &wk.g[static_cast<size_t>(j) * n];
            T gf = zero;
            for (int i = 0; i < n; ++i) gf += gj[i] * disc.minv[i] * dy[half + i];
            const double sm = sl.smass[j];
            // The entries summed in locals, four at a time (each entry's sum is the same,
            // in the same order); the rest one at a time.
            int k = 0;
            while (k + 3 < ns) {
                T a0 = zero, a1 = zero, a2 = zero, a3 = zero;
                for (int i = 0; i < n; ++i) {
                    const T gji = gj[i];
                    const T* ui = U + static_cast<size_t>(i) * ns + k;
                    a0 += gji * ui[0];
                    a1 += gji * ui[1];
                    a2 += gji * ui[2];
                    a3 += gji * ui[3];
                }
                row[k] = a0 * sm;
                row[k + 1] = a1 * sm;
                row[k + 2] = a2 * sm;
                row[k + 3] = a3 * sm;
                k += 4;
            }
            while (k < ns) {
                T a0 = zero;
                for (int i = 0; i < n; ++i) a0 += gj[i] * U[static_cast<size_t>(i) * ns + k];
                row[k] = a0 * sm;
                k += 1;
            }
            const T gpqj = aux.gpq[j];
            row[j] += 1.0;
            if (ph[j] == SLIP) {
                const T smu = aux.smu[j];
                row[j] -= sm * gpqj * sl.radius[j] * smu / sl.inertia[j];
                row[ns] = aux.known[j] + sm * gf + sm * gpqj * aux.fphi[j] / sl.inertia[j];
            } else {
                row[ns] = aux.known[j] + sm * gf + sm * gpqj * omd;
            }
        }
        solve_small<T>(sys, lda, 0, ns);
        for (int k = 0; k < ns; ++k)
            if (ph[k] != SEPARATION) aux.N[k] = sys[static_cast<size_t>(k) * lda + ns];
        // A flying slider's normal force is 0 (set by evaluate), and so is its column.
        for (int i = 0; i < n; ++i) {
            T acc = dy[half + i] * disc.minv[i];
            const T* ui = U + static_cast<size_t>(i) * ns;
            for (int k = 0; k < ns; ++k) acc -= aux.N[k] * ui[k];
            dy[half + i] = acc;
        }
    }
    // The sliders' own accelerations, from their normal forces (either path).
    for (int k = 0; k < ns; ++k) {
        if (ph[k] == SEPARATION) continue;
        const T nf = aux.N[k];
        if (ph[k] == SLIP) {
            aux.F[k] = aux.smu[k] * nf;
            dy[half + n + k] = (aux.fphi[k] + sl.radius[k] * aux.F[k]) / sl.inertia[k];
        } else {
            dy[half + n + k] = omd + y[n + k] * 0.0;
        }
    }
}

// Rates of the energy accumulators [W].
template <class T, class TT>
inline void powers(const Model& M, const T* y, int ylen, const int* ph, TT om, TT omd,
                   const Work<T>& wk, T* dy) {
    const Disc& disc = M.disc;
    const Sliders& sl = M.sl;
    const int n = M.n, ns = M.S, half = n + 2 * ns;
    const int e0 = 2 * half;
    const SliderAux<T>& aux = wk.aux;
    const T zero = y[n] * 0.0;
    T fric = zero, drive = zero, moment = zero, slope = zero, sdamp = zero, ddamp = zero;
    for (int j = 0; j < ns; ++j) {
        const T phid = aux.phid[j];
        const T f = aux.F[j];
        const double r = sl.radius[j];
        fric += f * r * (phid - om);
        drive += f * r * om;
        T gpqd = zero;
        const T* gpj = &wk.gp[static_cast<size_t>(j) * n];
        for (int i = 0; i < n; ++i) gpqd += gpj[i] * y[half + i];
        moment += sl.shh[j] * f * gpqd;
        slope += sl.sigma[j] * aux.N[j] * phid * aux.gpq[j];
        T zd;
        if (ph[j] == SEPARATION)
            zd = y[half + n + ns + j];
        else
            zd = aux.wcd[j];
        sdamp -= sl.cz[j] * zd * zd + sl.cphi[j] * phid * phid;
    }
    const double eps = M.omdot;
    for (int i = 0; i < n; ++i) {
        const int p = disc.partner[i];
        const T qdi = y[half + i];
        drive -= disc.ml2[i] * om * omd * y[i] * y[i];
        if (p >= 0) {
            drive -= qdi * disc.gyr[i] * (2.0 * om * y[half + p] + eps * omd * y[p] * disc.omd_fix[i]);
            ddamp -= qdi * disc.cdamp_om[i] * om * y[p];
        }
        ddamp -= qdi * disc.cdamp[i] * qdi;
    }
    dy[e0 + E_FRICTION] = fric;
    dy[e0 + E_DRIVE] = drive;
    dy[e0 + E_MOMENT] = moment;
    dy[e0 + E_SLOPE] = slope;
    dy[e0 + E_SLIDER_DAMPING] = sdamp;
    dy[e0 + E_DISC_DAMPING] = ddamp;
    for (int c = E_DISC_DAMPING + 1; c < ylen - e0; ++c) dy[e0 + c] = zero;
}

// Event functions of every slider's phase, positive while it holds (3 per slider, unused
// slots +inf). Needs wk filled by evaluate at y.
template <class T>
inline void event_values(const Model& M, const int* ph, const int* sg, const T* y,
                         const Work<T>& wk, T* out) {
    const int n = M.n, ns = M.S;
    const double mus = M.fr.mus;
    const double inf = std::numeric_limits<double>::infinity();
    const SliderAux<T>& aux = wk.aux;
    for (int j = 0; j < ns; ++j) {
        const int o = 3 * j;
        out[o] = inf;
        out[o + 1] = inf;
        out[o + 2] = inf;
        const T nf = aux.N[j];
        if (ph[j] == SLIP) {
            out[o] = static_cast<double>(sg[j]) * aux.v[j];
            out[o + 1] = nf;
        } else if (ph[j] == STICK) {
            const T f = aux.F[j];
            out[o] = mus * nf - f;
            out[o + 1] = mus * nf + f;
            out[o + 2] = nf;
        } else {
            out[o] = M.sl.sigma[j] * (y[n + ns + j] - aux.wc[j]);
        }
    }
}

}  // namespace fivdisc
