// Re-contact: the perfectly plastic impact on every active contact (Moreau's law).
//
// Velocities u = (qdot, zdot_1 .. zdot_S) with mass matrix W = diag(M, m_1 .. m_S) jump
// by W^-1 sum_i lambda_i a_i where contact i's gap velocity is
// gammadot_i = a_i.u - b_i = sigma_i (zdot_i - g_i.qdot - phidot_i g'_i.q) and the
// compressive impulses solve the linear complementarity problem
//     lambda >= 0,  gammadot+ = gammadot- + D lambda >= 0,  lambda.gammadot+ = 0,
//     D = A W^-1 A^T  (symmetric positive definite).
// A contact that would need a tensile impulse is released. A single contact has the
// closed form of the paper's Eqs. 54-56. Positions and phidot never jump. The maps take
// real or complex states (decisions on real parts), so their Jacobians come from the
// complex step.
#pragma once

#include <cmath>
#include <vector>

#include "layout.hpp"
#include "rhs.hpp"

namespace fivdisc {

// Normal velocity of the disc's surface under slider j [m/s]; wk must hold the mode
// shapes at y.
template <class T>
inline T contact_velocity(const Model& M, int j, const T* y, const Work<T>& wk) {
    const int n = M.n, ns = M.S, half = n + 2 * ns;
    const T phid = y[half + n + j];
    T acc = 0.0;
    for (int i = 0; i < n; ++i) acc += wk.G(j, i) * y[half + i] + phid * wk.GP(j, i) * y[i];
    return acc;
}

// Kinetic energy of the disc modes and of the normal motion of members [J].
template <class T>
inline T kinetic(const Model& M, const T* y, const int* members, int count) {
    const int n = M.n, ns = M.S, half = n + 2 * ns;
    T acc = 0.0;
    for (int i = 0; i < n; ++i) acc += 0.5 * y[half + i] * y[half + i] / M.disc.minv[i];
    for (int a = 0; a < count; ++a) {
        const int j = members[a];
        const T zd = y[half + n + ns + j];
        acc += 0.5 * M.sl.mass[j] * zd * zd;
    }
    return acc;
}

// Add the impact's kinetic energy loss and the surface's work to the accumulators:
// the loss is 1/2 |du|_W^2, the rest of the change is lambda.b.
template <class T>
inline void book(const Model& M, T* y, int ylen, T before, const T* u_minus, const int* members,
                 int count) {
    const int n = M.n, ns = M.S, half = n + 2 * ns;
    const int e0 = 2 * half;
    if (ylen <= e0) return;
    T loss = 0.0;
    for (int i = 0; i < n; ++i) {
        const T du = y[half + i] - u_minus[half + i];
        loss += 0.5 * du * du / M.disc.minv[i];
    }
    for (int a = 0; a < count; ++a) {
        const int j = members[a];
        const T du = y[half + n + ns + j] - u_minus[half + n + ns + j];
        loss += 0.5 * M.sl.mass[j] * du * du;
    }
    const T change = kinetic(M, y, members, count) - before;
    y[e0 + E_IMPACT] -= loss;
    y[e0 + E_SURFACE] += change + loss;
}

// Plastic impact of slider j alone (paper Eqs. 47-56): slider and disc leave with one
// normal velocity. wk must hold the mode shapes at y.
template <class T>
inline void single_impact(const Model& M, int j, T* y, int ylen, const Work<T>& wk) {
    const int n = M.n, ns = M.S, half = n + 2 * ns;
    const double* minv = M.disc.minv.data();
    const int members[1] = {j};
    const std::vector<T> u_minus(y, y + ylen);
    const T before = kinetic(M, y, members, 1);
    const double m = M.sl.mass[j];
    const T zd_minus = y[half + n + ns + j];
    const T phid = y[half + n + j];
    T ratio = 0.0;
    T disc = 0.0;
    for (int i = 0; i < n; ++i) {
        ratio += m * wk.G(j, i) * wk.G(j, i) * minv[i];
        disc += wk.G(j, i) * y[half + i] + phid * wk.GP(j, i) * y[i];
    }
    const T zd_plus = (disc + ratio * zd_minus) / (1.0 + ratio);
    for (int i = 0; i < n; ++i) y[half + i] -= m * wk.G(j, i) * minv[i] * (zd_plus - zd_minus);
    y[half + n + ns + j] = zd_plus;
    book(M, y, ylen, before, u_minus.data(), members, 1);
}

// x[act] = solution of a[act, act] x = b[act]; x = 0 elsewhere (a is m x m).
template <class T>
inline void solve_active(const std::vector<T>& a, const std::vector<T>& b, std::vector<T>& x,
                         const std::vector<char>& act, int m) {
    std::vector<int> idx;
    for (int i = 0; i < m; ++i) {
        x[i] = 0.0;
        if (act[i]) idx.push_back(i);
    }
    const int k = static_cast<int>(idx.size());
    if (k == 0) return;
    std::vector<T> sub(static_cast<size_t>(k) * (k + 1));
    for (int r = 0; r < k; ++r) {
        sub[static_cast<size_t>(r) * (k + 1) + k] = b[idx[r]];
        for (int c = 0; c < k; ++c)
            sub[static_cast<size_t>(r) * (k + 1) + c] = a[static_cast<size_t>(idx[r]) * m + idx[c]];
    }
    solve_small<T>(sub.data(), k + 1, 0, k);
    for (int r = 0; r < k; ++r) x[idx[r]] = sub[static_cast<size_t>(r) * (k + 1) + k];
}

// Solve lam >= 0, w = gam + D lam >= 0, lam.w = 0 exactly (Murty's least-index principal
// pivoting, finite for a positive definite D). forced[i] makes contact i bilateral
// (w_i = 0, any sign of lam_i). Returns w; lam is filled.
template <class T>
inline std::vector<T> solve_lcp(const std::vector<T>& dmat, const std::vector<T>& gam,
                                const std::vector<char>& forced, std::vector<T>& lam, int m) {
    std::vector<char> act(m, 1);
    std::vector<T> w(m), neg(m);
    double scale = 0.0;
    for (int i = 0; i < m; ++i) scale = pmax(scale, std::fabs(re(gam[i])));
    const double tol_w = 1e-13 * scale;
    const long long tries = 4 * (1LL << (m < 40 ? m : 40)) + 4;
    for (long long it = 0; it < tries; ++it) {
        for (int i = 0; i < m; ++i) neg[i] = -gam[i];
        solve_active(dmat, neg, lam, act, m);
        double lam_scale = 0.0;
        for (int i = 0; i < m; ++i) lam_scale = pmax(lam_scale, std::fabs(re(lam[i])));
        const double tol_l = 1e-13 * lam_scale;
        int flip = -1;
        for (int i = 0; i < m; ++i) {
            T acc = gam[i];
            for (int k = 0; k < m; ++k) acc += dmat[static_cast<size_t>(i) * m + k] * lam[k];
            w[i] = acc;
        }
        for (int i = 0; i < m; ++i) {
            if (act[i] && !forced[i] && re(lam[i]) < -tol_l) {
                flip = i;
                break;
            }
            if (!act[i] && re(w[i]) < -tol_w) {
                flip = i;
                break;
            }
        }
        if (flip < 0) {
            for (int i = 0; i < m; ++i)
                if (act[i]) w[i] = 0.0;
            return w;
        }
        act[flip] = !act[flip];
    }
    return w;
}

// Plastic impact on the contacts members[:count] (the landing slider and those in
// contact), by the complementarity problem. wk must hold the mode shapes at y, and the
// contacts' zdot their contact velocities. forced marks contacts that must stay closed.
// On return w_out[a] is the gap velocity of member a after the impact (> 0: it leaves).
template <class T>
inline void contact_impact(const Model& M, const int* members, int count, T* y, int ylen,
                           const Work<T>& wk, const std::vector<char>& forced, std::vector<T>& w_out) {
    const int n = M.n, ns = M.S, half = n + 2 * ns;
    const double* minv = M.disc.minv.data();
    const double* sigma = M.sl.sigma.data();
    const double* mass = M.sl.mass.data();
    const std::vector<T> u_minus(y, y + ylen);
    const T before = kinetic(M, y, members, count);
    std::vector<T> dmat(static_cast<size_t>(count) * count, T(0.0));
    std::vector<T> gam(count), lam(count);
    for (int a = 0; a < count; ++a) {
        const int ja = members[a];
        for (int b = 0; b < count; ++b) {
            const int jb = members[b];
            T acc = 0.0;
            for (int i = 0; i < n; ++i) acc += wk.G(ja, i) * wk.G(jb, i) * minv[i];
            if (ja == jb) acc += 1.0 / mass[ja];
            dmat[static_cast<size_t>(a) * count + b] = sigma[ja] * sigma[jb] * acc;
        }
        gam[a] = sigma[ja] * (y[half + n + ns + ja] - contact_velocity(M, ja, y, wk));
    }
    const std::vector<T> w = solve_lcp(dmat, gam, forced, lam, count);
    for (int a = 0; a < count; ++a) {
        const int ja = members[a];
        const T sl = lam[a] * sigma[ja];
        for (int i = 0; i < n; ++i) y[half + i] -= sl * wk.G(ja, i) * minv[i];
        y[half + n + ns + ja] += sl / mass[ja];
        w_out[a] = w[a];
    }
    book(M, y, ylen, before, u_minus.data(), members, count);
}

}  // namespace fivdisc
