"""Record the core reference: what the numba kernel gives, for the C++ core to reproduce
(issue 37, item 4).

Run from a clean checkout of the commit to record, before the kernel changes::

    python tests/data/record_core_reference.py            # writes core_reference.npz
    python tests/data/record_core_reference.py --dry-run  # prints the runs, writes nothing

It writes ``tests/data/core_reference.npz``: one compressed ``.npz`` whose ``"meta"``
entry (JSON) names the commit, the versions and every run's parameters (the case as TOML
text, the span, tolerances, the driving pattern), and whose arrays are each run's start
and results under ``"<run>/<what>"``. ``tests/core/test_recorded_reference.py`` replays
every run with the current kernel and compares.

What is recorded:

* every packaged example case (the sweep files left out) over a short span from its own
  start, and, for the three whose separations come late (Fig. 18a at 6 pi rad/s, Fig. 28
  at 50 rad/s with and without the impact), a window started from the state a run
  reached just before them;
* the test suite's own cases: several sliders on both faces, separation and re-contact
  with and without the impact, impact cascades, energy terms, the Stribeck, exponential
  and table laws, a decelerating disc stopping (a kink of the speed) and a table speed
  profile with kinks, a run stopped on an event;
* each of those plain and with 1 and 4 tangent vectors from seeded random starts (but
  for the cases in ``PLAIN_ONLY``, with the reason), at rtol 1e-10, atol 1e-13, with 120
  output samples: the events (kind, from- and to-phase, slider, time), the samples and
  the end state, the final tangent vectors, the status. The samples are kept once, with
  the plain run: the tangent runs' are checked equal to them here;
* three periodic orbits (``fivdisc.periodic_orbit``: Fig. 13 after a 5 s transient, the
  damped-disc example's orbit, a three-slider stick-slip orbit) with their multipliers,
  and one shot of each orbit's period from its point with the identity as tangents (the
  monodromy the kernel gives, whatever Newton does);
* Lyapunov exponents and their uncertainty (``fivdisc.lyapunov``) on three cases: a
  paper case (one exponent: one set of vectors), a damped-disc Stribeck stick-slip orbit
  (two) and three sliders at a stable equilibrium (three).
"""

from __future__ import annotations

import argparse
import datetime
import subprocess
import sys
import time
import zlib
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "core"))

import core_replay as cr  # noqa: E402

import fivdisc  # noqa: E402
from fivdisc import examples  # noqa: E402

RTOL, ATOL = 1e-10, 1e-13
SPAN = 0.04  # 4-8 stick-slip switches on the paper's cases
SAMPLES = 120  # output samples per run (plus the start)
TANGENTS = (1, 4)
SEED = 37  # the number; each run's seed adds a hash of its name

# --- the test suite's cases (their sources named) -------------------------------------

# tests/test_simulate_reference.py, tests/test_family.py: Table 1 and sliders on it.
PAIR = [{"angle": 0.0, "face": "top"},
        {"angle": 1.3, "face": "bottom", "mass": 0.12, "preload": 450.0,
         "normal_stiffness": 2.5e4, "track_radius": 0.09}]
TWO_FACES = [{"angle": 0.0}, {"angle": 1.0, "face": "bottom", "mass": 0.12}]
EIGHT = [{"angle": 2 * np.pi * j / 8 + 0.1 * j, "face": "top" if j % 2 else "bottom",
          "preload": 400.0 + 20 * j} for j in range(8)]
# tests/test_tangent.py: a light disc of two modes, one and two sliders.
LIGHT_BASE = {"disc": {"density": 720.0, "modes": [[0, 0], [0, 1]]}, "speed": {"value": 1.0}}
LIGHT_ONE = {"slider": {"mass": 1.0, "normal_damping": 20.0, "preload": 50.0}, **LIGHT_BASE}
LIGHT_TWO = {"sliders": [
    {"mass": 1.0, "normal_damping": 20.0, "preload": 50.0, "angle": 0.0},
    {"mass": 0.5, "normal_damping": 10.0, "preload": 50.0, "angle": 2.0, "face": "bottom"},
], **LIGHT_BASE}
# tests/test_orbits.py: the textbook stick-slip oscillator on a one-mode disc.
RIGID = {"disc": {"modes": [[0, 0]]},
         "slider": {"rotational_damping": 0.0, "normal_damping": 5.0},
         "friction": {"static": 0.8, "kinetic_max": 0.5, "kinetic_min": 0.5, "decay": 0.0},
         "speed": {"value": 1.0}}
# tests/test_lyapunov_accuracy.py: a damped, thicker disc with Stribeck friction.
S33_DISC = {"inner_radius": 0.05, "outer_radius": 0.14, "thickness": 0.004,
            "modes": [[0, 0], [0, 1], [0, 2]], "damping_ratio": 0.001,
            "damping_frame": "space"}
S33_FRICTION = {"law": "stribeck", "static": 0.8, "kinetic_max": 0.6, "kinetic_min": 0.35,
                "stribeck_velocity": 0.5, "stribeck_exponent": 2.0, "viscous": 0.02}
S33_BOTTOM = {"face": "bottom", "angle": 1.0, "track_radius": 0.1, "mass": 0.12,
              "normal_stiffness": 3.5e4, "normal_damping": 0.15,
              "rotational_stiffness": 1800.0, "rotational_damping": 0.06, "preload": 250.0}
S33_THREE = {
    "disc": S33_DISC, "friction": S33_FRICTION, "speed": {"value": 12.0},
    "sliders": [
        {"face": "top", "angle": 0.0, "track_radius": 0.11, "mass": 0.08,
         "normal_stiffness": 4e4, "normal_damping": 0.2, "rotational_stiffness": 1500.0,
         "rotational_damping": 0.05, "preload": 200.0},
        {"face": "top", "angle": 2.1, "track_radius": 0.11, "mass": 0.1,
         "normal_stiffness": 3e4, "normal_damping": 0.1, "rotational_stiffness": 2000.0,
         "rotational_damping": 0.08, "preload": 150.0},
        S33_BOTTOM,
    ],
    "simulation": {"initial_state": "equilibrium", "perturbation": {"phi": 1e-4}},
}
S33_ONE = {"disc": S33_DISC, "friction": S33_FRICTION, "speed": {"value": 3.0},
           "sliders": [S33_BOTTOM]}


def _kick_mode(k: int, speed: float):
    """Rest with modal rate ``k`` at ``speed`` [m/s]: the sliders fly and land."""
    def start(model):
        q_dot = np.zeros(model.n)
        q_dot[k] = speed
        return cr.initial_state(model, {"q_dot": q_dot})
    return start


def _kick_half(model):
    """tests/test_tangent.py's start: rest with the first modal rate at 0.5 m/s."""
    y = np.zeros(model.state_size)
    y[model.state_size // 2] = 0.5
    return y


def _table(alpha: float, points: int) -> dict:
    speeds = np.linspace(0.0, 2.0, points)
    return {"law": "table", "speeds": speeds.tolist(),
            "values": (0.35 + 0.25 * np.exp(-alpha * speeds)).tolist()}


# name -> (Case keyword tables, start (None: the case's own) , span [s], extra Spec fields)
SUITE: dict[str, tuple[dict, object, float, dict]] = {
    # tests/test_simulate_reference.py
    "suite-slip-only": ({"slider": {"normal_damping": 11.0, "rotational_damping": 1.0},
                         "friction": {"decay": 10.0}, "speed": {"value": 10.0},
                         "simulation": {"initial_state": "equilibrium"}}, None, SPAN, {}),
    "suite-stick-slip": ({}, None, SPAN, {}),
    "suite-decelerating-stop": (
        {"speed": {"profile": "decelerating", "initial": 2 * np.pi, "duration": 0.05}},
        None, 0.06, {}),  # the disc stops at 0.05 s: a kink of the speed
    "suite-separation-impact": ({"simulation": {"impact": True}}, _kick_mode(0, 5.0),
                                0.05, {}),
    "suite-separation-no-impact": ({"simulation": {"impact": False}}, _kick_mode(0, 5.0),
                                   0.05, {}),
    "suite-stop-on-separation": ({}, _kick_mode(0, 5.0), 0.05,
                                 {"stop_on": ("separation",)}),
    # tests/test_family_reference.py
    "pair-stick-slip": ({"sliders": PAIR}, None, SPAN, {}),
    "pair-separation-impact": ({"sliders": PAIR, "simulation": {"impact": True}},
                               _kick_mode(0, 5.0), 0.03, {}),
    "pair-separation-no-impact": ({"sliders": PAIR, "simulation": {"impact": False}},
                                  _kick_mode(0, 5.0), 0.05, {}),
    "pair-material-damping-stribeck-decelerating": (
        {"sliders": PAIR, "disc": {"damping_ratio": [0.02, 0.01, 0.005, 0.003]},
         "friction": {"law": "stribeck", "stribeck_velocity": 0.2, "stribeck_exponent": 1.5,
                      "viscous": 0.05},
         "speed": {"profile": "decelerating", "initial": 8.0, "duration": 0.02}},
        _kick_mode(0, 5.0), 0.03, {}),
    "pair-space-damping-table": (
        {"sliders": PAIR, "disc": {"damping_ratio": 0.01, "damping_frame": "space"},
         "friction": {"law": "table", "static": 0.7, "speeds": [0.0, 0.1, 0.3, 0.6, 1.0],
                      "values": [0.6, 0.52, 0.45, 0.42, 0.41]}},
        None, SPAN, {}),
    # tests/test_family.py
    "faces-identical-pads": ({"sliders": [{"face": "top"}, {"face": "bottom"}]}, None, SPAN,
                             {}),
    "energy-material-damping": ({"sliders": TWO_FACES, "disc": {"damping_ratio": 0.01}},
                                _kick_mode(0, 5.0), SPAN, {"energy": True}),
    "energy-space-damping": (
        {"sliders": TWO_FACES, "disc": {"damping_ratio": 0.01, "damping_frame": "space"}},
        _kick_mode(0, 5.0), SPAN, {"energy": True}),
    "energy-decelerating": (
        {"sliders": TWO_FACES,
         "speed": {"profile": "decelerating", "initial": 10.0, "duration": 0.5}},
        _kick_mode(0, 5.0), SPAN, {"energy": True}),
    "energy-no-impact": ({"sliders": TWO_FACES, "simulation": {"impact": False}},
                         _kick_mode(0, 5.0), SPAN, {"energy": True}),
    "eight-sliders": ({"sliders": EIGHT}, _kick_mode(0, 8.0), 0.02, {"energy": True}),
    "impact-cascade": (
        {"sliders": [{"face": "top"}, {"face": "bottom", "angle": np.pi}],
         "simulation": {"min_flight_time": 1e-11}}, _kick_mode(1, 8.0), 0.01,
        {"energy": True}),
    "impact-cascade-closed-early": (
        {"sliders": [{"face": "top"}, {"face": "bottom", "angle": np.pi}],
         "simulation": {"min_flight_time": 1e-8}}, _kick_mode(1, 8.0), 0.01,
        {"energy": True}),
    "stribeck-exponent-one": (
        {"friction": {"law": "stribeck", "stribeck_velocity": 0.25, "stribeck_exponent": 1.0,
                      "viscous": 0.0}}, None, SPAN, {}),
    "table-sampled-exponential": ({"friction": _table(3.0, 41)}, None, SPAN, {}),
    # tests/test_tangent.py
    "light-one-kicked": (LIGHT_ONE, _kick_half, 0.0165, {}),
    "light-two-kicked": (LIGHT_TWO, _kick_half, 0.05, {}),
    "light-one-speed-table": (
        {**LIGHT_ONE, "speed": {"profile": "table", "times": [0.0, 0.004, 0.009, 1.0],
                                "values": [1.0, 1.0, 0.4, 0.4]}}, _kick_half, 0.014, {}),
    # tests/test_orbits.py, tests/test_lyapunov_accuracy.py
    "rigid-oscillator": (RIGID, None, SPAN, {}),
    "s33-one-slider-stribeck": (S33_ONE, None, SPAN, {}),
    "s33-three-sliders-equilibrium": (S33_THREE, None, SPAN, {}),
}

# Cases recorded plain only, and why.
PLAIN_ONLY = {
    "faces-identical-pads": "two identical pads at one angle on opposite faces switch at "
    "the same instants; the order of the two switches, which rounding decides, changes the "
    "composed saltation matrix (the flow is not differentiable there), so the tangent "
    "vectors are not defined by the algorithm alone",
}

# Example -> start of a window [s] in which it separates (from a run over [0, start]).
LATE = {"fig18a": 2.905, "fig28a": 2.205, "fig28b": 2.205}
LATE_SPAN = 0.02

# Periodic orbits: name -> (case, periodic_orbit keywords).
ORBITS = {
    "fig13": (lambda: fivdisc.load_case(examples.path("fig13")),
              {"transient": 5.0, "window": 0.05}),
    "damped-disc": (lambda: fivdisc.load_case(examples.path("damped-disc")),
                    {"transient": 1.0}),
    # Below its Hopf point in sliders.2.rotational_damping (0.041): a stable stick-slip
    # orbit of all three sliders, reached from the perturbed equilibrium.
    "three-sliders": (lambda: fivdisc.Case(**S33_THREE).replace(
        {"speed.value": 10.0, "sliders.2.rotational_damping": 0.02}), {"transient": 3.0}),
}
# h omega of the orbit shots' step cap (fivdisc.analysis.orbits uses the same).
SHOT_STEP = 0.15

# Lyapunov exponents: name -> (case, lyapunov keywords).
LYAPUNOV = {
    "fig08": (lambda: fivdisc.load_case(examples.path("fig08")),
              {"n": 1, "transient": 0.5, "duration": 1.0}),
    "s33-one-slider-stribeck": (lambda: fivdisc.Case(**S33_ONE),
                                {"n": 2, "transient": 2.0, "duration": 1.0}),
    "s33-three-sliders-equilibrium": (lambda: fivdisc.Case(**S33_THREE),
                                      {"n": 3, "transient": 2.0, "duration": 1.0}),
}


def _checked_toml(case: fivdisc.Case) -> str:
    """The case's TOML text, checked to give back the same case."""
    text = case.to_toml()
    if fivdisc.Case.from_toml(text) != case:
        raise RuntimeError(f"the case does not survive its TOML text:\n{text}")
    return text


def _seed(name: str) -> int:
    return SEED + zlib.crc32(name.encode())


def base_specs() -> list[cr.Spec]:
    """Every plain run (the tangent runs are drawn from them)."""
    specs = []
    for name in examples.available():
        path = examples.path(name)
        if "[axes]" in path.read_text(encoding="utf-8"):
            continue  # a sweep file, not a case
        case = fivdisc.load_case(path)
        model = fivdisc.build_model(case)
        specs.append(cr.Spec(name=f"example-{name}", case=_checked_toml(case),
                             y0=cr.initial_state(model), duration=SPAN,
                             output_rate=SAMPLES / SPAN, rtol=RTOL, atol=ATOL,
                             energy=case.simulation.energy_balance,
                             note=f"the packaged example {name}.toml from its start"))
    for name, start in LATE.items():
        case = fivdisc.load_case(examples.path(name))
        model = fivdisc.build_model(case)
        pre = cr.Integration(model, cr.initial_state(model), duration=start, rtol=RTOL,
                             atol=ATOL)
        pre.run_to(start)
        assert pre.status_name == "success", (name, pre.status_name)
        specs.append(cr.Spec(name=f"example-{name}-late", case=_checked_toml(case),
                             y0=pre.state, phases=cr.phases_of(pre), duration=LATE_SPAN,
                             output_rate=SAMPLES / LATE_SPAN, rtol=RTOL, atol=ATOL,
                             note=f"the packaged example {name}.toml from the state its "
                                  f"run reached at {start} s (rtol {RTOL:g}): its speed "
                                  "is constant, so the window starts at t = 0"))
    for name, (tables, start, span, extra) in SUITE.items():
        case = fivdisc.Case(**tables)
        model = fivdisc.build_model(case)
        y0 = cr.initial_state(model) if start is None else start(model)
        specs.append(cr.Spec(name=name, case=_checked_toml(case), y0=y0, duration=span,
                             output_rate=SAMPLES / span, rtol=RTOL, atol=ATOL, **extra))
    return specs


def with_tangents(spec: cr.Spec, k: int) -> cr.Spec:
    """``spec`` with ``k`` random tangent vectors: normal deviates in the energy-scaled
    state (``core_replay.state_scales``), each of unit norm there."""
    model = cr.model_of(spec)
    seed = _seed(f"{spec.name}/{k}")
    v = np.random.default_rng(seed).standard_normal((k, model.state_size))
    v /= np.linalg.norm(v, axis=1)[:, None]
    return cr.Spec(**{**spec.__dict__, "tangents0": v * cr.state_scales(model)[None, :],
                      "seed": seed})


def orbit_shot(name: str, case: fivdisc.Case, orbit) -> cr.Spec:
    """One period from the orbit's point with the identity as tangent vectors, as
    fivdisc.periodic_orbit shoots (rtol 1e-12, atol 1e-19, steps capped)."""
    model = fivdisc.build_model(case)
    cap = cr.tangent_step(model, SHOT_STEP)
    if case.simulation.max_step > 0:
        cap = min(cap, case.simulation.max_step)
    return cr.Spec(name=f"orbit-{name}", case=_checked_toml(case), y0=orbit.state,
                   phases=np.asarray(orbit.phases, dtype=np.int64), duration=orbit.period,
                   output_rate=SAMPLES / orbit.period, rtol=1e-12, atol=1e-19,
                   max_step=cap, tangents0=np.eye(model.state_size),
                   note="one period of the orbit fivdisc.periodic_orbit found, from its "
                        "point, with the identity as tangents: the final tangents are the "
                        "monodromy's columns")


def _commit() -> tuple[str, bool]:
    def git(*args):
        return subprocess.run(["git", *args], capture_output=True, text=True, check=True,
                              cwd=HERE).stdout.strip()
    return git("rev-parse", "HEAD"), bool(git("status", "--porcelain", "--", "src"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dry-run", action="store_true", help="print, write nothing")
    parser.add_argument("--output", type=Path, default=cr.DATA)
    args = parser.parse_args()

    commit, dirty = _commit()
    if dirty and not args.dry_run:
        raise SystemExit("src/ has uncommitted changes: record from a clean checkout, so "
                         "that the file's commit is what was run")
    import numba

    meta: dict = {
        "what": "fivdisc's numba kernel recorded as the reference for the C++ core "
                "(issue 37, item 4); tests/core/test_recorded_reference.py compares",
        "commit": commit,
        "recorded": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "versions": {"python": sys.version.split()[0], "numpy": np.__version__,
                     "numba": numba.__version__},
        "script": "tests/data/record_core_reference.py",
        "runs": {}, "orbits": {}, "lyapunov": {},
    }
    arrays: dict[str, np.ndarray] = {}

    def record(key: str, spec: cr.Spec, samples_of: str | None = None) -> cr.Record:
        """Run ``spec`` and keep it under ``key``; with ``samples_of``, the key of a run
        of the same trajectory (the plain run of the same start: tangent vectors do not
        change the steps), whose samples stand for this run's instead of a copy."""
        start = time.perf_counter()
        rec = cr.replay(spec)
        wall = time.perf_counter() - start
        kinds = cr.event_kinds(rec.event_rows)
        count = {k: kinds.count(k) for k in dict.fromkeys(kinds)}
        print(f"{key:58s} {rec.status:8s} {rec.steps:6d} steps {len(kinds):4d} events "
              f"{wall:6.3f} s {count}", flush=True)
        meta["runs"][key] = {**spec.meta(), "status": rec.status, "t_end": rec.t_end,
                             "steps": rec.steps, "wall_time": round(wall, 4),
                             "samples_of": samples_of or key}
        arrays[f"{key}/y0"] = spec.y0
        if spec.tangents0 is not None:
            arrays[f"{key}/tangents0"] = spec.tangents0
        for what, value in rec.arrays().items():
            if samples_of and what in ("samples", "aux"):
                kept = arrays[f"{samples_of}/{what}"]
                if not np.array_equal(value, kept):
                    raise RuntimeError(f"{key}: the tangent vectors changed the trajectory")
                continue
            arrays[f"{key}/{what}"] = value
        return rec

    meta["plain_only"] = PLAIN_ONLY
    for spec in base_specs():
        record(f"{spec.name}/plain", spec)
        if spec.name in PLAIN_ONLY:
            continue
        for k in TANGENTS:
            record(f"{spec.name}/tangents-{k}", with_tangents(spec, k),
                   samples_of=f"{spec.name}/plain")

    for name, (make, kwargs) in ORBITS.items():
        case = make()
        start = time.perf_counter()
        orbit = fivdisc.periodic_orbit(case, **kwargs)
        wall = time.perf_counter() - start
        print(f"orbit {name}: period {orbit.period:.12g} s, {orbit.iterations} iterations, "
              f"residual {orbit.residual:.2e}, {orbit.verdict}, {wall:.1f} s; "
              f"|multipliers| {np.round(orbit.moduli, 6)}", flush=True)
        meta["orbits"][name] = {"case": _checked_toml(case), "kwargs": kwargs,
                                "period": orbit.period, "trivial": orbit.trivial,
                                "iterations": orbit.iterations, "residual": orbit.residual,
                                "verdict": orbit.verdict, "wall_time": round(wall, 2)}
        arrays[f"orbit/{name}/multipliers"] = orbit.multipliers
        arrays[f"orbit/{name}/state"] = orbit.state
        arrays[f"orbit/{name}/phases"] = np.asarray(orbit.phases, dtype=np.int64)
        shot = record(f"orbit-{name}/monodromy", orbit_shot(name, case, orbit))
        meta["runs"][f"orbit-{name}/monodromy"]["orbit"] = name
        arrays[f"orbit-{name}/monodromy/multipliers"] = np.linalg.eigvals(shot.tangents.T)

    for name, (make, kwargs) in LYAPUNOV.items():
        case = make()
        start = time.perf_counter()
        spec = fivdisc.lyapunov(case, **kwargs, seed=0)
        wall = time.perf_counter() - start
        print(f"lyapunov {name}: {spec.exponents} +- {spec.uncertainty}, {wall:.1f} s",
              flush=True)
        meta["lyapunov"][name] = {"case": _checked_toml(case), "kwargs": {**kwargs, "seed": 0},
                                  "wall_time": round(wall, 2)}
        arrays[f"lyapunov/{name}/exponents"] = spec.exponents
        arrays[f"lyapunov/{name}/uncertainty"] = spec.uncertainty

    if args.dry_run:
        return
    cr.save(args.output, meta, arrays)
    print(f"wrote {args.output} ({args.output.stat().st_size / 1e6:.2f} MB, "
          f"{len(meta['runs'])} runs) at {commit}")


if __name__ == "__main__":
    main()
