"""The compiled core against the last numba kernel: the same runs in both, compared.

Run ``python benchmarks/compare_core.py [--span S] [--tangent-span S] [--only NAME]
[--vectors 0,1,4]``. The last commit whose kernel was numba (``previous.LAST_NUMBA``) is
installed into its own virtual environment (``previous.run_previous``, cached). Every
packaged example (short spans), the Figs. 8-9 stick-slip parameters spread over 2, 4 and
8 sliders, the two pads and Fig. 18a with energy accumulators, and kicks that make the
sliders separate and land (plastic impacts, cascades over 3 and 8 sliders) are
integrated by both, from the same initial states, driven as ``fivdisc.simulate`` drives
them (the same chunks, the same bounded calls), plain and with 1 and 4 tangent vectors
(the step capped at ``tangent_step``). It prints per run the worst differences: event
sequences (kinds, phases, sliders, order), event times [s], the samples relative to each
column's peak, the final state, the tangents relative to their largest entry, the step
counts; and exits non-zero if any exceeds its tolerance (issue 37: 1e-12 s, 1e-10 of the
peak, 1e-9).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import textwrap
from pathlib import Path

import numpy as np

from fivdisc import examples
from fivdisc.case import Case, load_case
from fivdisc.engine.equilibrium import initial_state
from fivdisc.model.build import build_model
from previous import LAST_NUMBA, run_previous

TOL_TIME = 1e-12
TOL_TRAJ = 1e-10
TOL_TAN = 1e-9

# Runs every job of a .npz file and writes the results to another; the same code in the
# current tree and at the numba commit (before the layer folders).
_RUNNER = textwrap.dedent(
    """
    import sys
    import numpy as np
    from fivdisc.case import Case
    try:
        from fivdisc.engine.integration import Integration, tangent_step
        from fivdisc.model.build import build_model
    except ImportError:
        from fivdisc.integration import Integration, tangent_step
        from fivdisc.model import build_model

    jobs = np.load({jobs!r}, allow_pickle=False)
    out = {{}}
    for k in range(int(jobs["count"])):
        case = Case.from_toml(str(jobs[f"case{{k}}"]))
        span, vectors, energy = (float(jobs[f"span{{k}}"]), int(jobs[f"vectors{{k}}"]),
                                 bool(jobs[f"energy{{k}}"]))
        model = build_model(case)
        run = Integration(model, jobs[f"y0{{k}}"], duration=span,
                          output_rate=case.simulation.output_rate, energy=energy,
                          max_step=tangent_step(model) if vectors else None)
        if vectors:
            run.set_tangents(np.eye(vectors, model.state_size) + 0.1)
        for chunk in range(1, 201):
            if run.run_to(span * chunk / 200) != 0:
                break
        times, rows = run.events()
        steps = (run.stats["steps"], run.stats["rejected"]) if hasattr(run, "stats") else (
            int(run.ist[1]), int(run.ist[2]))
        out[f"status{{k}}"] = run.status
        out[f"times{{k}}"], out[f"rows{{k}}"] = times, rows
        out[f"out_y{{k}}"] = np.array(run.out_y[: run.n_samples])
        out[f"out_aux{{k}}"] = np.array(run.out_aux[: run.n_samples])
        out[f"y{{k}}"], out[f"ph{{k}}"] = np.array(run.y), np.array(run.ph)
        out[f"steps{{k}}"] = np.array(steps)
        if vectors:
            out[f"tan{{k}}"] = run.tangents(slaved=False)
            out[f"tans{{k}}"] = run.tangents(slaved=True)
    np.savez({results!r}, **out)
    """
)


def _spread(base: dict, count: int) -> dict:
    """``base`` with ``count`` copies of its slider spread around the disc."""
    case = {k: v for k, v in base.items() if k != "slider"}
    slider = base.get("slider", {})
    case["sliders"] = [{**slider, "angle": 2 * np.pi * j / count + 0.05 * j}
                       for j in range(count)]
    return case


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
    fig = load_case(examples.path("fig18a"))
    yield "fig18a energy", fig.replace({"simulation.duration": span}), True
    kick = Case(simulation={"duration": span, "output_rate": 20000.0})
    yield "kick impact", kick, True, _kick
    yield "kick no impact", kick.replace({"simulation.impact": False}), True, _kick
    yield "kick pads", pads.replace({"simulation.duration": span}), True, _kick
    for count in (3, 8):
        spread = Case(**_spread({"simulation": {"duration": span, "output_rate": 1000.0}},
                                count))
        yield f"kick x{count}", spread, True, _kick


def _peak_relative(a, b) -> float:
    if a.size == 0:
        return 0.0
    peak = np.max(np.abs(a), axis=0)
    with np.errstate(all="ignore"):
        rel = np.where(peak > 0, np.max(np.abs(a - b), axis=0) / peak,
                       np.max(np.abs(a - b), axis=0))
    return float(np.nanmax(rel))


def compare(k, then, now) -> dict:
    res = {"notes": []}
    if int(then[f"status{k}"]) != int(now[f"status{k}"]):
        res["notes"].append(f"status {then[f'status{k}']} vs {now[f'status{k}']}")
    tt, tr, nt, nr = then[f"times{k}"], then[f"rows{k}"], now[f"times{k}"], now[f"rows{k}"]
    res["events"] = tt.size
    res["kinds"] = np.bincount(tr[:, 0], minlength=5) if tt.size else np.zeros(5, int)
    m = min(tt.size, nt.size)
    same = tt.size == nt.size and np.array_equal(tr, nr)
    first = m if same else next((i for i in range(m) if not np.array_equal(tr[i], nr[i])), m)
    if not same:
        res["notes"].append(f"event sequences differ: {tt.size} vs {nt.size}, first at {first}")
    res["dt"] = float(np.max(np.abs(tt[:first] - nt[:first]), initial=0.0))
    if not np.array_equal(then[f"steps{k}"], now[f"steps{k}"]):
        res["notes"].append(f"steps {then[f'steps{k}']} vs {now[f'steps{k}']}")
    res["steps"] = int(then[f"steps{k}"][0])
    worst = 0.0
    for key in ("out_y", "out_aux"):
        a, b = then[f"{key}{k}"], now[f"{key}{k}"]
        if a.shape != b.shape:
            res["notes"].append(f"{key} shapes {a.shape} vs {b.shape}")
            continue
        worst = max(worst, _peak_relative(a, b))
    ya, yb = then[f"y{k}"], now[f"y{k}"]
    scale = np.maximum(np.abs(ya), np.max(np.abs(then[f"out_y{k}"]), axis=0, initial=0.0))
    with np.errstate(all="ignore"):
        worst = max(worst, float(np.nanmax(np.where(scale > 0, np.abs(ya - yb) / scale,
                                                     np.abs(ya - yb)))))
    res["traj"] = worst
    if not np.array_equal(then[f"ph{k}"], now[f"ph{k}"]):
        res["notes"].append("final phases differ")
    if f"tan{k}" in then:
        tan = 0.0
        for key in ("tan", "tans"):
            a, b = then[f"{key}{k}"], now[f"{key}{k}"]
            tan = max(tan, float(np.max(np.abs(a - b)) / max(np.max(np.abs(a)), 1e-300)))
        res["tan"] = tan
    res["ok"] = (not res["notes"] and res["dt"] <= TOL_TIME and res["traj"] <= TOL_TRAJ
                 and res.get("tan", 0.0) <= TOL_TAN)
    return res


def _for_the_baseline(case: Case) -> str:
    """The case's TOML without the sliders' own perturbations (a key the numba commit
    does not know, added with several pads): both sides start from the same given state,
    so no perturbation enters the runs."""
    import tomllib

    import tomli_w

    data = tomllib.loads(case.to_toml())
    for slider in [data.get("slider", {}), *data.get("sliders", [])]:
        slider.pop("perturbation", None)
    return tomli_w.dumps(data)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--span", type=float, default=0.3, help="simulated time [s] (plain)")
    parser.add_argument("--tangent-span", type=float, default=0.05,
                        help="simulated time [s] with tangents")
    parser.add_argument("--only", default=None, help="only cases whose name contains this")
    parser.add_argument("--vectors", default="0,1,4", help="tangent vector counts")
    parser.add_argument("--baseline", default=LAST_NUMBA, help="the numba commit")
    args = parser.parse_args()
    jobs, names = {}, []
    for vectors in (int(v) for v in args.vectors.split(",")):
        span = args.span if vectors == 0 else args.tangent_span
        for name, case, energy, *start in cases(span):
            if args.only and args.only not in name:
                continue
            model = build_model(case)
            k = len(names)
            names.append((name, vectors))
            jobs |= {f"case{k}": _for_the_baseline(case), f"span{k}": case.simulation.duration,
                     f"vectors{k}": vectors, f"energy{k}": energy,
                     f"y0{k}": start[0](model) if start else initial_state(model)}
    jobs["count"] = len(names)
    with tempfile.TemporaryDirectory() as tmp:
        jobs_file, then_file, now_file = (str(Path(tmp) / f) for f in
                                          ("jobs.npz", "then.npz", "now.npz"))
        np.savez(jobs_file, **jobs)
        run_previous(args.baseline, _RUNNER.format(jobs=jobs_file, results=then_file))
        exec(_RUNNER.format(jobs=jobs_file, results=now_file), {})
        then, now = dict(np.load(then_file)), dict(np.load(now_file))
    failed = 0
    worst = {"dt": 0.0, "traj": 0.0, "tan": 0.0}
    kinds = np.zeros(5, int)
    for k, (name, vectors) in enumerate(names):
        res = compare(k, then, now)
        kinds += res["kinds"]
        for key in worst:
            worst[key] = max(worst[key], res.get(key, 0.0))
        failed += not res["ok"]
        print(f"{'ok  ' if res['ok'] else 'FAIL'} {name:22s} v={vectors} {res['steps']:6d} steps "
              f"{res['events']:5d} events  dt {res['dt']:.1e}  traj {res['traj']:.1e}"
              + (f"  tan {res['tan']:.1e}" if "tan" in res else "")
              + f"  kinds {'/'.join(str(x) for x in res['kinds'])}"
              + ("  " + "; ".join(res["notes"]) if res["notes"] else ""), flush=True)
    print(f"worst against {args.baseline}: event times {worst['dt']:.2e} s, trajectories "
          f"{worst['traj']:.2e} of peak, tangents {worst['tan']:.2e}; events stick/slip/"
          f"reversal/separation/recontact {'/'.join(str(x) for x in kinds)}; {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
