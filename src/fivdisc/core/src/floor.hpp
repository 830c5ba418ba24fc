// The floor of the integrator's cost per step, for the benchmarks (benchmarks/floor.py):
// DOPRI5 with the integrator's PI step control on a linear system y' = J y, J applied as
// a sparse matrix in CSR form plus a low-rank rest U^T (V y); no events, no contact
// solve, no output. Compiled with the core, by the same compiler and flags.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "dopri5.hpp"
#include "scalar.hpp"

namespace fivdisc {

struct LinearOperator {
    const int64_t* indptr;
    const int64_t* indices;
    const double* data;
    const double* u;  // (rank, n)
    const double* v;  // (rank, n)
    int rank;
    int n;
    void apply(const double* y, double* out) const {
        for (int i = 0; i < n; ++i) {
            double acc = 0.0;
            for (int64_t p = indptr[i]; p < indptr[i + 1]; ++p) acc += data[p] * y[indices[p]];
            out[i] = acc;
        }
        for (int r = 0; r < rank; ++r) {
            const double* vr = v + static_cast<size_t>(r) * n;
            const double* ur = u + static_cast<size_t>(r) * n;
            double s = 0.0;
            for (int i = 0; i < n; ++i) s += vr[i] * y[i];
            for (int i = 0; i < n; ++i) out[i] += ur[i] * s;
        }
    }
};

// Accepted steps of DOPRI5 from y (updated in place) over [0, t_final].
inline long floor_dopri_linear(const LinearOperator& op, double* y, double t_final, double rtol,
                               double atol) {
    const int ns = op.n;
    std::vector<double> k(static_cast<size_t>(7) * ns, 0.0), ytmp(ns), err_vec(ns);
    auto K = [&](int st) { return &k[static_cast<size_t>(st) * ns]; };
    op.apply(y, K(0));
    double t = 0.0, h = 1e-6, err_old = 1e-4;
    long steps = 0;
    bool after_reject = false;
    while (t < t_final) {
        const double hs = pmin(h, t_final - t);
        for (int st = 1; st < 7; ++st) {
            for (int i = 0; i < ns; ++i) ytmp[i] = y[i];
            for (int j = 0; j < st; ++j) {
                const double a = hs * dp5::A[st][j];
                if (a != 0.0) {
                    const double* kj = K(j);
                    for (int i = 0; i < ns; ++i) ytmp[i] += a * kj[i];
                }
            }
            op.apply(ytmp.data(), K(st));
        }
        for (int i = 0; i < ns; ++i) err_vec[i] = 0.0;
        for (int st = 0; st < 7; ++st) {
            const double a = hs * dp5::E[st];
            if (a != 0.0) {
                const double* ks = K(st);
                for (int i = 0; i < ns; ++i) err_vec[i] += a * ks[i];
            }
        }
        double acc = 0.0;
        for (int i = 0; i < ns; ++i) {
            const double sc = atol + rtol * pmax(std::fabs(y[i]), std::fabs(ytmp[i]));
            const double r = err_vec[i] / sc;
            acc += r * r;
        }
        const double err = std::sqrt(acc / ns);
        if (err > 1.0) {
            h = hs / pmin(5.0, std::pow(err, dp5::EXPO1) / 0.9);
            after_reject = true;
            continue;
        }
        ++steps;
        const double pi = err > 0.0 ? std::pow(err, dp5::EXPO1) / std::pow(err_old, dp5::BETA) : 0.0;
        double fac = pi > 0.0 ? pmin(5.0, pmax(0.1, 0.9 / pi)) : 5.0;
        err_old = pmax(err, 1e-4);
        if (after_reject) fac = pmin(fac, 1.0);
        after_reject = false;
        for (int i = 0; i < ns; ++i) y[i] = ytmp[i];
        double* k0 = K(0);
        const double* k6 = K(6);
        for (int i = 0; i < ns; ++i) k0[i] = k6[i];
        t += hs;
        h = hs * fac;
        if (!(h > 0.0) || !std::isfinite(t)) break;
    }
    return steps;
}

}  // namespace fivdisc
