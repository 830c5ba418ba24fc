"""The compiled core against the last numba kernel, per step, side by side in one run.

Run ``python benchmarks/bench_core.py [--rounds R] [--span S]``. The last commit whose
kernel was numba (``previous.LAST_NUMBA``) is installed into its own virtual environment
(``previous.run_previous``, cached; the first run also waits for numba's compilation
there, outside the timings), and the two are timed in turns, ``--rounds`` times: 1, 2 and
8 sliders, in stick-slip (Figs. 8-9 parameters spread around the disc) and in steady
sliding (Fig. 4), plain and with 1, 2 and 4 tangent vectors (the step capped at
``tangent_step``, as the analyses do), and the paper's Fig. 10 case (decelerating disc)
without and with its 10 kHz output. Each figure is the time per accepted step by the
CPU time of the integrating thread (a machine busy with other work disturbs it far less
than the wall time), the fastest of the rounds; the ratio core / numba is printed (the
target is <= 1.0), the step counts of both (they must agree: the same steps), and the
core's cost against its structured floor (``floor.py``; target <= 1.15 at S = 1, 2, 8).
The flags measured are the build's (``CMakeLists.txt``: -O3, no -march=native, no FMA
contraction).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import textwrap

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from previous import LAST_NUMBA, run_previous

_TIMER = textwrap.dedent(
    """
    import json, time, tomllib
    import numpy as np
    from fivdisc import Case, examples
    try:  # the layer folders
        from fivdisc.engine.equilibrium import initial_state
        from fivdisc.engine.integration import Integration, tangent_step
        from fivdisc.model.build import build_model
    except ImportError:  # before them
        from fivdisc.integration import Integration, tangent_step
        from fivdisc.model import build_model
        from fivdisc.simulate import initial_state

    def spread(base, count):
        case = {{k: v for k, v in base.items() if k != "slider"}}
        case["sliders"] = [{{"angle": 2 * np.pi * j / count + 0.05 * j}} for j in range(count)]
        return case

    def steps_of(run):
        return run.stats["steps"] if hasattr(run, "stats") else int(run.ist[1])

    def one(model, y0, span, vectors, cap, rate=0.0):
        run = Integration(model, y0, duration=span, max_step=cap, output_rate=rate)
        if vectors:
            run.set_tangents(np.eye(vectors, model.state_size))
        start = time.thread_time()
        run.run_to(span)
        return (time.thread_time() - start) / steps_of(run), steps_of(run)

    fig04 = tomllib.loads(examples.path("fig04").read_text())
    fig04["simulation"] = {{**fig04.get("simulation", {{}}), "output_rate": 100.0}}
    bases = {{"stick-slip": {{"simulation": {{"output_rate": 100.0}}}}, "sliding": fig04}}
    out = {{}}
    for label, base in bases.items():
        for count in (1, 2, 8):
            model = build_model(Case(**spread(base, count)))
            y0 = initial_state(model)
            for vectors in (0, 1, 2, 4):
                cap = tangent_step(model) if vectors else None
                one(model, y0, 0.01, vectors, cap)  # imports, and numba's compilation
                out[f"{{label}} {{count}} {{vectors}}"] = one(model, y0, {span!r}, vectors, cap)
    # The paper's Fig. 10 case (decelerating disc), without and with its 10 kHz output.
    from fivdisc import load_case
    model = build_model(load_case(examples.path("fig10")))
    y0 = initial_state(model)
    for label, rate in (("fig10", 0.0), ("fig10-10kHz", 10000.0)):
        one(model, y0, 0.01, 0, None, rate)
        out[f"{{label}} 1 0"] = one(model, y0, {span!r}, 0, None, rate)
    print(json.dumps(out))
    """
)


def _round(span: float) -> tuple[dict, dict]:
    """One round: the numba commit's figures, then the core's."""
    code = _TIMER.format(span=span)
    before = json.loads(run_previous(LAST_NUMBA, code).strip().splitlines()[-1])
    scope: dict = {}
    exec(code.replace("print(json.dumps(out))", "RESULT = out"), scope)
    return before, scope["RESULT"]


def floors(span: float) -> dict[int, float]:
    """The structured floor's cost per step at S = 1, 2, 8 (steady sliding, Fig. 4)."""
    import tomllib

    from fivdisc import Case, examples
    from fivdisc.model.build import build_model
    from floor import _dopri_linear, _operators

    fig04 = tomllib.loads(examples.path("fig04").read_text())
    out = {}
    import time

    import numpy as np

    for count in (1, 2, 8):
        case = {k: v for k, v in fig04.items() if k != "slider"}
        case["sliders"] = [{"angle": 2 * np.pi * j / count + 0.05 * j} for j in range(count)]
        model = build_model(Case(**case))
        start = np.zeros(model.state_size)
        start[: model.n] = 1e-5
        start[model.n + 2 * count : 2 * model.n + 2 * count] = 1e-2
        op = _operators(model)["structured"]
        best = np.inf
        for _ in range(3):
            t0 = time.thread_time()
            steps = _dopri_linear(op, start.copy(), span, 1e-6, 1e-9)
            best = min(best, (time.thread_time() - t0) / steps)
        out[count] = best
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--span", type=float, default=0.5,
                        help="simulated time of each timed run [s] (default 0.5)")
    args = parser.parse_args()
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, "
          f"{platform.python_version()}; numba kernel of {LAST_NUMBA}")
    best_before: dict = {}
    best_now: dict = {}
    for _ in range(args.rounds):
        before, now = _round(args.span)
        for key in now:
            for best, figures in ((best_before, before), (best_now, now)):
                cost, steps = figures[key]
                if key not in best or cost < best[key][0]:
                    best[key] = (cost, steps)
    floor = floors(args.span)
    print(f"per step, core / numba, CPU time, fastest of {args.rounds} rounds, "
          f"{args.span:g} s spans")
    for key in best_now:
        (c, cs), (b, bs) = best_now[key], best_before[key]
        label, count, vectors = key.split()
        extra = (f"; {c / floor[int(count)]:.2f} x its structured floor"
                 if label == "sliding" and vectors == "0" else "")
        print(f"{label:10s} S={count} v={vectors}: {c * 1e6:7.2f} us / {b * 1e6:7.2f} us = "
              f"{c / b:.2f}  (steps {cs} / {bs}){extra}")


if __name__ == "__main__":
    main()
