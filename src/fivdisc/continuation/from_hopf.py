"""The periodic orbits born at a Hopf point of the sliding equilibrium, continued.

At a Hopf point (:mod:`fivdisc.analysis.hopf`) a family of small periodic orbits is born
along the critical eigenvector ``v`` with the period ``2 pi / omega``. The family is
started from the small orbit ``x0 = y_eq + eps Re(v)``, ``T = 2 pi / omega``, corrected
with its amplitude along ``Re(v)`` held and the parameter free (the first orbit then
lies at ``p(eps)``), and continued by :func:`~fivdisc.continuation.walk.continue_orbit`'s
machinery towards larger amplitudes, through folds, until the slip-speed oscillation
reaches the sliding speed and a stick phase appears (grazing: the branch either goes on
as stick-slip orbits or ends there, saying so).

Which side of the Hopf value the small orbits lie on decides the Hopf point's kind:
on the side where the equilibrium is unstable it is supercritical (small stable orbits,
the vibration grows gently from zero), on the stable side subcritical (small unstable
orbits: a threshold around a stable equilibrium, and a jump to a large vibration where
the equilibrium loses stability).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from fivdisc.analysis.hopf import HopfPoint
from fivdisc.analysis.kinds import BifurcationKind as Kind
from fivdisc.continuation.branch import Branch
from fivdisc.continuation.checks import check_target
from fivdisc.continuation.problem import OrbitProblem
from fivdisc.continuation.settings import ContinuationSettings
from fivdisc.continuation.starts import hopf_start
from fivdisc.continuation.walk import run_walk
from fivdisc.errors import FivdiscError
from fivdisc.model.build import build_model

__all__ = ["hopf_cycles"]


def grazing_amplitude(hopf: HopfPoint) -> float:
    """The amplitude ``eps`` along ``Re(v)`` at which the linear orbit's slip-speed
    oscillation ``eps |v_phidot|`` reaches the sliding speed ``Omega`` for the first
    slider: where, to first order, a stick phase appears."""
    model = build_model(hopf.case)
    rates = [abs(hopf.eigenvector[model.index("phi_dot", j)])
             for j in range(model.n_sliders)]
    return float(abs(hopf.case.speed.value) / max(max(rates), 1e-300))


def hopf_cycles(
    hopf: HopfPoint,
    to: float,
    *,
    amplitude: float = 0.01,
    settings: ContinuationSettings | None = None,
    progress: bool = False,
    **options: Any,
) -> Branch:
    """Start the periodic orbits born at a Hopf point and continue them.

    Parameters
    ----------
    hopf : HopfPoint
        From :func:`~fivdisc.analysis.hopf.hopf_points`.
    to : float
        A value of ``hopf.key`` where the continuation stops if the branch gets there
        [the key's unit] (the branch's direction is set by the orbits, not by `to`).
    amplitude : float
        Size of the first orbit, as a fraction of the linear orbit that would graze the
        stick boundary (slip-speed oscillation equal to the sliding speed) [-]:
        ``eps = amplitude * Omega / |v_phidot|``. In (0, 0.5].
    settings, progress, **options
        As :func:`~fivdisc.continuation.walk.continue_orbit` (``options``: fields of
        :class:`~fivdisc.continuation.settings.ContinuationSettings` only); the unknowns'
        scale is the grazing orbit, so a step of 0.02 takes about 2 % of the way to
        grazing.

    Returns
    -------
    Branch
        The branch of orbits from the Hopf point, with attributes ``hopf_value``,
        ``hopf_omega``, ``hopf_direction``, ``criticality`` (``"subcritical"`` or
        ``"supercritical"``, by the side the orbits lie on), ``hopf_l1`` and
        ``hopf_l1_error`` (the point's first Lyapunov coefficient [s^2], whose sign
        says the same for small orbits) and ``bistable_low``, ``bistable_high`` (nan if there is no
        bistable range) in its dataset, printed by ``str`` (see :meth:`Branch.hopf`).

    Raises
    ------
    FivdiscError
        A bad argument (one line, before any work).
    ConvergenceError
        The first orbit does not converge (take a smaller `amplitude`).

    See Also
    --------
    fivdisc.hopf_points : The Hopf points of the sliding equilibrium along a key.
    fivdisc.periodic_orbit : One orbit by shooting, from a transient run.
    fivdisc.continue_orbit : A branch from an orbit found by shooting (a stick-slip
        orbit, say) instead of from a Hopf point.

    Notes
    -----
    The first orbit solves, for ``(x, T, p)``, the shooting equations
    ``phi_T(x; p) = x``, the phase condition and ``w . (z - z_eq) = eps |w|``, with
    ``w`` the scaled ``Re(v)``. Near the Hopf point ``p(eps) - p_H = c eps^2``: the sign
    of ``c`` against the side where the equilibrium is unstable gives the kind (that of
    the first Lyapunov coefficient ``l1``: ``c`` has the sign of ``-l1 / (d Re lambda /
    dp)``). The bistable range is where the equilibrium is stable and a stable orbit of
    the branch exists: from the Hopf value to the farthest stable orbit on the
    equilibrium's stable side (a fold of cycles, at its located value), or at least to
    where unstable
    slipping orbits on that side graze the stick boundary. There stick-slip orbits
    begin, and the unstable orbits separate the equilibrium's basin from them; the
    stick-slip orbits themselves are not continued here and may coexist with the
    equilibrium beyond the grazing value, so that end of the range is then a bound
    only (``bistable_open``; continue a stick-slip orbit there with
    :func:`~fivdisc.continuation.walk.continue_orbit` to find where it ends). A
    subcritical branch that stops before its orbits fold or graze leaves the range
    undetermined (``bistable_undetermined``): its unstable orbits bound the equilibrium's
    basin, and the motion beyond them may be a stable vibration coexisting with it. The
    equilibrium's stability beyond other Hopf points of the key is not checked.

    Examples
    --------
    A slider on a rigid disc (no modes): sliding turns stable above the Hopf point at
    9.1629 rad/s, and the small slipping orbits born there lie on that side and are
    unstable, a subcritical Hopf point. Their speed offset follows the averaged
    closed form ``Omega - Omega_H = r alpha V^2 / 8`` in their rate amplitude ``V``, and
    their period starts at ``2 pi / omega``:

    >>> import numpy as np
    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5})
    >>> (hopf,) = fivdisc.hopf_points(rigid, "speed.value", np.linspace(1.0, 19.0, 7))
    >>> cycles = fivdisc.hopf_cycles(hopf, 19.0, max_points=3)
    >>> cycles.hopf()["criticality"], bool(cycles.stable.any())
    ('subcritical', False)
    >>> ds = cycles.dataset
    >>> rate = 0.5 * float(ds["phi_dot_max"][0, 0] - ds["phi_dot_min"][0, 0])  # V [rad/s]
    >>> print(f"{cycles.parameter[0] - hopf.value:.2e} {0.1 * rate**2 / 8:.2e}")
    1.05e-04 1.05e-04
    >>> print(f"{cycles.period[0] / (2 * np.pi / hopf.omega):.6f}")
    1.000000
    """
    if not (np.isfinite(amplitude) and 0 < amplitude <= 0.5):
        raise FivdiscError(f"amplitude = {amplitude!r} is invalid: must be in (0, 0.5], a "
                           "fraction of the grazing orbit's size")
    settings = ContinuationSettings.of(settings, options)
    if options:
        raise FivdiscError(f"{sorted(options)[0]} is not an option of hopf_cycles: the "
                           "options are amplitude, settings, progress and the fields of "
                           "ContinuationSettings")
    case, key = hopf.case, hopf.key
    check_target(case, key, to)
    size = grazing_amplitude(hopf)
    model = build_model(case)
    problem = OrbitProblem(case, key, np.zeros(model.n_sliders, dtype=np.int64), hopf.period,
                           settings)
    direction = hopf.eigenvector.real

    def first(deadline: float):
        return hopf_start(problem, hopf.state, direction, amplitude * size, size, deadline)

    result = run_walk(problem, first, to, settings, progress,
                      f"at the Hopf point {key} = {hopf.value:.10g}, amplitude {amplitude:g} "
                      "of grazing")
    _judge(result, hopf)
    return result


def restate_hopf(result: Branch, source: Branch) -> None:
    """Give `result`, which continues `source` (a branch from
    :func:`hopf_cycles`, or itself such a continuation), the Hopf point's kind and the
    bistable range over both branches' orbits (what ``fivdisc continue --from hopf.nc``
    prints); nothing if `source` is not from a Hopf point."""
    import types

    info = source.hopf()
    if info is None:
        return
    hopf = types.SimpleNamespace(**{k: info[k] for k in (
        "value", "omega", "direction", "on_boundary", "mode", "unstable_modes", "l1",
        "l1_error")})
    _judge(result, hopf, earlier=info)
    result.dataset.attrs["hopf_continued"] = 1


def _judge(result: Branch, hopf: Any, earlier: dict[str, Any] | None = None) -> None:
    """The Hopf point's kind and the bistable range, in the branch's attributes; for a
    branch that continues another from the Hopf point, `earlier` is that one's
    :meth:`~fivdisc.continuation.branch.Branch.hopf`: its kind stands, and its range
    joins this branch's."""
    p = result.parameter
    unstable_side = float(hopf.direction)
    side = np.sign(p[0] - hopf.value)
    kind = "supercritical" if side == unstable_side else "subcritical"
    if earlier is not None:
        kind = earlier["criticality"]
    # Orbits on the side where the equilibrium is stable, and stable themselves.
    stable_side = (p - hopf.value) * unstable_side < 0
    coexist = list(p[result.stable & stable_side])
    # Unstable slipping orbits that graze on the stable side: stick-slip orbits coexist
    # with the equilibrium from there to the Hopf value, and may reach beyond the
    # grazing value, where they are not followed: the range is then open on that side.
    grazing = [b["parameter"] for b in result.bifurcations()
               if b["kind"] == Kind.GRAZING and (b["parameter"] - hopf.value) * unstable_side < 0]
    # A fold next to a stable point is the farthest end of those stable orbits, located
    # more exactly than any point computed beside it.
    n = len(p)
    folds = [b["parameter"] for b in result.bifurcations()
             if b["kind"] == Kind.FOLD and (b["parameter"] - hopf.value) * unstable_side < 0
             and any(result.stable[i] for i in (b["point"], b["point"] + 1) if i < n)]
    if earlier is not None and np.isfinite(earlier["bistable"][0]):
        # The earlier branch's range: its end away from the Hopf point, a bound if it was.
        low, high = earlier["bistable"]
        far = low if high == hopf.value else high
        (grazing if earlier["bistable_open"] else folds).append(far)
    coexist = np.array(coexist + grazing + folds)
    open_end = False
    if hopf.on_boundary and coexist.size:
        far = coexist[np.argmax(np.abs(coexist - hopf.value))]
        open_end = bool(far in grazing)
        low, high = sorted((float(far), hopf.value))
    else:
        low = high = np.nan
    # A subcritical point's unstable orbits bound the basin of stable sliding; until the
    # branch folds or grazes, what lies beyond them (and whether it is a stable
    # vibration) is not known: the range is undetermined, not absent.
    undetermined = bool(hopf.on_boundary and kind == "subcritical" and not coexist.size)
    result.dataset.attrs.update({"hopf_value": hopf.value, "hopf_omega": hopf.omega,
                                 "hopf_direction": hopf.direction, "criticality": kind,
                                 "hopf_l1": getattr(hopf, "l1", np.nan),
                                 "hopf_l1_error": getattr(hopf, "l1_error", np.nan),
                                 "bistable_low": low, "bistable_high": high,
                                 "bistable_open": int(open_end),
                                 "bistable_undetermined": int(undetermined),
                                 "hopf_on_boundary": int(hopf.on_boundary),
                                 "hopf_mode": str(getattr(hopf, "mode", "")),
                                 "hopf_unstable_modes": ", ".join(
                                     getattr(hopf, "unstable_modes", ()))})
