"""The compiled C++ core against the numba kernel, run side by side in one process.

Run ``python benchmarks/compare_core.py [--span S] [--only NAME]``. Every packaged
example (short spans), the Figs. 8-9 stick-slip parameters spread over 2, 4 and 8 sliders,
and the two pads with energy accumulators are integrated by both kernels, plain and with
1 and 4 tangent vectors, driven exactly as ``fivdisc.simulate`` drives them (the same
chunks, the same bounded calls). It prints per run the worst differences: event
sequences (kinds, phases, sliders, order), event times [s], the samples relative to
each column's peak, the final state, and the tangents relative to their largest entry;
and exits non-zero if any exceeds its tolerance.
"""

from __future__ import annotations

import argparse
import sys
import tomllib

import numpy as np

from fivdisc import examples
from fivdisc.case import Case, load_case
from fivdisc.core import _core, slots
from fivdisc.engine.equilibrium import initial_state
from fivdisc.engine.integration import Integration, tangent_step
from fivdisc.model.build import build_model


def _spread(base: dict, count: int) -> dict:
    """``base`` with ``count`` copies of its slider spread around the disc."""
    case = {k: v for k, v in base.items() if k != "slider"}
    slider = base.get("slider", {})
    case["sliders"] = [{**slider, "angle": 2 * np.pi * j / count + 0.05 * j}
                       for j in range(count)]
    return case

CHUNKS = 200
TOL_TIME = 1e-12
TOL_TRAJ = 1e-10
TOL_TAN = 1e-9


def core_model(model):
    k = model.kernel_args
    return _core.Model(k.disc, k.slider, k.shape, k.table, k.speed, k.opts)


class Pair:
    """One run on both kernels: the numba Integration and the core's Integrator built
    from its settings."""

    def __init__(self, model, y0, span, rate, vectors, energy, max_step):
        self.numba = Integration(model, y0, duration=span, output_rate=rate, energy=energy,
                                 max_step=max_step)
        nb_run = self.numba
        ctl = nb_run.ctl
        self.core = _core.Integrator(
            core_model(model), nb_run.y.copy(), nb_run.ph.copy(), t_final=span,
            rtol=ctl[slots.C_RTOL], atol=ctl[slots.C_ATOL], max_step=ctl[slots.C_MAX_STEP],
            out_dt=ctl[slots.C_OUT_DT], n_out=nb_run.out_y.shape[0],
            max_switches=ctl[slots.C_MAX_SWITCHES], zeno_dt=ctl[slots.C_ZENO_DT],
            zeno_count=ctl[slots.C_ZENO_COUNT], stop_mask=int(ctl[slots.C_STOP_MASK]),
            breaks=nb_run.breaks)
        if vectors:
            start = np.eye(vectors, model.state_size) + 0.1
            nb_run.set_tangents(start)
            self.core.set_tangents(start)
        self.span = span
        self.ev_times: list[np.ndarray] = []
        self.ev_rows: list[np.ndarray] = []

    def run(self):
        nb_run, core = self.numba, self.core
        for chunk in range(1, CHUNKS + 1):
            target = self.span * chunk / CHUNKS
            while True:
                status = nb_run.advance(target)
                if status != slots.ST_RUNNING or nb_run.t >= target:
                    break
            while True:
                # The numba Integration's call budget, the same for the core.
                cstatus = core.advance(target, nb_run.call_steps)
                t, r = core.take_events()
                if t.size:
                    self.ev_times.append(t)
                    self.ev_rows.append(r)
                if cstatus != slots.ST_RUNNING or core.t >= target:
                    break
            if status != slots.ST_RUNNING or cstatus != slots.ST_RUNNING:
                break
        return status, cstatus


def compare(name, pair):
    nb_run, core = pair.numba, pair.core
    status, cstatus = pair.run()
    out = {"name": name, "ok": True, "notes": []}

    def bad(note):
        out["ok"] = False
        out["notes"].append(note)

    if status != cstatus:
        bad(f"status {status} vs {cstatus}")
    nb_t, nb_r = nb_run.events()
    c_t = np.concatenate(pair.ev_times) if pair.ev_times else np.empty(0)
    c_r = np.concatenate(pair.ev_rows) if pair.ev_rows else np.empty((0, 4), np.int64)
    out["events"] = nb_t.size
    out["kinds"] = np.bincount(nb_r[:, 0], minlength=5) if nb_t.size else np.zeros(5, int)
    if nb_t.size != c_t.size or not np.array_equal(nb_r, c_r):
        m = min(nb_t.size, c_t.size)
        first = next((i for i in range(m) if not np.array_equal(nb_r[i], c_r[i])), m)
        bad(f"event sequences differ: {nb_t.size} vs {c_t.size} events, first at {first}")
        out["dt"] = float(np.max(np.abs(nb_t[:first] - c_t[:first]), initial=0.0))
    else:
        out["dt"] = float(np.max(np.abs(nb_t - c_t), initial=0.0))
    if out["dt"] > TOL_TIME:
        bad(f"event times differ by {out['dt']:.3g} s")
    st = core.stats
    if (st["steps"] != nb_run.ist[slots.I_STEPS] or st["rejected"] != nb_run.ist[slots.I_REJECTED]
            or st["rhs"] != nb_run.ist[slots.I_RHS]
            or st["rhs_events"] != nb_run.ist[slots.I_EVAL_EVENTS]):
        bad(f"counters differ: {dict(st)} vs steps {nb_run.ist[slots.I_STEPS]} rejected "
            f"{nb_run.ist[slots.I_REJECTED]} rhs {nb_run.ist[slots.I_RHS]} rhs_events "
            f"{nb_run.ist[slots.I_EVAL_EVENTS]}")
    out["steps"] = int(nb_run.ist[slots.I_STEPS])
    n = min(nb_run.n_samples, core.n_samples)
    if nb_run.n_samples != core.n_samples:
        bad(f"samples {nb_run.n_samples} vs {core.n_samples}")
    worst = 0.0
    for a, b in ((nb_run.out_y[:n], core.out_y[:n]), (nb_run.out_aux[:n], core.out_aux[:n])):
        if n:
            peak = np.max(np.abs(a), axis=0)
            diff = np.max(np.abs(a - b), axis=0)
            with np.errstate(all="ignore"):
                rel = np.where(peak > 0, diff / peak, diff)
            worst = max(worst, float(np.nanmax(rel)))
    peak = np.maximum(np.abs(nb_run.y), 1e-300)
    worst = max(worst, float(np.max(np.abs(nb_run.y - core.y) / np.maximum(
        peak, np.max(np.abs(nb_run.out_y[:n]), axis=0, initial=0.0)))))
    out["traj"] = worst
    if worst > TOL_TRAJ:
        bad(f"trajectories differ by {worst:.3g} of their peak")
    if not np.array_equal(nb_run.ph, core.ph):
        bad("final phases differ")
    if nb_run.tan is not None:
        a = nb_run.tangents(slaved=False)
        b = core.tangents(slaved=False)
        scale = max(np.max(np.abs(a)), 1e-300)
        tan = float(np.max(np.abs(a - b)) / scale)
        a = nb_run.tangents(slaved=True)
        b = core.tangents(slaved=True)
        tan = max(tan, float(np.max(np.abs(a - b)) / max(np.max(np.abs(a)), 1e-300)))
        out["tan"] = tan
        if not tan <= TOL_TAN:
            bad(f"tangents differ by {tan:.3g} of their largest entry")
    return out


def _kick(model, speed=5.0):
    """Rest, with a strong transverse velocity of the first disc mode: the sliders separate
    and land again."""
    y = np.zeros(model.state_size)
    y[model.n + 2 * model.n_sliders] = speed
    return y


def cases(span):
    """(name, case, energy[, initial state]) of the comparison."""
    for path in sorted(examples.DIRECTORY.glob("*.toml")):
        try:
            case = load_case(path)
        except Exception:  # a sweep file
            continue
        sim = case.simulation
        yield path.stem, case.replace({"simulation.duration": min(span, sim.duration)}), False
    stick = {"simulation": {"duration": span, "output_rate": 1000.0}}
    for count in (2, 4, 8):
        yield f"stick-slip x{count}", Case(**_spread(stick, count)), False
    pads = load_case(examples.path("two-pads"))
    yield "two-pads energy", pads.replace({"simulation.duration": span}), True
    fig = tomllib.loads(examples.path("fig18a").read_text())
    yield "fig18a energy", Case(**{**fig, "simulation": {**fig["simulation"],
                                                         "duration": span}}), True
    kick = Case(simulation={"duration": span, "output_rate": 20000.0})
    yield "kick impact", kick, True, _kick
    yield "kick no impact", kick.replace({"simulation.impact": False}), True, _kick
    yield "kick pads", pads.replace({"simulation.duration": span}), True, _kick
    for count in (3, 8):
        spread = Case(**_spread({"simulation": {"duration": span, "output_rate": 1000.0}}, count))
        yield f"kick x{count}", spread, True, _kick


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--span", type=float, default=0.3, help="simulated time [s] (plain)")
    parser.add_argument("--tangent-span", type=float, default=0.05,
                        help="simulated time [s] with tangents")
    parser.add_argument("--only", default=None, help="only cases whose name contains this")
    parser.add_argument("--vectors", default="0,1,4", help="tangent vector counts")
    args = parser.parse_args()
    failed = 0
    kinds = np.zeros(5, int)
    worst = {"dt": 0.0, "traj": 0.0, "tan": 0.0}
    for vectors in (int(v) for v in args.vectors.split(",")):
        span = args.span if vectors == 0 else args.tangent_span
        for name, case, energy, *start in cases(span):
            if args.only and args.only not in name:
                continue
            model = build_model(case)
            y0 = start[0](model) if start else initial_state(model)
            sim = case.simulation
            max_step = tangent_step(model) if vectors else None
            pair = Pair(model, y0, sim.duration, sim.output_rate, vectors, energy, max_step)
            res = compare(name, pair)
            kinds += res["kinds"]
            for key in worst:
                worst[key] = max(worst[key], res.get(key, 0.0))
            flag = "ok  " if res["ok"] else "FAIL"
            failed += not res["ok"]
            print(f"{flag} {name:22s} v={vectors} {res['steps']:6d} steps {res['events']:5d} "
                  f"events  dt {res['dt']:.1e}  traj {res['traj']:.1e}"
                  + (f"  tan {res['tan']:.1e}" if "tan" in res else "")
                  + f"  kinds {'/'.join(str(k) for k in res['kinds'])}"
                  + ("  " + "; ".join(res["notes"]) if res["notes"] else ""), flush=True)
    print(f"worst: event times {worst['dt']:.2e} s, trajectories {worst['traj']:.2e} of peak, "
          f"tangents {worst['tan']:.2e}; events stick/slip/reversal/separation/recontact "
          f"{'/'.join(str(k) for k in kinds)}; {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
