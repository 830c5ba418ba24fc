// The non-smooth time integration: adaptive DOPRI5 steps inside a phase machine.
//
// One call of advance() goes on from the saved state until a target time is passed, the
// run ends, it fails, the event log is nearly full, or it has tried its budget of steps
// (so that the caller can report progress, count steps against a budget and take an
// interrupt however slowly the integration goes). The integrator's whole state is kept
// between calls, and a call that ends on its step budget resumes the step-size
// controller where it was.
//
// Switches are located on the dense output (events.hpp); the next phase is always chosen
// from the state at the switch (switch.hpp); tangent vectors, if any, are carried across
// with their saltation matrices (tangent.hpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "dopri5.hpp"
#include "events.hpp"
#include "layout.hpp"
#include "rhs.hpp"
#include "switch.hpp"
#include "tangent.hpp"

namespace fivdisc {

// Scratch of the integrator, allocated once.
struct Scratch {
    std::vector<double> ynew, ytmp, yout, dy, rc, evn, evt, probes, ev_old, err_vec;
    void init(int size, int n_ev) {
        ynew.assign(size, 0.0);
        ytmp.assign(size, 0.0);
        yout.assign(size, 0.0);
        dy.assign(size, 0.0);
        rc.assign(static_cast<size_t>(5) * size, 0.0);
        evn.assign(n_ev, 0.0);
        evt.assign(n_ev, 0.0);
        probes.assign(static_cast<size_t>(PROBES) * n_ev, 0.0);
        ev_old.assign(n_ev, INFINITY);
        err_vec.assign(size, 0.0);
    }
};

class Integrator {
  public:
    Model M;
    Layout L;
    OutputColumns cols;
    Control ctl;
    Counters cnt;
    Clock clk;
    std::vector<double> y;   // the state (with the energy accumulators, if any)
    std::vector<int> ph, sg;  // every slider's phase and slip sign
    std::vector<double> k;   // (7, size): the stages; k[0] the right-hand side at y
    std::vector<double> ev_prev;  // event values at y
    std::vector<double> breaks;   // kinks of the speed profile, increasing
    // Samples (n_out rows): of the state, (n_out, size), and per slider N, f, phase, w,
    // then Omega, (n_out, cols.width()). The caller's arrays (attach_output), or owned
    // storage left uninitialised (like numpy.empty: pages never written are never
    // committed).
    double* out_y = nullptr;
    double* out_aux = nullptr;
    int64_t n_out = 0;
    EventLog log;
    int event_capacity = 1 << 15;
    std::unique_ptr<Tangents> tan;

    Integrator(Model model, std::vector<double> y0, std::vector<int> phases, const Control& control,
               int64_t n_out_, std::vector<double> breaks_)
        : M(std::move(model)), ctl(control), y(std::move(y0)), ph(std::move(phases)),
          breaks(std::move(breaks_)), n_out(n_out_) {
        const bool energy = static_cast<int>(y.size()) > 2 * (M.n + 2 * M.S);
        L = Layout(M, energy);
        cols.S = M.S;
        sg.assign(M.S, 1);
        k.assign(static_cast<size_t>(7) * L.size, 0.0);
        ev_prev.assign(static_cast<size_t>(3) * M.S, 0.0);
        own_y.reset(new double[static_cast<size_t>(n_out > 0 ? n_out : 1) * L.size]);
        own_aux.reset(new double[static_cast<size_t>(n_out > 0 ? n_out : 1) * cols.width()]);
        out_y = own_y.get();
        out_aux = own_aux.get();
        wk.init(M);
        sc.init(L.size, 3 * M.S);
    }

    // Carry k tangent vectors (rows of V, k x nd) from the current state on.
    void set_tangents(const double* V, int kvec) {
        if (!tan || tan->k != kvec) tan = std::make_unique<Tangents>(M, L.size, kvec);
        std::copy(V, V + static_cast<size_t>(kvec) * L.nd, tan->V.begin());
        if (cnt.started) tangent_prepare(M, clk.t, y.data(), L.size, ph.data(), sg.data(), *tan);
    }

    // Write the samples into the caller's arrays, (n_out, size) and (n_out, width), which
    // must outlive the integrator's use of them; the owned storage is released.
    void attach_output(double* y_rows, double* aux_rows) {
        out_y = y_rows;
        out_aux = aux_rows;
        own_y.reset();
        own_aux.reset();
    }

    int advance(double t_target);

  private:
    std::unique_ptr<double[]> own_y, own_aux;
    Work<double> wk;
    Scratch sc;

    double* K(int st) { return &k[static_cast<size_t>(st) * L.size]; }

    Switcher<double> switcher(double t) {
        return Switcher<double>{M, t, y.data(), L.size, ph.data(), sg.data(), wk, sc.dy.data(),
                                log, cnt.rhs, clk.h_cap};
    }

    static double rms_scaled(const double* a, const double* y0, const double* y1, double atol,
                             double rtol, int m) {
        double acc = 0.0;
        for (int i = 0; i < m; ++i) {
            const double s = atol + rtol * pmax(std::fabs(y0[i]), std::fabs(y1[i]));
            const double r = a[i] / s;
            acc += r * r;
        }
        return std::sqrt(acc / m);
    }

    // Starting step size (Hairer, Norsett & Wanner, Sec. II.4).
    double initial_step(double t) {
        const double rtol = ctl.rtol, atol = ctl.atol;
        const int m = L.nd;
        const double* f0 = K(0);
        const double* yy = y.data();
        const double d0 = rms_scaled(yy, yy, yy, atol, rtol, m);
        const double d1 = rms_scaled(f0, yy, yy, atol, rtol, m);
        double h0;
        if (d0 < 1e-5 || d1 < 1e-5)
            h0 = 1e-6;
        else
            h0 = 0.01 * d0 / d1;
        double* ytmp = sc.ytmp.data();
        double* dy = sc.dy.data();
        for (int i = 0; i < L.size; ++i) ytmp[i] = yy[i] + h0 * f0[i];
        evaluate<double, double>(M, t + h0, ytmp, L.size, ph.data(), sg.data(), false, wk, dy);
        for (int i = 0; i < L.size; ++i) dy[i] = (dy[i] - f0[i]) / h0;
        const double d2 = rms_scaled(dy, yy, yy, atol, rtol, m);
        double h1;
        if (pmax(d1, d2) <= 1e-15)
            h1 = pmax(1e-6, h0 * 1e-3);
        else
            h1 = std::pow(0.01 / pmax(d1, d2), 0.2);
        return pmin(100.0 * h0, h1);
    }

    // Stages 1-6 of the step [t, t + hs] from y into k; ytmp is left at the last stage's
    // state, the step's end, and evn at the event values there. With tangents each
    // stage's state and evaluation go to their own slot, for tangent_step once the step is
    // accepted.
    void stages(double t, double hs) {
        const int size = L.size;
        double* ys = sc.ytmp.data();
        Work<double>* ws = &wk;
        for (int st = 1; st < 7; ++st) {
            if (tan) {
                ys = tan->ys(st);
                ws = &tan->twk[st];
            }
            for (int i = 0; i < size; ++i) ys[i] = y[i];
            for (int j = 0; j < st; ++j) {
                const double a = hs * dp5::A[st][j];
                if (a != 0.0) {
                    const double* kj = K(j);
                    for (int i = 0; i < size; ++i) ys[i] += a * kj[i];
                }
            }
            evaluate<double, double>(M, t + dp5::C[st] * hs, ys, size, ph.data(), sg.data(), false, *ws, K(st));
        }
        if (tan)
            for (int i = 0; i < size; ++i) sc.ytmp[i] = ys[i];
        event_values(M, ph.data(), sg.data(), sc.ytmp.data(), *ws, sc.evn.data());
    }

    // Keep each slider's phase and slip sign in output row i, for complete_rows.
    void begin_row(int64_t i) {
        double* row = &out_aux[static_cast<size_t>(i) * cols.width()];
        for (int j = 0; j < M.S; ++j) {
            row[j] = sg[j];
            row[cols.phase(j)] = ph[j];
        }
    }

    // Sample the dense output of the step [t0, t0 + h] at output times in (t0, t1].
    void sample_states(double t0, double t1, double h) {
        int64_t i = cnt.out_next;
        const double out_dt = ctl.out_dt;
        const double t_final = ctl.t_final;
        const int size = L.size;
        while (i < n_out) {
            const double ti = pmin(static_cast<double>(i) * out_dt, t_final);
            if (ti > t1) break;
            const double theta = (ti - t0) / h;
            double* row = &out_y[static_cast<size_t>(i) * size];
            for (int c = 0; c < size; ++c) row[c] = dp5::dense_one(sc.rc.data(), size, theta, c);
            begin_row(i);
            ++i;
        }
        cnt.out_next = i;
    }

    // Complete the output rows first .. last - 1 that sample_states began, from the
    // right-hand side at each: the contact kinematics (a sticking slider's phidot, z and
    // zdot of one in contact), per slider N, f, w under it, then Omega; clk.w_peak keeps
    // the largest |w| under the sliders (a nan stays). Done once the steps are taken.
    void complete_rows(int64_t first, int64_t last) {
        const int n = M.n, S = M.S, half = L.half, size = L.size;
        std::vector<int> phr(S), sgr(S);
        double* ys = sc.yout.data();
        double* dy = sc.dy.data();
        const SliderAux<double>& aux = wk.aux;
        for (int64_t i = first; i < last; ++i) {
            const double ti = pmin(static_cast<double>(i) * ctl.out_dt, ctl.t_final);
            double* row = &out_y[static_cast<size_t>(i) * size];
            double* arow = &out_aux[static_cast<size_t>(i) * cols.width()];
            for (int j = 0; j < S; ++j) {
                sgr[j] = static_cast<int>(arow[j]);
                phr[j] = static_cast<int>(arow[cols.phase(j)]);
            }
            for (int c = 0; c < size; ++c) ys[c] = row[c];
            evaluate<double, double>(M, ti, ys, size, phr.data(), sgr.data(), false, wk, dy);
            double om, omd;
            speed_at(M.speed, ti, false, om, omd);
            for (int j = 0; j < S; ++j) {
                if (phr[j] == STICK) row[half + n + j] = om;
                if (phr[j] != SEPARATION) {
                    row[n + S + j] = aux.wc[j];
                    row[half + n + S + j] = aux.wcd[j];
                }
                arow[cols.normal(j)] = aux.N[j];
                arow[cols.friction(j)] = aux.F[j];
                const double w = std::fabs(aux.wc[j]);
                arow[cols.w(j)] = aux.wc[j];
                if (!(w <= clk.w_peak) && clk.w_peak == clk.w_peak) clk.w_peak = w;
            }
            arow[cols.omega()] = om;
        }
    }
};

inline int Integrator::advance(double t_target) {
    const int size = L.size;
    const int nd = L.nd;
    const int n_ev = 3 * M.S;
    const int S = M.S;
    const double inf = std::numeric_limits<double>::infinity();
    const double rtol = ctl.rtol, atol = ctl.atol, max_step = ctl.max_step, t_final = ctl.t_final;
    double* ynew = sc.ynew.data();
    double* ytmp = sc.ytmp.data();
    double* evn = sc.evn.data();
    double* ev_old = sc.ev_old.data();
    double* err_vec = sc.err_vec.data();
    // Event values at the previous step's start, for the dip predicted from three values
    // (inf: none since the start of this call, a switch or a kink).
    for (int i = 0; i < n_ev; ++i) ev_old[i] = inf;
    double h_old = 0.0;
    std::vector<int> ph_start(S);
    std::vector<double> ev_start(n_ev);

    double t = clk.t;
    double h = clk.h;
    const int64_t first_row = cnt.out_next;
    if (!cnt.started) {
        if (tan) {
            ph_start = ph;
            before_switch(y.data(), sg.data(), S, *tan);
        }
        auto sw = switcher(t);
        sw.run(MODE_START, NO_EVENT, ph.data(), ev_prev.data(), K(0), ev_prev.data());
        sw.restart(K(0), ev_prev.data());
        if (tan)
            saltation(M, MODE_START, NO_EVENT, t, ph_start.data(), ev_prev.data(), y.data(), ph.data(),
                      sg.data(), K(0), wk, *tan);
        if (h <= 0.0) h = initial_step(t);
        if (cnt.out_next == 0 && n_out > 0) {
            for (int i = 0; i < size; ++i) out_y[static_cast<size_t>(i)] = y[i];
            begin_row(0);
            cnt.out_next = 1;
        }
        cnt.started = true;
        cnt.rhs += 2;
    }

    int status = ST_RUNNING;
    bool after_reject = cnt.paused == 2;
    double err_old = cnt.paused ? clk.err_old : 1e-4;
    cnt.paused = 0;
    const int64_t call_steps = ctl.call_steps;
    int64_t tried = 0;
    while (true) {
        if (t >= t_final) {
            status = ST_DONE;
            break;
        }
        if (t >= t_target || log.size() > event_capacity - 4 * S - 4) break;
        if (call_steps > 0 && tried >= call_steps) {
            cnt.paused = after_reject ? 2 : 1;
            clk.err_old = err_old;
            break;
        }
        tried += 1;
        const auto kb = std::upper_bound(breaks.begin(), breaks.end(), t) - breaks.begin();
        double tb = kb < static_cast<long>(breaks.size()) ? breaks[kb] : t_final;
        tb = pmin(tb, t_final);
        double hs = h;
        if (max_step > 0.0) hs = pmin(hs, max_step);
        bool land = false;
        if (t + hs >= tb || (tb - t - hs) < 1e-3 * hs) {
            hs = tb - t;
            land = true;
        }

        stages(t, hs);
        for (int i = 0; i < size; ++i) ynew[i] = ytmp[i];
        cnt.rhs += 6;
        for (int i = 0; i < size; ++i) err_vec[i] = 0.0;
        for (int st = 0; st < 7; ++st) {
            const double a = hs * dp5::E[st];
            if (a != 0.0) {
                const double* kk = K(st);
                for (int i = 0; i < size; ++i) err_vec[i] += a * kk[i];
            }
        }
        const double err = rms_scaled(err_vec, y.data(), ynew, atol, rtol, nd);

        if (!std::isfinite(err) || err > 1.0) {
            if (std::isfinite(err))
                h = hs / pmin(5.0, std::pow(err, dp5::EXPO1) / 0.9);
            else
                h = 0.25 * hs;
            cnt.rejected += 1;
            after_reject = true;
            if (h < 1e-14 * pmax(1.0, std::fabs(t))) {
                status = std::isfinite(err) ? ST_UNDERFLOW : ST_NONFINITE;
                break;
            }
            continue;
        }

        cnt.steps += 1;
        const double t_new = land ? tb : t + hs;
        if (tan) tangent_step(M, t, hs, ph.data(), sg.data(), *tan);

        bool have_rc = false;
        auto dense = [&]() {
            if (!have_rc) {
                dp5::dense_coefficients(y.data(), ynew, K(0), size, hs, sc.rc.data(), size);
                have_rc = true;
            }
        };
        double theta = 2.0;
        int which;
        {
            StepEvents se{M, t, hs, sc.rc.data(), size, ph.data(), sg.data(), wk, sc.dy.data(),
                          ytmp, sc.evt.data(), cnt.eval_events};
            which = first_event(se, ev_prev.data(), evn, ev_old, h_old, n_ev, sc.probes, dense, theta);
        }

        // PI control (Gustafsson; Hairer, Norsett & Wanner II.4): damps the step-size
        // oscillation that plain error-per-step control shows, and so rejections.
        const double pi = err > 0.0 ? std::pow(err, dp5::EXPO1) / std::pow(err_old, dp5::BETA) : 0.0;
        double fac = pi > 0.0 ? pmin(5.0, pmax(0.1, 0.9 / pi)) : 5.0;
        err_old = pmax(err, 1e-4);
        if (after_reject) fac = pmin(fac, 1.0);
        after_reject = false;

        if (which >= 0) {
            dense();
            const double t_e = theta >= 1.0 ? t_new : t + theta * hs;
            sample_states(t, t_e, hs);
            dp5::dense_eval(sc.rc.data(), size, theta, y.data());
            const int first_new = log.size();
            clk.h_cap = inf;
            ph_start = ph;
            std::copy(ev_prev.begin(), ev_prev.end(), ev_start.begin());
            if (tan) {
                tangent_interpolate(theta, hs, *tan);
                before_switch(y.data(), sg.data(), S, *tan);
            }
            auto sw = switcher(t_e);
            sw.run(MODE_EVENT, which, ph_start.data(), ev_start.data(), K(0), ev_prev.data());
            t = t_e;
            sw.restart(K(0), ev_prev.data());
            for (int i = 0; i < n_ev; ++i) ev_old[i] = inf;
            cnt.rhs += 1;
            if (tan)
                saltation(M, MODE_EVENT, which, t, ph_start.data(), ev_start.data(), y.data(), ph.data(),
                          sg.data(), K(0), wk, *tan);
            for (int e = first_new; e < log.size(); ++e)
                if (ctl.stop_mask & (int64_t{1} << log.items[e].kind)) status = ST_STOPPED;
            cnt.switches += 1;
            if (t - clk.last_switch < ctl.zeno_dt)
                cnt.zeno += 1;
            else
                cnt.zeno = 0;
            clk.last_switch = t;
            h = hs * pmin(fac, 1.0);
            if (clk.h_cap < inf) h = pmin(h, 0.25 * clk.h_cap);
            if (status == ST_STOPPED) break;
            if (cnt.zeno >= ctl.zeno_count) {
                status = ST_ZENO;
                break;
            }
            if (cnt.switches >= ctl.max_switches) {
                status = ST_MAX_SWITCHES;
                break;
            }
            continue;
        }

        for (int i = 0; i < size; ++i)
            if (!std::isfinite(ynew[i])) status = ST_NONFINITE;
        if (status != ST_RUNNING) break;
        const double next_out = pmin(static_cast<double>(cnt.out_next) * ctl.out_dt, t_final);
        if (cnt.out_next < n_out && next_out <= t_new) {
            dense();
            sample_states(t, t_new, hs);
        }
        for (int i = 0; i < size; ++i) y[i] = ynew[i];
        double* k0 = K(0);
        const double* k6 = K(6);
        for (int i = 0; i < size; ++i) k0[i] = k6[i];
        for (int i = 0; i < n_ev; ++i) {
            ev_old[i] = ev_prev[i];
            ev_prev[i] = evn[i];
        }
        h_old = hs;
        if (tan) tangent_accept(*tan);
        t = t_new;
        h = hs * fac;
        if (land && t < t_final) {
            if (tan) {
                ph_start = ph;
                before_switch(y.data(), sg.data(), S, *tan);
            }
            auto sw = switcher(t);
            sw.run(MODE_KINK, NO_EVENT, ph.data(), ev_prev.data(), K(0), ev_prev.data());
            sw.restart(K(0), ev_prev.data());
            for (int i = 0; i < n_ev; ++i) ev_old[i] = inf;
            cnt.rhs += 1;
            if (tan)
                saltation(M, MODE_KINK, NO_EVENT, t, ph_start.data(), ev_prev.data(), y.data(), ph.data(),
                          sg.data(), K(0), wk, *tan);
        }
    }

    complete_rows(first_row, cnt.out_next);
    clk.t = t;
    clk.h = h;
    cnt.status = status;
    return status;
}

}  // namespace fivdisc
