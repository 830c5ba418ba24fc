"""Cost per step of the compiled core against the numba kernel, side by side in one
process (phase 1 of the port; ``bench_family.py`` and ``bench_tangent.py`` measure
against an installed numba commit once numba is gone).

Run ``python benchmarks/compare_speed.py [--rounds R] [--span S]``: 1, 2 and 8 sliders in
stick-slip (Figs. 8-9 parameters spread around the disc) and in steady sliding (Fig. 4),
plain and with 1, 2 and 4 tangent vectors; each figure the fastest of the rounds by this
thread's CPU time, the two kernels timed in turns.
"""

from __future__ import annotations

import argparse
import time
import tomllib

import numpy as np

from compare_core import _spread, core_model
from fivdisc import Case, examples
from fivdisc.core import _core, slots
from fivdisc.engine.equilibrium import initial_state
from fivdisc.engine.integration import Integration, tangent_step
from fivdisc.model.build import build_model

clock = time.thread_time


def numba_run(model, y0, span, vectors, max_step):
    run = Integration(model, y0, duration=span, max_step=max_step)
    if vectors:
        run.set_tangents(np.eye(vectors, model.state_size))
    t0 = clock()
    run.run_to(span)
    return (clock() - t0) / int(run.ist[slots.I_STEPS])


def core_run(model, cm, y0, span, vectors, max_step):
    ref = Integration(model, y0, duration=span, max_step=max_step)
    run = _core.Integrator(cm, ref.y.copy(), ref.ph.copy(), t_final=span, rtol=ref.ctl[0],
                           atol=ref.ctl[1], max_step=ref.ctl[2], breaks=ref.breaks)
    if vectors:
        run.set_tangents(np.eye(vectors, model.state_size))
    t0 = clock()
    while run.advance(span, ref.call_steps) == slots.ST_RUNNING and run.t < span:
        run.take_events()
    return (clock() - t0) / run.stats["steps"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--span", type=float, default=0.5)
    args = parser.parse_args()
    fig04 = tomllib.loads(examples.path("fig04").read_text())
    fig04["simulation"] = {**fig04.get("simulation", {}), "output_rate": 100.0}
    bases = {"stick-slip": {"simulation": {"output_rate": 100.0}}, "sliding": fig04}
    print(f"per step, core / numba (CPU time, fastest of {args.rounds} rounds, "
          f"{args.span:g} s spans)")
    for label, base in bases.items():
        for count in (1, 2, 8):
            case = Case(**_spread(base, count))
            model = build_model(case)
            cm = core_model(model)
            y0 = initial_state(model)
            cells = []
            for vectors in (0, 1, 2, 4):
                max_step = tangent_step(model) if vectors else None
                numba_run(model, y0, 0.01, vectors, max_step)  # compile / load
                a, b = [], []
                for _ in range(args.rounds):
                    a.append(numba_run(model, y0, args.span, vectors, max_step))
                    b.append(core_run(model, cm, y0, args.span, vectors, max_step))
                cells.append(f"v={vectors}: {min(b) * 1e6:6.2f} us / {min(a) * 1e6:6.2f} us "
                             f"= {min(b) / min(a):.2f}")
            print(f"{label:10s} S={count}: " + "; ".join(cells), flush=True)


if __name__ == "__main__":
    main()
