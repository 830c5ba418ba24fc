"""The sliding equilibrium and its slip Jacobian at points of parameter space.

Maps, eigenvalue branches, Hopf points and stability boundaries all evaluate one case at
many values of a few numeric keys. :class:`ParameterPoints` does that for all of them: it
checks the keys once, builds the model once and patches it per point where the key
enters the kernel only through a value it holds (speed, a slider's damping, stiffness or
preload, a friction parameter), and reuses an equilibrium wherever the patched values
cannot change it (the sliders' dampers).
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import cache

import numpy as np

from fivdisc import core
from fivdisc.case import Case
from fivdisc.engine.equilibrium import Equilibrium, sliding_equilibrium, slip_phases
from fivdisc.errors import CaseError, SimulationError
from fivdisc.model import layout as lay
from fivdisc.model.build import Model, build_model, model_at


def reduced_indices(model: Model) -> np.ndarray:
    """Kernel-state indices of the slip equations' variables ``(q, phi, qdot, phidot)``:
    in contact the sliders' own z, zdot are slaved to the disc."""
    return _reduced(model.n, model.n_sliders)


@cache
def _reduced(n: int, ns: int) -> np.ndarray:
    half = n + 2 * ns
    return np.r_[0 : n + ns, half : half + n + ns]


def slip_jacobian(model: Model, state: np.ndarray) -> np.ndarray:
    """Exact (complex-step) Jacobian of the slip equations (s = +1 for every slider) at
    ``state``, in the variables ``(q, phi, qdot, phidot)``."""
    ph, sg = slip_phases(model)
    jac = core.jacobian(core.core_model(model), 0.0, state, ph, sg)
    idx = reduced_indices(model)
    return jac[idx][:, idx]


def check_keys(case: Case, keys: Sequence[str], options: Sequence[str]) -> None:
    """One-line errors for keys a parameter scan cannot vary.

    Parameters
    ----------
    case : Case
        The base case.
    keys : sequence of str
        Dotted case keys.
    options : sequence of str
        What names each key in a message (``"--x"``, ``"x"``, ...).

    Raises
    ------
    CaseError
        A key that this case does not have, whose value is not a number, or that is
        given twice.
    """
    seen: dict[str, str] = {}
    for key, option in zip(keys, options, strict=True):
        value = case.get(key)
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise CaseError(f"{option} = {key} is invalid: its value {value!r} is not a number; "
                            "a scan varies numeric keys only")
        if key in seen:
            raise CaseError(f"{option} = {key} is invalid: {seen[key]} varies the same key; "
                            "give each axis its own key")
        seen[key] = option


def check_values(option: str, key: str, values: np.ndarray) -> np.ndarray:
    """The values of one axis as floats, refused if they span no interval."""
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or values.size < 2 or not np.all(np.isfinite(values)):
        raise CaseError(f"{option} = {key}: needs at least 2 finite values, got "
                        f"{np.size(values)}")
    if values[0] == values[-1]:
        raise CaseError(f"{option} = {key}: the range {values[0]:g} to {values[-1]:g} is "
                        "empty: give two different ends")
    return values


def check_box(case: Case, axes: Sequence[tuple[str, np.ndarray]]) -> None:
    """Every axis value, alone and at the box's corners, must give a valid case (the
    case's own message names the key, the value and what is allowed)."""
    for key, values in axes:
        for v in values:
            case.replace({key: float(v)})
    corners = np.array(np.meshgrid(*[[v[0], v[-1]] for _, v in axes])).reshape(len(axes), -1)
    for combo in corners.T:
        case.replace({key: float(v) for (key, _), v in zip(axes, combo, strict=True)})


def _equilibrium_key(model: Model) -> tuple:
    # The sliders' dampers do not enter the equilibrium: scans over c_z, c_phi reuse one
    # solve.
    slider = model.kernel_args.slider.copy()
    slider[[lay.S_CZ, lay.S_SCZ, lay.S_CPHI]] = 0.0
    kern = model.kernel_args._replace(slider=slider)
    return tuple(a.tobytes() for a in kern)


class ParameterPoints:
    """Equilibria and Jacobians of one case at values of a few numeric keys.

    Parameters
    ----------
    case : Case
        The base case (constant speed).
    keys : sequence of str
        Dotted case keys; a point gives one value per key, in this order.

    Notes
    -----
    The keys are checked by the caller (:func:`check_keys`, :func:`check_box`), before
    any work, so that their messages name its options.
    """

    def __init__(self, case: Case, keys: Sequence[str]) -> None:
        self.case = case
        self.keys = tuple(keys)
        self.base = build_model(case)
        self._cache: dict[tuple, Equilibrium | None] = {}

    @property
    def size(self) -> int:
        """Order of the slip Jacobian, ``2 (n + S)``."""
        return 2 * (self.base.n + self.base.n_sliders)

    def model(self, values: Sequence[float]) -> Model:
        """Model at one point, by patching the base model where that is exact."""
        updates = {key: float(v) for key, v in zip(self.keys, values, strict=True)}
        return model_at(self.base, self.case, updates)

    def equilibrium(self, model: Model, guess: Equilibrium | None = None,
                    contact: bool = True) -> Equilibrium | None:
        """Sliding equilibrium of `model` (None where there is none); see
        :func:`~fivdisc.engine.equilibrium.sliding_equilibrium` for `contact`."""
        key = (_equilibrium_key(model), contact)
        if key not in self._cache:
            try:
                self._cache[key] = sliding_equilibrium(model, guess=guess, contact=contact)
            except SimulationError:
                self._cache[key] = None
        return self._cache[key]

    def require_equilibrium(self, values: Sequence[float], option: str) -> None:
        """Refuse, in one line, a scan whose start has no sliding equilibrium.

        Raises
        ------
        CaseError
            Naming `option`, the point and why (not constant speed, contact lost, ...).
        """
        try:
            sliding_equilibrium(self.model(values))
        except SimulationError as err:
            where = ", ".join(f"{k} = {v:g}" for k, v in zip(self.keys, values, strict=True))
            raise CaseError(f"{option}: no sliding equilibrium at {where} ({err})") from None

    def linearise(self, values: Sequence[float], guess: Equilibrium | None = None
                  ) -> tuple[Model, Equilibrium, np.ndarray] | None:
        """Model, equilibrium and slip Jacobian at one point (None: no equilibrium)."""
        model = self.model(values)
        eq = self.equilibrium(model, guess)
        if eq is None:
            return None
        return model, eq, slip_jacobian(model, eq.state)

    def eigenvalues(self, values: Sequence[float], guess: Equilibrium | None = None
                    ) -> np.ndarray | None:
        """Eigenvalues [1/s] of the slip Jacobian at one point (None: no equilibrium)."""
        point = self.linearise(values, guess)
        return None if point is None else np.linalg.eigvals(point[2])
