// Every change of phase: the start, slip/stick/separation switches, re-contact with its
// impact, the speed profile's kinks.
//
// The switch takes the state in real or complex arithmetic: every decision is taken on
// real parts, so a complex call with the real state plus a small imaginary perturbation
// follows the same branches and carries, in its imaginary part, the derivative of what
// the switch does to the state (the Jacobian of the jump map, used for the saltation
// matrices of tangent.hpp).
#pragma once

#include <cmath>
#include <limits>
#include <vector>

#include "impact.hpp"
#include "layout.hpp"
#include "rhs.hpp"

namespace fivdisc {

enum SwitchMode : int { MODE_START = 0, MODE_EVENT = 1, MODE_KINK = 2 };
inline constexpr int NO_EVENT = -1;

// One switch at time t of the state y (ylen values) with phases ph and slip signs sg,
// recording into log; wk and dy are the evaluation's scratch.
template <class T>
struct Switcher {
    const Model& M;
    T t;
    T* y;
    int ylen;
    int* ph;
    int* sg;
    Work<T>& wk;
    T* dy;
    EventLog& log;
    int64_t& rhs_count;
    double& h_cap;

    int n() const { return M.n; }
    int ns() const { return M.S; }
    int half() const { return M.n + 2 * M.S; }

    void eval() { evaluate<T, T>(M, t, y, ylen, ph, sg, true, wk, dy); }
    T omega() const {
        T om, omd;
        speed_at(M.speed, t, true, om, omd);
        return om;
    }
    void record(int kind, int from, int to, int j) { log.record(re(t), kind, from, to, j); }

    // Slider j leaves the disc: its own z, zdot start from the contact kinematics that
    // the last evaluation left in wk.
    void separate(int j) {
        y[n() + ns() + j] = wk.aux.wc[j];
        y[half() + n() + ns() + j] = wk.aux.wcd[j];
        ph[j] = SEPARATION;
    }

    // Phase of slider j in contact at y, the others' phases held: stick, slip (with its
    // sign) or, where contact would need a pulling normal force, separation.
    void choose_phase(int j) {
        const T om = omega();
        const double v = re(om - y[half() + n() + j]);
        int s = sg[j];
        if (v == 0.0) {
            ph[j] = STICK;
            eval();
            const double nf = re(wk.aux.N[j]);
            const double f = re(wk.aux.F[j]);
            if (nf > 0.0 && std::fabs(f) < M.fr.mus * nf) return;
            if (f > 0.0)
                s = 1;
            else if (f < 0.0)
                s = -1;
        } else if (v > 0.0) {
            s = 1;
        } else {
            s = -1;
        }
        ph[j] = SLIP;
        sg[j] = s;
        eval();
        if (re(wk.aux.N[j]) < 0.0) separate(j);
    }

    void record_change(int old_phase, int old_s, int new_phase, int new_s, int j) {
        if (old_phase == new_phase) {
            if (new_phase == SLIP && old_s != new_s) record(EV_REVERSAL, old_phase, new_phase, j);
            return;
        }
        int kind;
        if (new_phase == SEPARATION)
            kind = EV_SEPARATION;
        else if (old_phase == SEPARATION)
            kind = EV_RECONTACT;
        else if (new_phase == STICK)
            kind = EV_STICK;
        else
            kind = EV_SLIP;
        record(kind, old_phase, new_phase, j);
    }

    // After a switch, re-check every slider in contact (several sliders only): one that
    // would need N < 0 separates, a sticking one beyond the static limit slips; violators
    // switch one at a time, lowest index first, until none is left.
    void settle() {
        if (ns() == 1) return;
        const T om = omega();
        for (int it = 0; it < 4 * ns() + 4; ++it) {
            eval();
            bool changed = false;
            for (int k = 0; k < ns(); ++k) {
                if (ph[k] == SEPARATION) continue;
                const double nf = re(wk.aux.N[k]);
                const double f = re(wk.aux.F[k]);
                if (nf < 0.0) {
                    const int old = ph[k];
                    if (old == STICK) y[half() + n() + k] = om;
                    separate(k);
                    record(EV_SEPARATION, old, SEPARATION, k);
                    changed = true;
                    break;
                }
                if (ph[k] == STICK && std::fabs(f) > M.fr.mus * nf) {
                    ph[k] = SLIP;
                    sg[k] = f > 0.0 ? 1 : -1;
                    record(EV_SLIP, STICK, SLIP, k);
                    changed = true;
                    break;
                }
            }
            if (!changed) return;
        }
    }

    // Normal acceleration of the disc's surface under slider k, from the derivatives dy
    // at y [m/s^2].
    T surface_acceleration(int k) const {
        const SliderAux<T>& aux = wk.aux;
        const T phid = aux.phid[k];
        T acc = 2.0 * phid * aux.gpqd[k] - phid * phid * aux.l2gq[k];
        acc += dy[half() + n() + k] * aux.gpq[k];
        for (int i = 0; i < n(); ++i) acc += wk.G(k, i) * dy[half() + i];
        return acc;
    }

    // Plastic impact of slider j landing while others are in contact. Contacts the
    // impact releases go to released (count returned). A release whose flight would last
    // less than the minimum flight time, or whose peak gap is below round-off, is closed
    // instead (the contact made bilateral and the impact solved again): this ends an
    // impact cascade. Shorter steps are asked for (h_cap) so that the flights that remain
    // are resolved.
    int impact(int j, std::vector<int>& released) {
        const int N = n(), S = ns(), H = half();
        std::vector<int> members(S);
        members[0] = j;
        int count = 1;
        for (int k = 0; k < S; ++k)
            if (k != j && ph[k] != SEPARATION) members[count++] = k;
        if (count == 1) {
            single_impact(M, j, y, ylen, wk);
            return 0;
        }
        for (int a = 1; a < count; ++a) {
            const int k = members[a];
            y[H + N + S + k] = contact_velocity(M, k, y, wk);
        }
        const std::vector<T> y_pre(y, y + ylen);
        std::vector<char> forced(count, 0);
        std::vector<T> w(count);
        const std::vector<int> old_ph(ph, ph + S);
        const double min_flight = M.min_flight;
        int nrel = 0;
        for (int round = 0; round < count + 1; ++round) {
            for (int i = 0; i < ylen; ++i) y[i] = y_pre[i];
            contact_impact(M, members.data(), count, y, ylen, wk, forced, w);
            nrel = 0;
            for (int a = 0; a < count; ++a)
                if (re(w[a]) > 0.0) released[nrel++] = members[a];
            if (nrel == 0) break;
            // Predict each flight from the gap's velocity and acceleration just after, with
            // the landing slider in contact unless it leaves too.
            for (int a = 0; a < count; ++a) {
                const int k = members[a];
                if (re(w[a]) > 0.0) {
                    ph[k] = SEPARATION;
                    y[N + S + k] = wk.aux.wc[k];
                } else if (k == j) {
                    ph[k] = SLIP;
                }
            }
            eval();
            bool again = false;
            for (int a = 0; a < count; ++a) {
                const double wa = re(w[a]);
                if (wa <= 0.0) continue;
                const int k = members[a];
                const double gdd = M.sl.sigma[k] * re(dy[H + N + S + k] - surface_acceleration(k));
                if (gdd >= 0.0) continue;
                const double flight = 2.0 * wa / -gdd;
                const double peak = 0.5 * wa * wa / -gdd;
                // Round-off of z: its size, or the preload's compression of the slider's
                // spring where z itself is small.
                const double zscale = pmax(std::fabs(re(wk.aux.wc[k])),
                                           std::fabs(M.sl.n0[k] / M.sl.kz[k]));
                if (flight < min_flight || peak < 8.0 * 2.220446049250313e-16 * zscale) {
                    forced[a] = 1;
                    again = true;
                } else {
                    h_cap = pmin(h_cap, flight);
                }
            }
            for (int a = 0; a < count; ++a) ph[members[a]] = old_ph[members[a]];
            if (!again) break;
            nrel = 0;
        }
        return nrel;
    }

    // Carry the state across the switch triggered by event e (slider e / 3); the caller
    // settles the other sliders.
    void apply(int e) {
        const int N = n(), S = ns(), H = half();
        const int j = e / 3;
        const int which = e % 3;
        if (ph[j] == SEPARATION) {
            // Re-contact: g, g' at the landing state for the impact map, then the phases.
            eval();
            std::vector<int> released(S);
            int nrel = 0;
            if (M.impact) {
                nrel = impact(j, released);
            } else {
                // Velocities are kept; the slider takes the disc's normal velocity.
                const T zd_old = y[H + N + S + j];
                const T zd_new = contact_velocity(M, j, y, wk);
                y[H + N + S + j] = zd_new;
                const int e0 = 2 * H;
                if (ylen > e0)
                    y[e0 + E_IMPACT] += 0.5 * M.sl.mass[j] * (zd_new * zd_new - zd_old * zd_old);
            }
            // Contacts the impact released fly from where they are.
            const std::vector<int> before(ph, ph + S);
            bool landing_leaves = false;
            for (int a = 0; a < nrel; ++a) {
                const int k = released[a];
                landing_leaves = landing_leaves || k == j;
                ph[k] = SEPARATION;
                y[N + S + k] = wk.aux.wc[k];
            }
            record(EV_RECONTACT, SEPARATION, SLIP, j);
            const int first = log.size() - 1;
            if (landing_leaves) {
                record(EV_SEPARATION, SLIP, SEPARATION, j);
            } else {
                choose_phase(j);
                if (ph[j] == SEPARATION)
                    record(EV_SEPARATION, SLIP, SEPARATION, j);
                else if (first >= 0)
                    log.items[first].to = ph[j];
            }
            for (int a = 0; a < nrel; ++a) {
                const int k = released[a];
                if (k != j) record(EV_SEPARATION, before[k], SEPARATION, k);
            }
            return;
        }
        const bool normal_force_event = (ph[j] == SLIP && which == 1) || (ph[j] == STICK && which == 2);
        if (normal_force_event) {
            eval();
            const int old = ph[j];
            if (old == STICK) y[H + N + j] = omega();
            separate(j);
            record(EV_SEPARATION, old, SEPARATION, j);
            return;
        }
        // Relative velocity reached zero (slip) or the static limit was reached (stick):
        // the slider moves with the disc at this instant; decide from the forces.
        y[H + N + j] = omega();
        const int old = ph[j];
        const int old_s = sg[j];
        choose_phase(j);
        record_change(old, old_s, ph[j], sg[j], j);
    }

    // The first event of a slider not yet handled whose function crossed zero at the
    // same instant as the switch just made, or NO_EVENT.
    int simultaneous(const std::vector<char>& handled, const int* ph_start, const double* ev_start,
                     const T* ev_prev) const {
        for (int i = 0; i < 3 * ns(); ++i) {
            const int j = i / 3;
            if (!handled[j] && ph[j] == ph_start[j] && ev_start[i] > 0.0 && re(ev_prev[i]) <= 0.0)
                return i;
        }
        return NO_EVENT;
    }

    // The right-hand side of the new phases into k0 and their event values into ev.
    void restart(T* k0, T* ev) {
        evaluate<T, T>(M, t, y, ylen, ph, sg, true, wk, k0);
        event_values(M, ph, sg, y, wk, ev);
    }

    // Phases at the start: each slider in contact takes the phase its state allows, in
    // slider order; one whose contact would need N < 0 starts separated (recorded).
    void start() {
        for (int j = 0; j < ns(); ++j) {
            if (ph[j] != SEPARATION) {
                choose_phase(j);
                if (ph[j] == SEPARATION) record(EV_SEPARATION, SLIP, SEPARATION, j);
            }
        }
    }

    // Speed-profile kink: Omegadot jumps, so the stick reaction does too; every slider in
    // contact takes the phase its state now allows.
    void kink() {
        const T om = omega();
        for (int j = 0; j < ns(); ++j) {
            if (ph[j] == SEPARATION) continue;
            const int old = ph[j];
            const int old_s = sg[j];
            if (old == STICK) y[half() + n() + j] = om;
            choose_phase(j);
            record_change(old, old_s, ph[j], sg[j], j);
        }
    }

    // Every change of phase: the start, the switch of event e with the switches at the
    // same instant (ph_start and ev_start: the phases and event values at the start of
    // the step), or a kink of the speed profile. k0 and ev_prev receive the restart's
    // right-hand side and event values when several sliders switch at once.
    void run(int mode, int e, const int* ph_start, const double* ev_start, T* k0, T* ev_prev) {
        std::vector<char> handled(ns(), 0);
        while (true) {
            if (mode == MODE_START) {
                start();
            } else if (mode == MODE_EVENT) {
                handled[e / 3] = 1;
                apply(e);
            } else {
                kink();
            }
            settle();
            if (mode != MODE_EVENT || ns() == 1) return;
            restart(k0, ev_prev);
            rhs_count += 1;
            e = simultaneous(handled, ph_start, ev_start, ev_prev);
            if (e == NO_EVENT) return;
        }
    }
};

}  // namespace fivdisc
