"""The floor of the core's cost per step: a plain Dormand-Prince 5(4) loop with the same
step-size control over a linear system of the same state size, in C++ in the same
extension, built by the same compiler with the same flags
(``fivdisc.core._core.floor_dopri_linear``, ``src/fivdisc/core/src/floor.hpp``).

``floor_cost(model, duration)`` integrates ``y' = J y`` with J the exact Jacobian of the
model's slip equations at a generic state (so the step sizes resemble the real run's),
no events, no contact solve, no output, and returns the median time per accepted step
[s] and the steps taken. J is applied two ways: as a dense matrix (O(n^2) per product,
which at many coordinates costs more than the core's O(n) right-hand side) and in the
model's own structure, the sparse free disc and free sliders plus the contacts' low-rank
rest (O(n)). Anything the core spends beyond the floor is the price of its right-hand
side, events and output.

Run ``python benchmarks/floor.py``: it prints, for the paper's Fig. 10 case (one slider,
7 modal coordinates), the core's cost per accepted step without output and with the
10 kHz output, each as a ratio to both floors measured in the same run; then the cost per
step at 7 to 23 modal coordinates against the floors, and at 1 to 8 sliders beside the
floors of the same sliders (each as a ratio to one slider's), each with its
least-squares slope and the largest deviation from that line. Each slider count's cost
is also given as a ratio to its own structured floor, and that ratio relative to one
slider's (the growth of the core over the growth of its floor). The sliders' runs are
timed in turns with their floors (runs without output), the fastest of ``--rounds``
rounds, by the wall time or with ``--cpu-time`` by the CPU time; ``--only PART`` prints
one part. The flags measured are the build's: -O3, no -march=native, no FMA contraction
(``CMakeLists.txt``).
"""

from __future__ import annotations

import time

import numpy as np
from fivdisc.core._core import floor_dopri_linear

from fivdisc import core
from fivdisc.model.layout import Phase


def _dopri_linear(op, y, t_final, rtol, atol):
    """Accepted steps of DOPRI5 with the core's PI control on y' = J y (J as ``op``:
    CSR arrays and the low-rank factors)."""
    indptr, indices, data, u, v = op
    return floor_dopri_linear(indptr.astype(np.int64), indices.astype(np.int64),
                              np.ascontiguousarray(data, dtype=float),
                              np.ascontiguousarray(u), np.ascontiguousarray(v),
                              np.ascontiguousarray(y, dtype=float), t_final, rtol, atol)


def _operators(model) -> dict[str, tuple]:
    """The model's slip Jacobian J at a generic state, applied two ways: ``dense`` (J as
    it is, O(n^2) per product) and ``structured`` (J = B + U^T V with B the sparse
    Jacobian of the free disc and free sliders, and the contact's low-rank rest, O(n))."""
    import scipy.sparse as sp


    n_s = model.n_sliders
    ph = np.full(n_s, Phase.SLIP, dtype=np.int64)
    sg = np.ones(n_s, dtype=np.int64)
    y = np.zeros(model.state_size)
    y[: model.n] = 1e-6
    for j in range(n_s):
        y[model.index("phi_dot", j)] = 1.0
    cm = core.core_model(model)
    jac = core.jacobian(cm, 0.0, y, ph, sg)
    # The sliders' own z, zdot are held in contact; keep them so (zero rows).
    for j in range(n_s):
        jac[model.index("z", j)] = 0.0
        jac[model.index("z_dot", j)] = 0.0
    free = core.jacobian(cm, 0.0, y, np.full(n_s, Phase.SEPARATION, dtype=np.int64), sg)
    u, sv, vt = np.linalg.svd(jac - free)
    rank = int(np.sum(sv > 1e-12 * sv[0]))
    b = sp.csr_matrix(free)
    dense = sp.csr_matrix(jac)
    none = np.zeros((0, model.state_size))
    return {
        "dense": (dense.indptr, dense.indices, dense.data, none, none),
        "structured": (b.indptr, b.indices, b.data,
                       np.ascontiguousarray((u[:, :rank] * sv[:rank]).T),
                       np.ascontiguousarray(vt[:rank])),
    }


def floor_cost(model, duration: float, rtol: float = 1e-6, atol: float = 1e-9,
               repeat: int = 3) -> dict[str, tuple[float, int]]:
    """Median wall time per accepted step [s] of each linear floor (``_operators``), and
    its step count."""
    start = np.zeros(model.state_size)
    start[: model.n] = 1e-5
    start[model.n + 2 * model.n_sliders : 2 * model.n + 2 * model.n_sliders] = 1e-2
    out = {}
    for name, op in _operators(model).items():
        _dopri_linear(op, start.copy(), 1e-3, rtol, atol)
        costs = []
        steps = 0
        for _ in range(repeat):
            t0 = time.perf_counter()
            steps = _dopri_linear(op, start.copy(), duration, rtol, atol)
            costs.append((time.perf_counter() - t0) / steps)
        out[name] = (float(np.median(costs)), steps)
    return out


def _slope(label: str, x: list[int], cost: list[float]) -> None:
    """Least-squares line through the costs per step, and how far they stray from it."""
    slope, icpt = np.polyfit(x, cost, 1)
    stray = max(abs(c - (slope * xi + icpt)) / c for xi, c in zip(x, cost, strict=True))
    print(f"  slope {slope * 1e6:.3f} us per {label}, intercept {icpt * 1e6:.2f} us; "
          f"largest deviation from the line {100 * stray:.0f} %")


def main() -> None:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", choices=("fig10", "coordinates", "sliders"),
                        help="print only this part")
    parser.add_argument("--rounds", type=int, default=25,
                        help="rounds of the sliders' part (default 25)")
    parser.add_argument("--cpu-time", action="store_true",
                        help="time the sliders' part by this thread's CPU time, which a "
                        "machine busy with other work disturbs far less than the wall time")
    args = parser.parse_args()
    only = args.only
    if only in (None, "fig10"):
        fig10_case()
    if only in (None, "coordinates"):
        coordinates()
    if only in (None, "sliders"):
        sliders(args.rounds, time.thread_time if args.cpu_time else time.perf_counter)


def fig10_case() -> None:
    from bench_family import CASES, per_step
    from fivdisc import Case, build_model

    fig10 = CASES["fig10"]
    quiet = {**fig10, "simulation": {**fig10["simulation"], "output_rate": 0.1}}
    kernel = per_step({"no output": quiet, "10 kHz output": fig10})
    floors = floor_cost(build_model(Case(**fig10)), 35.0)
    print("== Fig. 10 case: one slider, 7 modal coordinates")
    for name, (cost, steps) in floors.items():
        print(f"floor ({name:10s}): {cost * 1e6:.2f} us per step ({steps} steps)")
    for label, c in kernel.items():
        ratios = ", ".join(f"{c['cost'] / cost:.2f} x {name}" for name, (cost, _) in
                           floors.items())
        print(f"kernel, {label:14s}: {c['cost'] * 1e6:.2f} us per step ({c['steps']} steps)"
              f" -> {ratios} floor")
    print(f"cost of the 10 kHz output: "
          f"{100 * (kernel['10 kHz output']['cost'] / kernel['no output']['cost'] - 1):+.0f} %")


def coordinates() -> None:
    from bench_family import CASES, per_step
    from fivdisc import Case, build_model

    fig10 = CASES["fig10"]
    quiet = {**fig10, "simulation": {**fig10["simulation"], "output_rate": 0.1}}
    print("== modal coordinates (modes (0, l), l <= L; Fig. 10 case, 5 s, no output)")
    coords, costs = [], []
    for top in (3, 5, 7, 9, 11):
        case = {**quiet, "disc": {"modes": [(0, l) for l in range(top + 1)]},
                "simulation": {**quiet["simulation"], "duration": 5.0}}
        model = build_model(Case(**case))
        c = per_step({"k": case})["k"]["cost"]
        f = floor_cost(model, 5.0)
        coords.append(model.n)
        costs.append(c)
        print(f"{model.n:3d} coordinates: {c * 1e6:.2f} us per step -> "
              f"{c / f['structured'][0]:.2f} x structured, {c / f['dense'][0]:.2f} x dense floor")
    _slope("coordinate", coords, costs)


def _floor_once(op, start, duration: float, clock) -> float:
    """Time per accepted step [s] of one run of a linear floor by ``clock``."""
    t0 = clock()
    steps = _dopri_linear(op, start.copy(), duration, 1e-6, 1e-9)
    return (clock() - t0) / steps


def _kernel_once(model, y0, duration: float, clock) -> float:
    """Time per accepted step [s] of the core's run without output by ``clock``."""
    from fivdisc.engine.integration import Integration

    run = Integration(model, y0, duration=duration)
    t0 = clock()
    run.run_to(duration)
    return (clock() - t0) / run.stats["steps"]


def sliders(rounds: int, clock) -> None:
    """Per step, 1 to 8 sliders against the floors of the same sliders.

    On a shared machine the kernel and its floors are timed in turns, ``rounds`` times
    (each round: every slider count's run, then its floors' runs), and each figure is
    the fastest of the rounds: the work is deterministic, so the fastest run is the one
    least disturbed by the rest of the machine (the advice of :mod:`timeit`)."""
    import tomllib

    from bench_family import _spread
    from fivdisc import Case, build_model, examples
    from fivdisc.engine.simulation import initial_state

    # Short runs, many rounds: the more of them, the likelier some ran undisturbed.
    span = 1.0
    print(f"== sliders (Fig. 4 parameters, steady sliding, {span:g} s; fastest of {rounds} "
          "rounds)")
    fig04 = tomllib.loads(examples.path("fig04").read_text())
    fig04["simulation"] = {**fig04.get("simulation", {}), "duration": span,
                           "output_rate": 100.0}
    counts = [1, 2, 4, 8]
    cases = {s: Case(**_spread(fig04, s)) for s in counts}
    ops = {}
    models = {}
    for s, case in cases.items():
        model = build_model(case)
        models[s] = (model, initial_state(model))
        start = np.zeros(model.state_size)
        start[: model.n] = 1e-5
        start[model.n + 2 * s : 2 * model.n + 2 * s] = 1e-2
        ops[s] = (start, _operators(model))
        _kernel_once(*models[s], 0.01, clock)
        for op in ops[s][1].values():
            _dopri_linear(op, start.copy(), 1e-3, 1e-6, 1e-9)
    kernel = {s: [] for s in counts}
    floors = {s: {name: [] for name in ops[s][1]} for s in counts}
    for _ in range(rounds):
        for s in counts:
            kernel[s].append(_kernel_once(*models[s], span, clock))
            start, named = ops[s]
            for name, op in named.items():
                floors[s][name].append(_floor_once(op, start, span, clock))
    cost = {s: min(kernel[s]) for s in counts}
    floor = {s: {name: min(c) for name, c in floors[s].items()} for s in counts}
    for s in counts:
        grows = ", ".join(f"{name} floor {f * 1e6:.2f} us ({f / floor[1][name]:.2f} x)"
                          for name, f in floor[s].items())
        own = cost[s] / floor[s]["structured"]
        rounds_own = sorted(k / f for k, f in zip(kernel[s], floors[s]["structured"],
                                                  strict=True))
        print(f"{s} slider(s): {cost[s] * 1e6:.2f} us per step ({cost[s] / cost[1]:.2f} x one "
              f"slider); {grows}; {own:.2f} x its structured floor (median of the rounds "
              f"{rounds_own[len(rounds_own) // 2]:.2f}), "
              f"{own * floor[1]['structured'] / cost[1]:.2f} x relative to one slider's")
    _slope("slider", counts, [cost[s] for s in counts])


if __name__ == "__main__":
    main()
