// Event location inside an accepted step: sign changes of the event functions between
// the step's ends, root finding on the dense output, the search for a dip below zero
// that a parabola through three values predicts, and probes at interior points where
// the function is close to zero for its change over the step.
//
// The point on the far side of a root (where the event function is already <= 0) is
// taken, so that the next phase starts in a state consistent with it.
#pragma once

#include <cmath>
#include <limits>
#include <vector>

#include "dopri5.hpp"
#include "layout.hpp"
#include "rhs.hpp"

namespace fivdisc {

// Interior points (+1) at which a near-zero event function is probed within a step.
inline constexpr int PROBES = 4;

// Where the parabola through an event function's values a, b, c at the fractions -r, 0
// and 1 of the step (the previous step's start, this step's ends) has its minimum, if
// inside the step and deep enough that the function may cross zero there although both
// ends are positive: the fraction, else 2.
inline double predicted_dip(double a, double b, double c, double r) {
    if (!(r > 0.0) || !std::isfinite(r)) return 2.0;
    const double gamma = (a - b + (c - b) * r) / (r * (1.0 + r));
    if (!(gamma > 0.0)) return 2.0;
    const double beta = c - b - gamma;
    const double vertex = -beta / (2.0 * gamma);
    if (!(0.0 < vertex && vertex < 1.0)) return 2.0;
    const double low = b - beta * beta / (4.0 * gamma);
    // The parabola is an estimate: the function is searched if its predicted minimum is
    // below the depth of the predicted dip, not only below zero.
    if (low < pmin(b, c) - low) return vertex;
    return 2.0;
}

// The event functions of one step [t, t + h] from its dense output rc.
struct StepEvents {
    const Model& M;
    double t, h;
    const double* rc;  // (5, size)
    int size;
    const int* ph;
    const int* sg;
    Work<double>& wk;
    double* dy;
    double* ytmp;
    double* evt;
    int64_t& eval_events;

    // Whether event i is a function of the state alone: a slipping slider's relative
    // speed. The others need the contact solve of a right-hand side.
    bool kinematic(int i) const { return i % 3 == 0 && ph[i / 3] == SLIP; }

    // Event i at fraction theta of the step. A kinematic event is computed from the
    // dense output of phidot alone, with the operations evaluate and event_values use;
    // any other fills out with every event's value there.
    double at(double theta, int i, double* out) {
        if (kinematic(i)) {
            double om, omd;
            speed_at(M.speed, t + theta * h, false, om, omd);
            const int half = M.n + 2 * M.S;
            return static_cast<double>(sg[i / 3]) * (om - dp5::dense_one(rc, size, theta, half + M.n + i / 3));
        }
        eval_events += 1;
        dp5::dense_eval(rc, size, theta, ytmp);
        evaluate<double, double>(M, t + theta * h, ytmp, size, ph, sg, false, wk, dy);
        event_values(M, ph, sg, ytmp, wk, out);
        return out[i];
    }
    double at(double theta, int i) { return at(theta, i, evt); }

    // Fraction of the step at which event i crosses zero, taken on the far side.
    // Illinois false position on the bracket [lo, hi] with g(lo) > 0 >= g(hi): the kept
    // end's value is halved when the same end survives twice; a bisection steps in if the
    // bracket fails to shrink fourfold in four iterations. Stops when the bracket is below
    // 1e-12 s.
    double locate(int i, double lo, double hi, double g_lo, double g_hi) {
        const double tol = pmax(1e-12 / h, 1e-15);
        int side = 0;
        double width_ref = hi - lo;
        for (int it = 0; it < 200; ++it) {
            const double width = hi - lo;
            if (width <= tol) break;
            double mid;
            if (it % 4 == 3) {
                if (width > 0.25 * width_ref)
                    mid = 0.5 * (lo + hi);
                else
                    mid = lo + width * g_lo / (g_lo - g_hi);
                width_ref = width;
            } else {
                mid = lo + width * g_lo / (g_lo - g_hi);
            }
            // Keep the trial point strictly inside so that the bracket always shrinks.
            mid = pmin(pmax(mid, lo + 0.5 * tol), hi - 0.5 * tol);
            const double gm = at(mid, i);
            if (gm > 0.0) {
                lo = mid;
                g_lo = gm;
                if (side == 1) g_hi *= 0.5;
                side = 1;
            } else {
                hi = mid;
                g_hi = gm;
                if (side == -1) g_lo *= 0.5;
                side = -1;
            }
        }
        return hi;
    }

    // Search the dense output of event i, positive at both ends of the step, for a dip
    // below zero: successive parabolic interpolation on its minimum from vertex. Returns
    // the fraction where it crosses zero (on the far side), or 2 if its minimum inside the
    // step is positive.
    double dip(int i, double vertex, double g0, double g1) {
        double xa = 0.0, xm = vertex, xb = 1.0;
        double ga = g0, gb = g1;
        double gm = at(xm, i);
        for (int it = 0; it < 12; ++it) {
            if (gm <= 0.0) return locate(i, xa, xm, ga, gm);
            if (gm > ga || gm > gb) return 2.0;  // no minimum between the outer points
            const double da = (xm - xa) * (gm - gb);
            const double db = (xm - xb) * (gm - ga);
            const double den = 2.0 * (da - db);
            if (den == 0.0) return 2.0;
            const double x = xm - ((xm - xa) * da - (xm - xb) * db) / den;
            if (!(xa < x && x < xb) || std::fabs(x - xm) < 1e-12 / h) return 2.0;
            const double g = at(x, i);
            if (g <= 0.0) {
                if (x < xm) return locate(i, xa, x, ga, g);
                return locate(i, xm, x, gm, g);
            }
            if (x < xm) {
                if (g < gm) {
                    xb = xm; gb = gm; xm = x; gm = g;
                } else {
                    xa = x; ga = g;
                }
            } else if (g < gm) {
                xa = xm; ga = gm; xm = x; gm = g;
            } else {
                xb = x; gb = g;
            }
        }
        return 2.0;
    }
};

// The first event of an accepted step: compares the event values at the step's start
// (ev_prev), end (evn) and the previous step's start (ev_old, inf where unknown; h_old
// that step's length). dense() fills the dense-output coefficients on first need.
// Returns the event's index (or NO_EVENT) and its fraction of the step in theta.
template <class Dense>
inline int first_event(StepEvents& se, const double* ev_prev, const double* evn, const double* ev_old,
                       double h_old, int n_ev, std::vector<double>& probes, Dense&& dense, double& theta) {
    const double inf = std::numeric_limits<double>::infinity();
    const double hs = se.h;
    int probed = 0;
    int which = -1;
    theta = 2.0;
    for (int i = 0; i < n_ev; ++i) {
        if (evn[i] == inf) continue;
        double th;
        if (ev_prev[i] > 0.0 && evn[i] <= 0.0) {
            dense();
            th = se.locate(i, 0.0, 1.0, ev_prev[i], evn[i]);
        } else if (ev_prev[i] > 0.0 && ev_old[i] < inf && hs > 0.0 &&
                   predicted_dip(ev_old[i], ev_prev[i], evn[i], h_old / hs) <= 1.0) {
            // Positive at both ends, but the parabola through this and the previous step's
            // values dips inside the step: an excursion through zero narrower than the step
            // (a brief slip inside a stick, a grazing), which the ends and the probes can
            // miss. Its minimum is searched for.
            dense();
            th = se.dip(i, predicted_dip(ev_old[i], ev_prev[i], evn[i], h_old / hs), ev_prev[i], evn[i]);
            if (th > 1.0) continue;
        } else if (ev_prev[i] > 0.0 && pmin(ev_prev[i], evn[i]) < 2.0 * std::fabs(evn[i] - ev_prev[i])) {
            // Both ends positive but close to zero for the change over the step: the
            // function may dip below zero and back inside it, so probe the dense output.
            dense();
            th = 2.0;
            double g_lo = ev_prev[i];
            const bool kin = se.kinematic(i);
            for (int p = 1; p < PROBES; ++p) {
                const double tp = static_cast<double>(p) / PROBES;
                double gp;
                double* row = &probes[static_cast<size_t>(p) * n_ev];
                // One right-hand side at a probe serves every event probed there.
                if (kin || ((probed >> p) & 1) == 0) {
                    gp = se.at(tp, i, row);
                    if (!kin) probed |= 1 << p;
                } else {
                    gp = row[i];
                }
                if (gp <= 0.0) {
                    th = se.locate(i, static_cast<double>(p - 1) / PROBES, tp, g_lo, gp);
                    break;
                }
                g_lo = gp;
            }
            if (th > 1.0) continue;
        } else if (ev_prev[i] <= 0.0 && evn[i] < pmin(ev_prev[i], 0.0)) {
            // A phase entered exactly on its boundary is already leaving it.
            th = 1.0;
        } else {
            continue;
        }
        if (th < theta) {
            theta = th;
            which = i;
        }
    }
    return which;
}

}  // namespace fivdisc
