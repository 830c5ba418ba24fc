"""Cost of the model family, side by side in one run.

Run ``python benchmarks/bench_family.py``. It prints, each as a ratio against a baseline
measured in the same run:

1. the single-slider cost per accepted step against the kernel before the model family
   (``previous.BEFORE_FAMILY``, installed into its own virtual environment), on the
   paper's Fig. 10 case and a stick-slip case (Figs. 8-9), with the results compared;
2. the speed-up over the scipy baseline (``bench_simulate.against_baseline``);
3. the cost per step of 2 and 8 sliders against 1 slider (same disc, same span), in
   stick-slip and in steady sliding.

Costs per step are the integration's wall time (``wall_time``)
over its accepted steps, the median of three runs.
"""

from __future__ import annotations

import json
import os
import textwrap

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from bench_simulate import against_baseline
from previous import BEFORE_FAMILY, run_previous

# Cases written with keys the pre-family code knows too.
CASES = {
    "fig10": {
        "speed": {"profile": "decelerating", "initial": 2 * np.pi, "duration": 35.0},
        "simulation": {"duration": 35.0, "output_rate": 10000.0},
    },
    "stick_slip": {"simulation": {"duration": 5.0, "output_rate": 10000.0}},
}

_TIMER = textwrap.dedent(
    """
    import json, sys
    import numpy as np
    from fivdisc import Case, simulate
    cases = json.loads(sys.argv[1]) if len(sys.argv) > 1 else json.loads({cases!r})
    out = {{}}
    for name, kw in cases.items():
        case = Case(**kw)
        simulate(case.replace({{"simulation.duration": 0.01}}))
        costs, steps = [], 0
        for _ in range(3):
            attrs = simulate(case).dataset.attrs
            costs.append(attrs["wall_time"] / attrs["n_steps"])
            steps = attrs["n_steps"]
        out[name] = {{"cost": float(np.median(costs)), "steps": int(steps)}}
    print(json.dumps(out))
    """
)


def _timer(cases: dict) -> str:
    return _TIMER.format(cases=json.dumps(cases))


def per_step(cases: dict) -> dict:
    """Median cost per accepted step [s] and steps of each case, in this process."""
    scope: dict = {}
    # The cases given, not the calling script's command line.
    code = (_timer(cases).replace("print(json.dumps(out))", "RESULT = out")
            .replace("json.loads(sys.argv[1]) if len(sys.argv) > 1 else ", ""))
    exec(code, scope)
    return scope["RESULT"]


def against_previous() -> None:
    before = json.loads(run_previous(BEFORE_FAMILY, _timer(CASES)))
    now = per_step(CASES)
    for name in CASES:
        b, n = before[name], now[name]
        print(f"{name:11s} per step: {n['cost'] * 1e6:6.2f} us now, {b['cost'] * 1e6:6.2f} us "
              f"before the family ({BEFORE_FAMILY}) -> ratio {n['cost'] / b['cost']:.2f}; "
              f"steps {n['steps']} vs {b['steps']}")


def _spread(base: dict, count: int) -> dict:
    """``base`` with ``count`` copies of its slider spread around the disc."""
    case = {k: v for k, v in base.items() if k != "slider"}
    slider = base.get("slider", {})
    case["sliders"] = [{**slider, "angle": 2 * np.pi * j / count + 0.05 * j}
                       for j in range(count)]
    return case


def sliders() -> None:
    """Cost per step of 1, 2 and 8 sliders: in stick-slip (Figs. 8-9 parameters, 2 s;
    every slider adds its switches, each located by extra evaluations) and in steady
    sliding (Fig. 4 parameters, 10 s: the integration alone)."""
    import tomllib

    from fivdisc import examples

    fig04 = tomllib.loads(examples.path("fig04").read_text())
    fig04["simulation"] = {**fig04.get("simulation", {}), "duration": 10.0,
                           "output_rate": 100.0}
    bases = {"stick-slip": {"simulation": {"duration": 2.0, "output_rate": 1000.0}},
             "steady sliding": fig04}
    for label, base in bases.items():
        costs = per_step({str(count): _spread(base, count) for count in (1, 2, 8)})
        one = costs["1"]["cost"]
        for count, c in costs.items():
            print(f"{label:14s} {count} slider(s): {c['cost'] * 1e6:6.2f} us per step "
                  f"({c['steps']} steps), {c['cost'] / one:.2f} x one slider")


def main() -> None:
    print("== single slider against the kernel before the model family")
    against_previous()
    print("== against the scipy baseline (Fig. 8 case, 0.5 s)")
    against_baseline(0.5)
    print("== several sliders, cost per step")
    sliders()


if __name__ == "__main__":
    main()
