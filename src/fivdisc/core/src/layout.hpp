// Where everything sits in the state vector, the per-slider results of a right-hand-side
// evaluation, the integrator's counters and clock, its event log and its output columns.
//
// State y for n modal coordinates and S sliders:
//     [q_0 .. q_{n-1}, phi_1 .. phi_S, z_1 .. z_S,
//      qdot_0 .. qdot_{n-1}, phidot_1 .. phidot_S, zdot_1 .. zdot_S, E_0 .. E_7]
// z_j, zdot_j are integrated only while slider j flies; E are the optional energy
// accumulators, kept out of the error norm and the events.
#pragma once

#include <cstdint>
#include <vector>

#include "model.hpp"

namespace fivdisc {

// Energy accumulators: integrated power [W] of each kind of force, and impact jumps [J].
enum Energy : int {
    E_FRICTION = 0, E_DRIVE = 1, E_MOMENT = 2, E_SLOPE = 3, E_SLIDER_DAMPING = 4,
    E_DISC_DAMPING = 5, E_IMPACT = 6, E_SURFACE = 7, N_ENERGY = 8
};

struct Layout {
    int n = 0, S = 0;
    int half = 0;     // offset of the velocities, n + 2 S
    int nd = 0;       // the dynamic state, 2 (n + 2 S)
    int size = 0;     // with the energy accumulators, if any
    Layout() = default;
    Layout(const Model& m, bool energy)
        : n(m.n), S(m.S), half(m.n + 2 * m.S), nd(2 * (m.n + 2 * m.S)),
          size(2 * (m.n + 2 * m.S) + (energy ? N_ENERGY : 0)) {}
    bool energy() const { return size > nd; }
    int q(int i) const { return i; }
    int phi(int j) const { return n + j; }
    int z(int j) const { return n + S + j; }
    int qd(int i) const { return half + i; }
    int phid(int j) const { return half + n + j; }
    int zd(int j) const { return half + n + S + j; }
    int e(int c) const { return nd + c; }
};

// Columns of the output samples' auxiliary block: per slider its normal force, friction
// force and w under it, its phase, then the disc's speed.
struct OutputColumns {
    int S = 0;
    int normal(int j) const { return j; }
    int friction(int j) const { return S + j; }
    int phase(int j) const { return 2 * S + j; }
    int w(int j) const { return 3 * S + j; }
    int omega() const { return 4 * S; }
    int width() const { return 4 * S + 1; }
};

// One switch.
struct Event {
    double t;
    int32_t kind, from, to, slider;
};

// Switches recorded by the integrator (read out and cleared by the caller).
struct EventLog {
    std::vector<Event> items;
    int size() const { return static_cast<int>(items.size()); }
    void record(double t, int kind, int from, int to, int j) {
        items.push_back(Event{t, kind, from, to, j});
    }
    void clear() { items.clear(); }
};

enum Status : int {
    ST_RUNNING = 0, ST_DONE = 1, ST_NONFINITE = 2, ST_UNDERFLOW = 3, ST_ZENO = 4,
    ST_MAX_SWITCHES = 5, ST_STOPPED = 6
};

// The integrator's settings.
struct Control {
    double rtol = 1e-6, atol = 1e-9;
    double max_step = 0.0;   // <= 0: none
    double t_final = 0.0;
    double out_dt = INFINITY;
    double max_switches = 1e18;
    double zeno_dt = 1e-10;
    double zeno_count = 1000;
    int64_t stop_mask = 0;   // bit k: stop after an event of kind k
    int64_t call_steps = 0;  // steps one call may try; <= 0: no bound
};

// Counters kept between calls.
struct Counters {
    int status = ST_RUNNING;
    int64_t steps = 0, rejected = 0, rhs = 0;
    int64_t out_next = 0;     // next output row
    int64_t switches = 0;
    int64_t zeno = 0;         // switches in a row closer than zeno_dt
    bool started = false;
    int64_t eval_events = 0;  // right-hand sides evaluated to locate events
    int paused = 0;           // 1 (2 after a rejected step): the last call ended on its step budget
};

// Times and sizes kept between calls.
struct Clock {
    double t = 0.0, h = 0.0;
    double last_switch = -INFINITY;
    double h_cap = INFINITY;  // set by an impact cascade: the flights to resolve
    double w_peak = 0.0;      // largest |w| under the sliders at the samples since reset
    double err_old = 1e-4;    // the step-size controller's previous error (paused calls)
};

}  // namespace fivdisc
