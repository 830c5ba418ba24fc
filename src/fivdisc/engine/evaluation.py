"""The right-hand side at one state, its exact Jacobian and the slaved rows of tangent
vectors: the compiled core's evaluations as the analyses above the engine use them, on
a :class:`~fivdisc.model.build.Model` (the core's copy of it is made once per model)."""

from __future__ import annotations

import numpy as np

from fivdisc import core
from fivdisc.model.build import Model

__all__ = ["evaluate", "jacobian", "unslaved"]


def _args(y: np.ndarray, phases: np.ndarray, signs: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return (np.asarray(y, dtype=float), np.asarray(phases, dtype=np.int64),
            np.asarray(signs, dtype=np.int64))


def evaluate(model: Model, y: np.ndarray, phases: np.ndarray, signs: np.ndarray,
             t: float = 0.0) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The right-hand side ``dy/dt`` at state ``y`` (the model's layout,
    :attr:`Model.slices`) and time ``t`` [s] with each slider in ``phases``
    (:class:`~fivdisc.model.layout.Phase`) and slip sign ``signs`` (+1: the disc faster),
    and per slider what the forces are there: ``normal_force`` [N], ``friction_force``
    [N], ``w`` (the disc's deflection under it [m]), ..."""
    return core.evaluate(core.core_model(model), float(t), *_args(y, phases, signs))


def jacobian(model: Model, y: np.ndarray, phases: np.ndarray, signs: np.ndarray,
             t: float = 0.0) -> np.ndarray:
    """The exact Jacobian ``d(dy/dt)/dy`` at ``y`` in the given phases and signs, by the
    complex step (the right-hand side's one source, on complex numbers): no truncation
    error, round-off ~1e-16 of its entries."""
    return core.jacobian(core.core_model(model), float(t), *_args(y, phases, signs))


def unslaved(model: Model, y: np.ndarray, phases: np.ndarray, signs: np.ndarray,
             vectors: np.ndarray, t: float = 0.0) -> np.ndarray:
    """Tangent ``vectors`` (rows, the model's full layout) at ``y`` with the rows the
    contact holds (an in-contact slider's z, zdot, following the disc) filled in from
    the free ones."""
    y, phases, signs = _args(y, phases, signs)
    return core.unslaved(core.core_model(model), float(t), y, phases, signs,
                         np.asarray(vectors, dtype=float))
