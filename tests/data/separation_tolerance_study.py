"""How far the separation times of the paper's long runs move with the integrator tolerance.

The slider's response in Figs. 8, 19 and 24 is chaotic: tiny differences (another
tolerance, another machine's floating point) grow until the trajectories part, so the
time of the first separation is not reproducible to the digit (Fig. 8's moved from 26.6 s
to 24.3 s between two machines). ``tests/test_paper.py`` therefore asserts separation
times only within the spread this study measures: each case at the default tolerances
and at 10x and 100x tighter and 10x looser ones. Run it with
``python tests/data/separation_tolerance_study.py`` (about 5 minutes on 2 cores); it
prints one line per case with the first and last separation start over the tolerances.
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor

from fivdisc.paper import FIG8, FIG19, FIG24
from fivdisc.paper import measure as ms
from fivdisc.simulate import simulate

RTOLS = (1e-5, 1e-6, 1e-7, 1e-8)  # the default is 1e-6 with atol = 1e-3 rtol
CASES = {
    "fig8": FIG8.case,
    "fig19a": FIG19.runs["a"],
    "fig19b": FIG19.runs["b"],
    "fig24a": FIG24.runs["a"],
    "fig24b": FIG24.runs["b"],
}


def _separation(job: tuple[str, float]) -> tuple[str, float, dict]:
    name, rtol = job
    case = CASES[name].replace({"simulation.rtol": rtol, "simulation.atol": 1e-3 * rtol})
    return name, rtol, ms.separation(simulate(case).dataset)


def main() -> None:
    jobs = [(name, rtol) for name in CASES for rtol in RTOLS]
    with ProcessPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(_separation, jobs))
    for name in CASES:
        rows = [r for n, _, r in results if n == name]
        firsts = [r["first"] for r in rows]
        lasts = [r["last"] for r in rows]
        counts = [r["count"] for r in rows]
        print(f"{name}: first {min(firsts):.2f}-{max(firsts):.2f} s, last "
              f"{min(lasts):.2f}-{max(lasts):.2f} s, count {min(counts)}-{max(counts)} "
              f"over rtol {', '.join(f'{t:g}' for t in RTOLS)}: "
              + "; ".join(f"{r['first']:.2f}/{r['last']:.2f}" for r in rows))


if __name__ == "__main__":
    main()
