"""The compiled core: fivdisc's integrator and right-hand side in C++17, built when
fivdisc is installed (CMake through scikit-build-core, nanobind for the binding; the
sources are in ``src/``) and imported as the extension ``fivdisc.core._core``.

What it holds (each header of ``src/`` one part): Dormand-Prince 5(4) with dense output
(``dopri5.hpp``); the right-hand side of every phase, templated on the scalar so that the
complex-step Jacobian and tangents come from the same source (``rhs.hpp``); event
location (``events.hpp``); switches (``switch.hpp``) and the plastic impact's
complementarity problem (``impact.hpp``); tangent vectors with their saltation matrices
(``tangent.hpp``); the integrator that keeps its state between calls (``integrator.hpp``);
the binding, which checks every input before any work (``binding.cpp``).

The Python face: :class:`Integrator` (driven by :class:`fivdisc.engine.integration.
Integration`), and the evaluations the analyses use: :func:`rhs`, :func:`evaluate` (with
the per-slider normal and friction forces), :func:`jacobian` (exact, by the complex
step), :func:`jvp`, :func:`event_values`, :func:`kinetic_friction`, :func:`unslaved`,
:func:`free_mask`, :func:`single_impact`, :func:`solve_lcp`. Each takes the model as
:func:`core_model` makes it. Input the core refuses raises :class:`CoreError` (a
:class:`~fivdisc.errors.FivdiscError` and a ``ValueError``) with a one-line message.
"""

from __future__ import annotations

import weakref

from fivdisc.core._core import (
    EVENT_BUFFER,
    CoreError,
    Integrator,
    evaluate,
    event_values,
    free_mask,
    jacobian,
    jvp,
    kinetic_friction,
    rhs,
    single_impact,
    solve_lcp,
    unslaved,
)
from fivdisc.core._core import Model as CoreModel

__all__ = [
    "EVENT_BUFFER", "EVI_FROM", "EVI_KIND", "EVI_SLIDER", "EVI_TO", "N_EVI", "ST_DONE",
    "ST_MAX_SWITCHES", "ST_NONFINITE", "ST_RUNNING", "ST_STOPPED", "ST_TOO_MANY_STEPS",
    "ST_UNDERFLOW", "ST_ZENO", "CoreError", "CoreModel", "Integrator", "core_model",
    "evaluate", "event_values", "free_mask", "jacobian", "jvp", "kinetic_friction", "rhs",
    "single_impact", "solve_lcp", "unslaved",
]

# Status codes of Integrator.advance.
ST_RUNNING = 0
ST_DONE = 1
ST_NONFINITE = 2
ST_UNDERFLOW = 3
ST_ZENO = 4
ST_MAX_SWITCHES = 5
ST_STOPPED = 6
# Set by the caller (fivdisc.engine.integration), not the core: the step budget is spent.
ST_TOO_MANY_STEPS = 7

# Columns of the event rows (Integrator.take_events).
EVI_KIND = 0
EVI_FROM = 1
EVI_TO = 2
EVI_SLIDER = 3
N_EVI = 4

_models: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def core_model(model) -> CoreModel:
    """The core's checked copy of a model's arrays: of a :class:`fivdisc.model.Model`
    (made once per model and kept while it lives), or of a
    :class:`~fivdisc.model.layout.KernelModel` tuple (made afresh)."""
    kernel = getattr(model, "kernel_args", None)
    if kernel is None:
        return CoreModel(*model)
    made = _models.get(model)
    if made is None:
        made = _models[model] = CoreModel(*kernel)
    return made
