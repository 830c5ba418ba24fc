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
from typing import NamedTuple

import numpy as np

from fivdisc.case import Case
from fivdisc.engine.equilibrium import Equilibrium, sliding_equilibrium, slip_phases
from fivdisc.engine.evaluation import jacobian
from fivdisc.errors import AnalysisError, CaseError, FivdiscError, SimulationError
from fivdisc.limits import duration_words
from fivdisc.model.build import Model, build_model, model_at

#: Fastest rate [1/s] of a model whose linearisation is analysed. The eigenvalues are
#: computed to about 2.2e-16 times the largest of them: 2e-4 1/s here, so that growth
#: rates of order 1/s still decide stability. Beyond it they are round-off (measured on
#: Table 1: the disc modes' growth rates hold to 1e-6 up to a slider damping rate of
#: 1e15 1/s, change sign at 1e17 and are noise at 1e23, with Hopf points "at 0 Hz").
#: A physical brake's fastest rate is below 1e7 1/s.
MAX_RATE = 1e12
# Case keys behind the names in the slider rates of
# fivdisc.engine.integration.time_scales (the inertia is mass * track_radius^2).
_RATE_KEYS = {"inertia": ("mass", "track_radius")}


def model_rates(model: Model) -> list[tuple[str, float]]:
    """The rates [1/s] of :func:`fivdisc.engine.integration.time_scales` and the disc's
    spin at its largest speed, times the largest nodal-diameter count (at least 1)."""
    from fivdisc.engine.integration import time_scales

    omega = abs(float(np.max(np.abs(model.speed.omega(np.array([0.0]))))))
    turns = max(1, int(np.max(model.l, initial=0)))
    with np.errstate(all="ignore"):
        spin = omega * turns
    return [*time_scales(model),
            (f"speed.value: the disc's spin times {turns} (its largest nodal-diameter count, "
             "at least 1)", spin)]


def _rate_settings(case: Case, what: str) -> str:
    """The case's keys and values behind one rate of :func:`model_rates`, in words."""
    import re

    head, _, expression = what.partition(": ")
    if head in ("slider",) or head.startswith("sliders."):
        names = [n for n in re.findall(r"[a-z_]+", expression) if n != "sqrt"]
        keys = [k for n in names for k in _RATE_KEYS.get(n, (n,))]
        shown = [f"{head}.{k} = {case.get(f'{head}.{k}')!r}" for k in dict.fromkeys(keys)]
        return f" ({', '.join(shown)})"
    if head == "speed.value":
        return f" (speed.value = {case.get('speed.value')!r} rad/s)" if (
            case.speed.profile == "constant") else ""
    if what.startswith("disc.damping_ratio"):
        return f" (disc.damping_ratio = {case.disc.damping_ratio!r})"
    return ""


def check_rates(model: Model, where: str = "") -> None:
    """Refuse a model whose linearisation cannot decide stability: a rate of
    :func:`model_rates` that is not finite or exceeds :data:`MAX_RATE`.

    Parameters
    ----------
    model
        The model (of a constant-speed case).
    where
        Prefixes the message (e.g. ``"--x slider.normal_damping = 1e+20: "``).

    Raises
    ------
    AnalysisError
        Naming the rate, the keys and values that set it, and what is allowed.
    """
    for what, rate in model_rates(model):
        if not rate <= MAX_RATE:
            raise AnalysisError(
                f"{where}{what} = {rate:.3g} 1/s{_rate_settings(model.case, what)} is out of "
                f"range for a stability analysis: must be <= {MAX_RATE:g} 1/s (the "
                "eigenvalues are computed to about 2.2e-16 times the fastest rate of the "
                "model, so beyond it the growth rates that decide stability are round-off); "
                "change that parameter"
            )


def check_jacobian(model: Model, state: np.ndarray, jac: np.ndarray, where: str = "") -> None:
    """Refuse a slip Jacobian (`jac`, at `state`) that is not finite, naming its first
    such entry, and the friction law's settings when the law is the cause (the Jacobian
    of the same model with constant friction is finite: the law's slope is out of
    range)."""
    bad = np.argwhere(~np.isfinite(jac))
    if bad.size == 0:
        return
    i, j = (int(v) for v in bad[0])
    angles = (["phi"] if model.n_sliders == 1
              else [f"phi{k}" for k in range(model.n_sliders)])
    names = [*model.labels, *angles, *(f"{v}_dot" for v in (*model.labels, *angles))]
    entry = f"d({names[i]})'/d({names[j]}) = {jac[i, j]}"
    law = model.case.friction
    if _finite_without_the_law(model, state):
        shown = ", ".join(f"friction.{k} = {v!r}" for k, v in law.model_dump().items()
                          if k not in ("law", "static") and isinstance(v, float | int))
        cause = (f"the slope of the friction law ({law.law}) at the sliding speed is out of "
                 f"floating-point range ({shown}); change those parameters")
    else:
        cause = ("a parameter of the case is out of the range doubles resolve; change the "
                 "extreme one")
    raise AnalysisError(f"{where}the linearised slip equations are not finite ({entry}): "
                        f"{cause}")


def _finite_without_the_law(model: Model, state: np.ndarray) -> bool:
    """Whether the slip Jacobian at `state` is finite with the friction law replaced by
    constant kinetic friction (the static coefficient's)."""
    law = model.case.friction
    if law.law == "exponential" and law.decay == 0.0:
        return False  # constant already
    plain = {"law": "exponential", "static": law.static, "kinetic_max": law.static,
             "kinetic_min": law.static, "decay": 0.0}
    try:
        other = build_model(model.case.replace({"friction": plain}))
    except FivdiscError:
        return False
    return bool(np.isfinite(slip_jacobian(other, state)).all())


def reduced_indices(model: Model) -> np.ndarray:
    """Kernel-state indices of the slip equations' variables ``(q, phi, qdot, phidot)``:
    in contact the sliders' own z, zdot are slaved to the disc."""
    sl = model.slices
    return np.r_[sl.q, sl.phi, sl.q_dot, sl.phi_dot]


def slip_jacobian(model: Model, state: np.ndarray) -> np.ndarray:
    """Exact (complex-step) Jacobian of the slip equations (s = +1 for every slider) at
    ``state``, in the variables ``(q, phi, qdot, phidot)``."""
    ph, sg = slip_phases(model)
    jac = jacobian(model, state, ph, sg)
    idx = reduced_indices(model)
    return jac[idx][:, idx]


#: A scan estimated to take longer than this [s] says so before it starts (a
#: :class:`~fivdisc.errors.FivdiscWarning` with the estimate).
LONG_SCAN = 60.0
# Scans of fewer points are not timed beforehand (a point takes milliseconds).
_TIMED_SCAN = 1000


def warn_if_long(points: ParameterPoints, values: Sequence[float], count: int,
                 what: str, fewer: str) -> None:
    """Warn (:class:`~fivdisc.errors.FivdiscWarning`) before a scan of `count` points
    whose time, measured on one point at `values`, exceeds :data:`LONG_SCAN`. `what`
    names the scan, `fewer` what takes less time."""
    import time
    import warnings

    from fivdisc.errors import FivdiscWarning

    if count < _TIMED_SCAN:
        return
    seconds = []
    for _ in range(2):  # the first may load the kernel
        start = time.perf_counter()
        point = points.linearise(values)
        if point is not None:
            np.linalg.eigvals(point[2])
        seconds.append(time.perf_counter() - start)
    total = count * seconds[-1]
    if total > LONG_SCAN:
        warnings.warn(f"{what} ({count:,} points) will take about {duration_words(total)} "
                      f"({seconds[-1] * 1e3:.2g} ms a point, measured on its first); "
                      f"{fewer} take less", FivdiscWarning, stacklevel=3)


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
        A key that this case does not have, whose value is not a number, that is a
        simulation setting (the linearisation does not depend on it), or that is given
        twice.
    """
    seen: dict[str, str] = {}
    for key, option in zip(keys, options, strict=True):
        if key.startswith("simulation."):
            raise CaseError(f"{option} = {key} is invalid: the simulation settings do not "
                            "change the sliding equilibrium or its eigenvalues, so a scan "
                            "of them repeats one answer; vary a key of disc, slider(s), "
                            "friction or speed")
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


def check_box(case: Case, axes: Sequence[tuple[str, np.ndarray]],
              options: Sequence[str] = ()) -> None:
    """Every axis value, alone and at the box's corners, must give a valid case (the
    case's own message names the key, the value and what is allowed), and at every corner
    of the box of the axes' smallest and largest values the model's rates must allow a
    stability analysis (:func:`check_rates`: each rate grows or falls with each key, so
    the corners hold the fastest); `options` name the axes in that message."""
    for key, values in axes:
        for v in values:
            case.replace({key: float(v)})
    corners = np.array(np.meshgrid(*[[v[0], v[-1]] for _, v in axes])).reshape(len(axes), -1)
    for combo in corners.T:
        case.replace({key: float(v) for (key, _), v in zip(axes, combo, strict=True)})
    ends = np.array(np.meshgrid(*[[np.min(v), np.max(v)] for _, v in axes])
                    ).reshape(len(axes), -1)
    names = [*options, *[""] * len(axes)][: len(axes)]
    for combo in np.unique(ends.T, axis=0):
        updates = {key: float(v) for (key, _), v in zip(axes, combo, strict=True)}
        where = ", ".join(f"{name} {key} = {v:g}".strip()
                          for name, (key, v) in zip(names, updates.items(), strict=True))
        check_rates(build_model(case.replace(updates)), f"at {where}: ")


def _equilibrium_key(model: Model) -> tuple:
    # The sliders' dampers do not enter the equilibrium: scans over c_z, c_phi reuse one
    # solve.
    undamped = model.with_sliders(cz=0.0, cphi=0.0)
    return tuple(a.tobytes() for a in undamped.kernel_args)


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
        jac = slip_jacobian(model, eq.state)
        where = ", ".join(f"{k} = {v:g}" for k, v in zip(self.keys, values, strict=True))
        check_jacobian(model, eq.state, jac, f"at {where}: ")
        return model, eq, jac

    def eigenvalues(self, values: Sequence[float], guess: Equilibrium | None = None
                    ) -> np.ndarray | None:
        """Eigenvalues [1/s] of the slip Jacobian at one point (None: no equilibrium)."""
        point = self.linearise(values, guess)
        return None if point is None else np.linalg.eigvals(point[2])


class Box(NamedTuple):
    """A checked box of two keys (:func:`box_of`): each axis as (key, (start, stop)), the
    equilibria and Jacobians over it, its lower corner and its sides."""

    x: tuple[str, np.ndarray]
    y: tuple[str, np.ndarray]
    points: ParameterPoints
    lo: np.ndarray
    span: np.ndarray


def box_of(case: Case, x: tuple[str, Sequence[float]], y: tuple[str, Sequence[float]],
           seeds: int, step: float, option: str, what: str = "a box") -> Box:
    """The box ``x`` by ``y`` (each ``(key, (start, stop))``) of a case, checked before any
    work: two values per key, ``seeds >= 2`` and ``step > 0`` (the tracing's), keys that
    change the linearisation and a box the model accepts, a sliding equilibrium at its
    lower corner (``option`` names the scan in the messages, ``what`` the box)."""
    from fivdisc.errors import CaseError

    xkey, ykey = x[0], y[0]
    xr_, yr_ = check_values("x", xkey, x[1]), check_values("y", ykey, y[1])
    if len(xr_) != 2 or len(yr_) != 2:
        raise CaseError(f"{what} needs KEY=START:STOP for each key (two values)")
    if seeds < 2 or not step > 0.0:
        raise CaseError(f"seeds = {seeds}, step = {step} are invalid: need seeds >= 2 and "
                        "step > 0")
    check_keys(case, [xkey, ykey], ["x", "y"])
    check_box(case, [(xkey, xr_), (ykey, yr_)], ["x", "y"])
    points = ParameterPoints(case, [xkey, ykey])
    points.require_equilibrium((xr_[0], yr_[0]), option)
    return Box((xkey, xr_), (ykey, yr_), points, np.array([xr_[0], yr_[0]]),
               np.array([xr_[1] - xr_[0], yr_[1] - yr_[0]]))
