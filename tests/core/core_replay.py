"""How a run of the recorded core reference is made, shared by the script that records it
(``tests/data/record_core_reference.py``) and the test that replays it
(``tests/core/test_recorded_reference.py``), so that both make exactly the same calls.

A run is a case (its TOML text), a start state and phases, a span, tolerances and
optionally tangent vectors at the start. It is driven as :func:`fivdisc.simulate` drives
its runs: a first call with target 0 (the start: the phases chosen, the first step),
then ``CHUNKS`` equal targets, each reached by :meth:`Integration.run_to`. The targets
matter: each call ends past its target, and the next one restarts the step-size
controller's memory and the in-step dip prediction, so the same run driven otherwise
takes other steps.

Everything taken from fivdisc's internals is imported in the block below and nowhere
else in the reference's files: when the package is reorganised
(``fivdisc.integration`` -> ``fivdisc.engine.integration``, ...), only this block
changes.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import fivdisc

# --- fivdisc internals: the only imports of non-public modules -------------------------
from fivdisc.analysis.orbits import energy_scales
from fivdisc.engine.integration import Integration, tangent_step  # noqa: F401  (tangent_step: recorder)
from fivdisc.engine.result import EVENT_KINDS
from fivdisc.engine.simulation import initial_state  # noqa: F401  (the recorder's start states)


def state_scales(model: fivdisc.Model) -> np.ndarray:
    """Per state coordinate, the size whose energy is 1 J (``1 / sqrt(stiffness)`` for a
    displacement, ``1 / sqrt(inertia)`` for a rate): states divided by it are compared in
    one unit, as fivdisc's orbits measure distances."""
    return energy_scales(model)


def phases_of(run: Integration) -> np.ndarray:
    """Each slider's phase (0 slip, 1 stick, 2 separation) where ``run`` stands."""
    return np.asarray(run.ph, dtype=np.int64).copy()


def samples_of(run: Integration) -> tuple[np.ndarray, np.ndarray]:
    """The output rows written: the state with the energy accumulators, and the auxiliary
    columns (per slider N, f, phase, w under it, then the disc speed)."""
    n = run.n_samples
    return run.out_y[:n].copy(), run.out_aux[:n].copy()
# ---------------------------------------------------------------------------------------


DATA = Path(__file__).resolve().parent.parent / "data" / "core_reference.npz"
# Calls after the start, as fivdisc.simulate makes (it makes 200; 10 keep the calls
# over a short span from being mostly call overhead, and still cross call boundaries).
CHUNKS = 10


@dataclass
class Spec:
    """Everything that defines one run (kept in the file's metadata and arrays)."""

    name: str
    case: str  # TOML text
    y0: np.ndarray
    duration: float
    output_rate: float
    rtol: float
    atol: float
    energy: bool = False
    phases: np.ndarray | None = None
    max_step: float | None = None
    stop_on: tuple[str, ...] = ()
    tangents0: np.ndarray | None = None  # (k, nd) rows, or None for a plain run
    chunks: int = CHUNKS
    seed: int | None = None  # of the random tangent vectors at the start
    note: str = ""

    def meta(self) -> dict:
        return {"name": self.name, "case": self.case, "duration": self.duration,
                "output_rate": self.output_rate, "rtol": self.rtol, "atol": self.atol,
                "energy": self.energy, "max_step": self.max_step,
                "stop_on": list(self.stop_on), "chunks": self.chunks, "seed": self.seed,
                "note": self.note,
                "phases": None if self.phases is None else [int(p) for p in self.phases],
                "n_tangents": 0 if self.tangents0 is None else int(self.tangents0.shape[0])}


@dataclass
class Record:
    """What a run gives: the event table, the output samples, the end, the tangents."""

    event_times: np.ndarray
    event_rows: np.ndarray  # (kind, from phase, to phase, slider)
    samples: np.ndarray  # output rows of the state, energy accumulators included
    aux: np.ndarray  # output rows of N, f, phase, w under each slider, then Omega
    end_state: np.ndarray
    t_end: float
    status: str
    steps: int  # steps tried (recorded for information, not compared)
    tangents: np.ndarray | None = None  # final tangent vectors (rows), slaved
    extra: dict = field(default_factory=dict)

    def arrays(self) -> dict[str, np.ndarray]:
        out = {"event_times": self.event_times, "event_rows": self.event_rows,
               "samples": self.samples, "aux": self.aux, "end_state": self.end_state}
        if self.tangents is not None:
            out["tangents"] = self.tangents
        return out


def model_of(spec: Spec) -> fivdisc.Model:
    return fivdisc.build_model(fivdisc.Case.from_toml(spec.case))


def replay(spec: Spec) -> Record:
    """Run ``spec`` with the current kernel."""
    model = model_of(spec)
    run = Integration(model, spec.y0, duration=spec.duration, output_rate=spec.output_rate,
                      stop_on=spec.stop_on, energy=spec.energy, rtol=spec.rtol,
                      atol=spec.atol, max_step=spec.max_step, phases=spec.phases)
    if spec.tangents0 is not None:
        run.set_tangents(spec.tangents0)
    run.advance(0.0)
    for k in range(1, spec.chunks + 1):
        run.run_to(spec.duration * k / spec.chunks)
        if run.status_name != "running":  # the end, a stop or a failure
            break
    times, rows = run.events()
    samples, aux = samples_of(run)
    return Record(event_times=times, event_rows=np.asarray(rows, dtype=np.int64),
                  samples=samples, aux=aux, end_state=run.state, t_end=run.t,
                  status=run.status_name, steps=run.steps_tried,
                  tangents=None if spec.tangents0 is None else run.tangents())


def event_kinds(rows: np.ndarray) -> list[str]:
    return [EVENT_KINDS[int(k)] for k in rows[:, 0]]


# --- the file ------------------------------------------------------------------------


def save(path: Path, meta: dict, arrays: dict[str, np.ndarray]) -> None:
    """One compressed ``.npz``: ``meta`` as JSON text under ``"meta"``, the arrays under
    their keys (no pickled objects, so it loads with ``allow_pickle=False``)."""
    np.savez_compressed(path, meta=np.array(json.dumps(meta, indent=1)), **arrays)


def load(path: Path = DATA) -> tuple[dict, dict[str, np.ndarray]]:
    with np.load(path, allow_pickle=False) as f:
        arrays = {k: f[k] for k in f.files}
    meta = json.loads(str(arrays.pop("meta")))
    return meta, arrays


def spec_from(meta: dict, arrays: dict[str, np.ndarray], key: str) -> Spec:
    """The spec of the recorded run ``key`` (its arrays are ``key + "/..."``)."""
    m = meta["runs"][key]
    return Spec(name=m["name"], case=m["case"], y0=arrays[f"{key}/y0"],
                duration=m["duration"], output_rate=m["output_rate"], rtol=m["rtol"],
                atol=m["atol"], energy=m["energy"],
                phases=None if m["phases"] is None else np.array(m["phases"], np.int64),
                max_step=m["max_step"], stop_on=tuple(m["stop_on"]),
                tangents0=arrays.get(f"{key}/tangents0"), chunks=m["chunks"], seed=m["seed"],
                note=m["note"])
