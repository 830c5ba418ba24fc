"""Slow, plain reference model of sliders on a spinning annular disc (the model family).

This module is an *independent* implementation of the model stated in
``docs/model.md`` (the printed paper has errors; that page wins): S sliders on
either face, disc damping and several friction laws.  It exists to check the package's fast
(compiled) simulator and to serve as the speed baseline of the benchmarks.  It
deliberately shares no code with ``fivdisc.core`` or ``fivdisc.simulate``:
it only takes modal data from ``fivdisc.model.plate`` and parameters from a case
object (``fivdisc.case.Case`` or any object with the same attributes, e.g. a
``types.SimpleNamespace``).

Case attributes read
--------------------
* ``case.sliders`` (sequence; else ``[case.slider]``), each with ``track_radius,
  mass, normal_stiffness, normal_damping, rotational_stiffness`` (= r^2 k_phi),
  ``rotational_damping`` (= r^2 c_phi), ``preload`` and optionally ``angle``
  (theta_j [rad], default 0) and ``face`` ("top" = +1 default, "bottom" = -1).
* ``case.disc``: geometry and material, ``modes`` [(k, l)], optional
  ``damping_ratio`` (float or one per mode, default 0) and ``damping_frame``
  ("material" default or "space").
* ``case.friction``: ``law`` ("exponential" default, "stribeck", "table"),
  ``static`` and the law's parameters (see :class:`FrictionLaw`).
* ``case.speed`` (profiles constant / decelerating / accelerating / table).
* ``case.simulation``: ``impact, omega_dot_terms, printed_gyroscopic_sign,
  initial_state, perturbation, max_step, max_switches, duration`` and
  ``min_flight_time`` (default 1e-11 s).

Public API
----------
* ``reference_simulate(case, t_end=None, *, rtol=1e-12, atol=1e-14, method="DOP853",
  y0=None, phase0=None, mode_data=None, max_step=None, max_switches=None)`` ->
  :class:`ReferenceResult` with ``events`` (tuples ``(t, from_phase, to_phase, kind,
  slider)``), ``segments``, ``impacts``, ``evaluate(times)`` (dict: ``q``, ``q_dot``
  (n_t, n); per slider (n_t, S): ``phi, phi_dot, z, z_dot, gap, normal_force,
  friction_force, phase, slip_sign``; ``disc_speed`` = ``Omega``, ``Omega_dot``, ``t``
  (n_t,)) and ``state(t)``.
* ``energy_terms(result, times)``, ``mechanical_energy(case, state)``,
  ``power_terms(case, out)``: the energy balance (below); ``jacobi_integral``,
  ``kinetic_energy_t2`` (T2 - T0 + V and T2, as before, summed over sliders).
* ``sliding_equilibrium(case)``, ``free_doublet_eigenvalues(omega, l, Omega, zeta,
  frame)``, ``plastic_impact(...)``, ``solve_impact_lcp(G, gap_rate_minus, forced)``,
  ``impact_map(...)`` (paper Eqs. 54-56), ``FrictionLaw(case.friction)``,
  ``mode_data_from_case(case)``, ``speed_at(speed, t)``, ``slider_list(case)``.

How it differs from the fast code, on purpose
---------------------------------------------
* At every right-hand-side evaluation the FULL linear system of the unknown
  accelerations, normal forces and gap accelerations is assembled as a dense
  ``(n + 3 S) x (n + 3 S)`` matrix (unknowns ``[qddot (n), phiddot (S), N (S),
  eddot (S)]``; a row that does not apply to a slider's phase is the identity
  row of a known value) and solved with :func:`numpy.linalg.solve`: no low-rank /
  Woodbury trick.
* Each stretch between switches is integrated with
  :func:`scipy.integrate.solve_ivp` (dense output) and Python event functions;
  event times are located by scipy's root finder on the dense output.
* In separation the state carries the *gap* ``e_j = sigma_j (z_j - w_j)`` and
  its rate instead of ``z_j`` and ``zdot_j`` (the same ODE,
  ``m z'' + c_z z' + k_z z + sigma N0 = 0`` with ``z = w + sigma e``).  The gap
  starts at exactly 0, so the re-contact event cannot fire spuriously through
  integration error in ``z - w`` (two O(1e-5 m) numbers).

State vector: ``y = [q (n), qdot (n), phi (S), phidot (S), e (S), edot (S)]``;
``e_j = edot_j = 0`` in contact.  For S = 1 this is the layout of the
single-slider reference: ``[q, qdot, phi, phidot, e, edot]``.  Modal coordinates
are ordered, for each ``(k, l)`` of ``case.disc.modes``: ``C_kl`` then ``D_kl``
if ``l >= 1``.  Phases per slider: 0 = slip (with sign s_j), 1 = stick,
2 = separation.

The equations (equations.md, and what it leaves to derive)
----------------------------------------------------------
Slider j sits at the space-fixed angle ``psi_j = theta_j + phi_j`` on radius
``r_j``; ``g_j, g'_j, g''_j`` are the mode shapes ``R(r_j) cos(l psi)`` /
``R(r_j) sin(l psi)`` and their psi-derivatives.  ``w_j = g_j.q``,
``wdot_j = g_j.qdot + phidot_j (g'_j.q)``.

Forces on the disc (virtual work).  Slider j on face sigma_j presses the disc
with N_j >= 0 towards ``-sigma_j w``: ``dW = -sigma_j N_j g_j.dq``.  The friction
force f_j (+ along +phi on the slider) acts on the disc with ``-f_j`` at the
surface ``z = sigma_j h / 2``, whose Kirchhoff in-plane displacement is
``u_theta = -sigma_j (h / 2) (1 / r) dw/dtheta`` on top of the prescribed rigid
rotation, so ``dW = -f_j du_theta = sigma_j (h / (2 r_j)) f_j g'_j.dq``.  The
disc equations then read (equations.md)::

    M q'' + G(Omega) q' + ... = sum_j sigma_j [-N_j g_j + (h / (2 r_j)) f_j g'_j] - D_damp

with ``N_j = N0_j + sigma_j (m_j zddot_j + c_zj zdot_j + k_zj z_j)`` in contact
(``zddot_j = g.qddot + 2 phidot (g'.qdot) + phidot^2 (g''.q) + phiddot (g'.q)``)
and the separated slider ``m z'' + c_z z' + k_z z + sigma N0 = 0``.

Disc damping (equations.md): per coordinate ``2 zeta omega M`` times the material
velocity ``a = qdot + Omega c`` with ``c_C = l D``, ``c_D = -l C`` ("material"),
or times ``qdot`` ("space").  ``zeta`` is one value per (k, l) entry, shared by C
and D.

Free damped doublet, closed form (used by the tests).  With ``X = C + i D`` the
undamped doublet plus damping is one complex equation::

    material:  X'' + (2 zeta omega - 2 i l Omega) X' + (omega^2 - l^2 Omega^2
               - 2 i zeta omega l Omega) X = 0
    space:     X'' + (2 zeta omega - 2 i l Omega) X' + (omega^2 - l^2 Omega^2) X = 0

Put ``lambda = i l Omega + mu``: the first gives ``mu^2 + 2 zeta omega mu +
omega^2 = 0``, i.e. ``lambda = i l Omega - zeta omega +/- i omega sqrt(1 -
zeta^2)`` (every wave decays at zeta omega: damping in the co-rotating frame);
the second gives ``mu^2 + 2 zeta omega mu + omega^2 + 2 i zeta omega l Omega =
0``, i.e. ``lambda = i l Omega - zeta omega +/- i sqrt(omega^2 (1 - zeta^2) +
2 i zeta omega l Omega)`` (complex square root): the two waves decay at about
``zeta (omega +/- l Omega)``, and the backward wave grows beyond the critical
speed ``l Omega > omega``.  C = Re X, D = Im X; the conjugate roots belong to
``conj(X)``.

Friction laws (:class:`FrictionLaw`), of the sliding speed ``u_j = r_j s_j v_j``
(``= r_j |Omega - phidot_j|`` in slip).  Inside a Runge-Kutta step that crosses
``v = 0`` the law is asked for ``u`` slightly below 0; it is continued smoothly:
the exponential and the stribeck law with delta = 1 by their formula, the
stribeck law with delta != 1 linearly with its one-sided slope at 0 (``mu_v``
for delta > 1; delta < 1 has an infinite slope there, continued as
``mu(0) + mu_v u``), the table linearly with the PCHIP's end slope.

Mechanical energy and its balance (:func:`mechanical_energy`,
:func:`power_terms`, :func:`energy_terms`).  From the Lagrangian, the disc's
kinetic energy is ``T_d = 1/2 rho h \\iint (w_t + Omega w_theta)^2 = 1/2 sum M a^2``
(a = material velocity above) and::

    E = 1/2 sum M a^2 + 1/2 sum M omega^2 q^2
        + sum_j [1/2 I_j phidot_j^2 + 1/2 m_j zdot_j^2 + 1/2 r_j^2 k_phij phi_j^2
                 + 1/2 k_zj z_j^2 + sigma_j N0_j z_j]

Differentiating along the disc equations (with the Omegadot terms) the
gyroscopic, centrifugal and Omegadot terms cancel exactly:
``dE_disc/dt = a . (Q - D_damp)``, the generalised forces do work on the material
velocity; ``g_j.a = g_j.qdot + Omega g'_j.q`` and ``g'_j.a = g'_j.qdot + Omega
g''_j.q``.  The slider equations add ``r f phidot - r^2 c_phi phidot^2 +
sigma N zdot - c_z zdot^2``.  In contact ``zdot = wdot``, so with
``v_j = Omega - phidot_j``::

    dE/dt = sum_j [ -r_j f_j v_j                                  (friction, <= 0 in slip)
                    + r_j f_j Omega                               (drive: motor vs friction)
                    + sigma_j (h/(2 r_j)) f_j (g'.qdot + Omega g''.q)
                    - sigma_j N_j v_j (g'_j.q) ]                  (surface: moment, slope)
            - sum_j (r_j^2 c_phij phidot_j^2 + c_zj zdot_j^2)     (slider dampers)
            - a . D_damp                                          (disc damping)
            + a . F_options                                       (options: no Omegadot
                                                                   terms, printed sign)

with ``F_options = +/- l M Omegadot q[partner]`` (the missing Omegadot terms, sign
of the C / D equation moved to the right) and ``-4 l M Omega Cdot`` in each D
equation (printed gyroscopic sign), written out from the option flags.

The "surface" term is the work of the moving, sloped disc surface on the slider
(the model's phi equation has no component of N along the slope; see below).
At an impact (positions unchanged) with impulses lambda_i (below),
``du = W^-1 A^T lambda`` and gap rates after ``gammadot+``: ``Delta(1/2 u W u) =
lambda.b - 1/2 |du|_W^2`` (as equations.md says, using ``lambda_i
gammadot+_i = 0``), and the linear term of T_d adds ``Omega c . M dqdot =
-sum_i sigma_i lambda_i Omega (g'_i.q)``, so::

    Delta E = -1/2 |du|_W^2  -  sum_i lambda_i sigma_i v_i (g'_i.q)

the same "surface" work as in the continuous balance, plus the plastic loss.
With the impact off, ``Delta E = 1/2 m_j (wdot_j^2 - zdot_j-^2)``.

Re-contact with several sliders (equations.md): Moreau's plastic impact on
``A = {j} + {sliders in contact} + {separated sliders whose gap is closed to
round-off}``; the LCP is solved exactly by enumerating the active sets
(:func:`solve_impact_lcp`).  A slider in flight is not struck: its zdot is kept
(its stored gap rate follows the disc's velocity jump).  Impact cascades: a
slider that the impact releases (lambda = 0, gammadot+ > 0) flies ballistically,
``e(t) ~ gammadot+ t + 1/2 eddot t^2``; if that flight ``2 gammadot+ / |eddot|`` is shorter than
``simulation.min_flight_time`` or its peak gap ``gammadot+^2 / (2 |eddot|)`` is
below the round-off of z (``8 eps max(|z|, N0/k_z)``), the slider is kept in
contact: the impact is solved again with that contact as an equality
(bilateral) constraint.  That is the limit of the Zeno cascade: its sum of
impulses ends in a state with every kept gap rate zero, ``u+ = u- + W^-1 A^T
Lambda`` with ``A u+ = b``, which is the bilateral solution (the preload's impulse
over the vanishing flights, O(min_flight_time), is what is neglected; the
kept contact's impulse may be tensile by that much).  The energy identity above
holds for it as well (``gammadot+_i = 0`` on kept contacts).

Phase choice and event re-arming
--------------------------------
* slip (sign s): exits when ``v = Omega - phidot`` reaches 0 (event direction
  ``-s``) or when ``N`` reaches 0 (direction -1).  At ``v = 0`` the slider's
  ``phidot`` is set to ``Omega`` exactly and the next phase is chosen from the
  state (with the other sliders' phases): stick if ``N_stick >= 0`` and
  ``|f_stick| <= mu_s N_stick``; else slip with ``s = sign(f_stick)`` (a
  "reversal" when s changes); separation if that contact phase has ``N < 0``.
* stick: exits when ``|f| - mu_s N`` reaches 0 from below (direction +1): then
  slip with ``s = sign(f)`` (the event is the evidence; re-testing at a point
  located only to round-off could pick stick again and loop); or when ``N``
  reaches 0.
* separation: exits when the gap reaches 0 from above (direction -1); the
  plastic impact is applied (unless ``simulation.impact`` is False), then the
  phase is chosen from the state.
* Simultaneous events: scipy stops at the earliest root of all exit functions;
  every other exit whose root lies within ``1e-14 max(1, t)`` s after it (found by
  brentq on the same step's dense output), or that has already crossed at that
  time, is taken at the same instant, one after the other in slider order.
  (Mathematically coincident exits, e.g. of mirror-symmetric sliders, are located
  ~1e-16 s apart by round-off.)
* After any switch every slider in contact is re-checked (``N >= 0``; a sticking
  one ``|f| <= mu_s N``; a slipping one, unless it entered slip at this instant,
  whether ``s v`` is at 0 within 1e-13 max(1, |Omega|), which then is its
  ``v = 0`` switch) and the lowest-index violator switches first, repeatedly
  (at most 8 S^2 + 8 rounds).
* At t = 0 the phases come from the state (v = 0: stick test; else slip with the
  sign of v); a slider whose contact would need N < 0 starts separated, logged
  as a separation at t = 0.
* An event function that is exactly 0 at the start of a stretch (``v`` after a
  stick or reversal, the gap after a separation) is replaced by ``x(t) / (t -
  t0)`` with its limit ``xdot(t0)`` at t0: same roots for t > t0, but it starts
  on the side the event direction ignores, so a step that overshoots a whole
  short flight still finds the root inside it (scipy's brentq would otherwise
  return t0).  A hard limit on the number of switches, and on stretches without
  progress in time, guards against endless loops.
* Kinks of the speed profile are integration breakpoints: the phases are
  re-checked there with the new ``Omegadot``.

Two properties of the stated model (not of this code) that checks must respect
------------------------------------------------------------------------------
* The slider's phi equation has no component of the normal force along the
  disc's slope, so without friction and damping the Jacobi integral changes at
  the rate ``N phidot (g'.q)``; it is a first integral only while that is zero.
* For the same reason the plastic impact can increase ``T2 = 1/2 u W u`` (by
  ``lambda.b``).
"""

from __future__ import annotations

import bisect
import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

__all__ = [
    "CONTACT_PHASES",
    "EVENT_KINDS",
    "SEPARATION",
    "SLIP",
    "STICK",
    "FrictionLaw",
    "ModeData",
    "ReferenceResult",
    "Segment",
    "energy_terms",
    "free_doublet_eigenvalues",
    "impact_map",
    "jacobi_integral",
    "kinetic_energy_t2",
    "mechanical_energy",
    "mode_data_from_case",
    "plastic_impact",
    "power_terms",
    "reference_simulate",
    "slider_list",
    "sliding_equilibrium",
    "solve_impact_lcp",
    "speed_at",
]

SLIP, STICK, SEPARATION = 0, 1, 2
CONTACT_PHASES = (SLIP, STICK)
PHASE_NAMES = {SLIP: "slip", STICK: "stick", SEPARATION: "separation"}
EVENT_KINDS = ("stick", "slip", "reversal", "separation", "recontact")
_EPS = np.finfo(float).eps


# --------------------------------------------------------------------------- case access
def slider_list(case: Any) -> list:
    """The case's sliders: ``case.sliders`` if present and non-empty, else ``[case.slider]``."""
    sliders = getattr(case, "sliders", None)
    return list(sliders) if sliders else [case.slider]


def _face_sign(face: Any) -> float:
    if isinstance(face, str):
        key = face.strip().lower()
        if key == "top":
            return 1.0
        if key == "bottom":
            return -1.0
        raise ValueError(f"slider face must be 'top' or 'bottom', got {face!r}")
    value = float(face)
    if value not in (1.0, -1.0):
        raise ValueError(f"slider face must be +1 or -1, got {face!r}")
    return value


@dataclass(frozen=True)
class _Sliders:
    """Per-slider parameters as arrays of length S."""

    r: np.ndarray
    m: np.ndarray
    kz: np.ndarray
    cz: np.ndarray
    Kphi: np.ndarray  # r^2 k_phi
    Cphi: np.ndarray  # r^2 c_phi
    N0: np.ndarray
    theta: np.ndarray
    sigma: np.ndarray
    I: np.ndarray
    hk: np.ndarray  # h / (2 r)

    @property
    def S(self) -> int:
        return int(self.r.size)

    @classmethod
    def from_case(cls, case: Any) -> _Sliders:
        sl = slider_list(case)
        h = float(case.disc.thickness)

        def arr(name, default=None):
            return np.array(
                [
                    float(getattr(s, name, default) if default is not None else getattr(s, name))
                    for s in sl
                ]
            )

        r = arr("track_radius")
        m = arr("mass")
        return cls(
            r=r,
            m=m,
            kz=arr("normal_stiffness"),
            cz=arr("normal_damping"),
            Kphi=arr("rotational_stiffness"),
            Cphi=arr("rotational_damping"),
            N0=arr("preload"),
            theta=arr("angle", 0.0),
            sigma=np.array([_face_sign(getattr(s, "face", "top")) for s in sl]),
            I=m * r**2,
            hk=h / (2.0 * r),
        )


# --------------------------------------------------------------------------- modal data
@dataclass(frozen=True)
class ModeData:
    """Per modal coordinate (C and D separately): R at the track radius, modal mass, omega,
    l, sine flag.

    ``R0`` holds R at the first slider's radius (shape (n,)).  Optional: ``R`` (shape (k, n))
    holds R at the radii ``radii`` (k values).  A slider on radius r uses the row of ``R``
    with that radius; without ``radii``, ``R`` must have one row per slider, and without
    ``R`` every slider uses ``R0`` (sliders on one track, or no modes).
    """

    R0: np.ndarray
    M: np.ndarray
    omega: np.ndarray
    l: np.ndarray
    is_sine: np.ndarray
    R: np.ndarray | None = None
    radii: tuple | None = None

    @property
    def n(self) -> int:
        return int(self.R0.size)

    @property
    def partner(self) -> np.ndarray:
        """Index of the twin coordinate (C <-> D); itself for l = 0."""
        idx = np.arange(self.n)
        part = idx.copy()
        for j in range(self.n):
            if self.l[j] >= 1:
                part[j] = j + 1 if not self.is_sine[j] else j - 1
        return part

    def radial(self, radii) -> np.ndarray:
        """R at the given sliders' radii, shape (S, n)."""
        radii = [float(r) for r in radii]
        S = len(radii)
        if self.R is None:
            return np.tile(self.R0, (S, 1))
        R = np.asarray(self.R, float)
        if self.radii is None:
            if R.shape != (S, self.n):
                raise ValueError(f"ModeData.R has shape {R.shape}, expected {(S, self.n)}")
            return R
        rows = []
        for r in radii:
            k = [i for i, ri in enumerate(self.radii) if abs(ri - r) <= 1e-14 * abs(r)]
            if not k:
                raise ValueError(f"ModeData has no mode shapes at radius {r} m")
            rows.append(R[k[0]])
        return np.array(rows).reshape(S, self.n)

    @classmethod
    def from_lists(cls, R0, M, omega, l, is_sine, R=None, radii=None) -> ModeData:
        return cls(
            np.asarray(R0, float),
            np.asarray(M, float),
            np.asarray(omega, float),
            np.asarray(l, int),
            np.asarray(is_sine, bool),
            None if R is None else np.atleast_2d(np.asarray(R, float)),
            None if radii is None else tuple(float(r) for r in radii),
        )


def mode_data_from_case(case: Any) -> ModeData:
    """Modal data of ``case.disc.modes`` at every slider's radius, from ``fivdisc.model.plate``."""
    modes = list(case.disc.modes)
    radii = [float(s.track_radius) for s in slider_list(case)]
    cols, M, om, ll, sine = [], [], [], [], []
    if modes:
        from fivdisc.model.plate import AnnularPlate

        plate = AnnularPlate.from_disc(case.disc)
        for k, l in modes:
            mode = plate.mode(int(k), int(l))
            rv = [float(np.asarray(mode.shape(r))) for r in radii]
            for is_sine in (False, True) if l >= 1 else (False,):
                cols.append(rv)
                M.append(float(mode.modal_mass))
                om.append(float(mode.omega))
                ll.append(int(l))
                sine.append(is_sine)
    R = np.array(cols, float).T.reshape(len(radii), len(cols))
    return ModeData.from_lists(R[0], M, om, ll, sine, R=R, radii=radii)


def _disc_damping(case: Any, md: ModeData) -> tuple[np.ndarray, bool]:
    """Damping ratio per modal coordinate and whether the frame is "material"."""
    disc = case.disc
    frame = str(getattr(disc, "damping_frame", "material")).lower()
    if frame not in ("material", "space"):
        raise ValueError(f"disc.damping_frame must be 'material' or 'space', got {frame!r}")
    ratio = getattr(disc, "damping_ratio", 0.0)
    if ratio is None:
        ratio = 0.0
    if np.ndim(ratio) == 0:
        return np.full(md.n, float(ratio)), frame == "material"
    ratio = [float(x) for x in ratio]
    modes = list(disc.modes)
    if len(ratio) != len(modes):
        raise ValueError(f"disc.damping_ratio has {len(ratio)} entries for {len(modes)} modes")
    zeta = []
    for (_, l), z in zip(modes, ratio, strict=True):
        zeta.extend([z, z] if int(l) >= 1 else [z])
    if len(zeta) != md.n:
        raise ValueError("disc.damping_ratio does not match the mode data")
    return np.array(zeta, float), frame == "material"


# --------------------------------------------------------------------------- friction
class FrictionLaw:
    """Kinetic friction coefficient of the sliding speed u [m/s] and the static limit.

    ``law`` ("exponential" default):  mu = mu1 + (mu0 - mu1) exp(-alpha u),
    with ``kinetic_max`` (mu0), ``kinetic_min`` (mu1), ``decay`` (alpha [s/m]);
    "stribeck":  mu = mu1 + (mu0 - mu1) exp(-(u / v_s)^delta) + mu_v u, with
    ``kinetic_max, kinetic_min, stribeck_velocity`` (v_s [m/s]),
    ``stribeck_exponent`` (delta), ``viscous`` (mu_v [s/m]);
    "table": PCHIP through (``speeds`` [m/s], ``values``), constant beyond the last point.
    ``static`` is mu_s.  For u < 0 (inside a step crossing v = 0) each law is continued
    smoothly (module docstring).
    """

    def __init__(self, fr: Any):
        self.law = str(getattr(fr, "law", "exponential")).lower()
        self.mu_s = float(fr.static)
        if self.law == "exponential":
            self.mu0 = float(fr.kinetic_max)
            self.mu1 = float(fr.kinetic_min)
            self.alpha = float(fr.decay)
        elif self.law == "stribeck":
            self.mu0 = float(fr.kinetic_max)
            self.mu1 = float(fr.kinetic_min)
            self.vs = float(fr.stribeck_velocity)
            self.delta = float(getattr(fr, "stribeck_exponent", 1.0))
            self.muv = float(getattr(fr, "viscous", 0.0))
        elif self.law == "table":
            from scipy.interpolate import PchipInterpolator

            u = np.asarray(fr.speeds, float)
            mu = np.asarray(fr.values, float)
            if u.size < 2 or np.any(np.diff(u) <= 0):
                raise ValueError("friction.speeds must increase strictly (at least two points)")
            self.u_first, self.u_last = float(u[0]), float(u[-1])
            self.mu_last = float(mu[-1])
            self.pchip = PchipInterpolator(u, mu, extrapolate=False)
            self.mu_first = float(mu[0])
            self.slope_first = float(self.pchip.derivative()(u[0]))
            # the PCHIP's cubic pieces, evaluated in plain Python (scipy's call is slow)
            self._knots = [float(x) for x in self.pchip.x]
            self._coef = [tuple(float(c) for c in col) for col in self.pchip.c.T]
        else:
            raise ValueError(f"unknown friction law {self.law!r}")

    def __call__(self, u: float) -> float:
        """mu at the sliding speed u [m/s] (u >= 0; smooth continuation below 0)."""
        u = float(u)
        if self.law == "exponential":
            return self.mu1 + (self.mu0 - self.mu1) * math.exp(-self.alpha * u)
        if self.law == "stribeck":
            if u >= 0.0 or self.delta == 1.0:
                x = u / self.vs
                ex = math.exp(-x) if self.delta == 1.0 else math.exp(-(x**self.delta))
                return self.mu1 + (self.mu0 - self.mu1) * ex + self.muv * u
            return self.mu0 + self.muv * u  # one-sided slope: mu_v (see module docstring)
        if u >= self.u_last:
            return self.mu_last
        if u <= self.u_first:
            return self.mu_first + self.slope_first * (u - self.u_first)
        i = min(bisect.bisect_right(self._knots, u) - 1, len(self._coef) - 1)
        c3, c2, c1, c0 = self._coef[i]
        dx = u - self._knots[i]
        return ((c3 * dx + c2) * dx + c1) * dx + c0


# --------------------------------------------------------------------------- speed profile
@dataclass(frozen=True)
class _Piece:
    """Omega(t) = omega_a + slope (t - t_a) on [t_a, t_b)."""

    t_a: float
    t_b: float
    omega_a: float
    slope: float

    def omega(self, t):
        return self.omega_a + self.slope * (t - self.t_a)


def _speed_pieces(speed: Any, t_end: float) -> list[_Piece]:
    """Split the speed profile into linear pieces; the piece ends are breakpoints."""
    profile = str(getattr(speed, "profile", "")).lower()
    inf = math.inf
    if profile == "constant":
        return [_Piece(0.0, inf, float(speed.value), 0.0)]
    if profile == "accelerating":
        return [_Piece(0.0, inf, float(speed.initial), float(speed.rate))]
    if profile == "decelerating":
        w0, tmax = float(speed.initial), float(speed.duration)
        return [_Piece(0.0, tmax, w0, -w0 / tmax), _Piece(tmax, inf, 0.0, 0.0)]
    if profile == "table":
        ts = np.asarray(speed.times, float)
        ws = np.asarray(speed.values, float)
        pieces = []
        if ts[0] > 0.0:
            pieces.append(_Piece(-inf, ts[0], ws[0], 0.0))
        for i in range(ts.size - 1):
            slope = (ws[i + 1] - ws[i]) / (ts[i + 1] - ts[i])
            pieces.append(_Piece(ts[i], ts[i + 1], ws[i], slope))
        pieces.append(_Piece(ts[-1], inf, ws[-1], 0.0))
        return pieces
    raise ValueError(f"unknown speed profile {profile!r}")


def _piece_at(pieces: Sequence[_Piece], t: float) -> _Piece:
    """The piece with t_a <= t < t_b (right-continuous: a knot belongs to the later piece)."""
    for p in pieces:
        if p.t_a <= t < p.t_b:
            return p
    return pieces[-1]


def speed_at(speed: Any, t) -> tuple[np.ndarray, np.ndarray]:
    """Omega(t) and Omegadot(t) (right derivative at kinks) of a case's speed profile."""
    t = np.atleast_1d(np.asarray(t, float))
    pieces = _speed_pieces(speed, float(t.max()))
    om = np.empty_like(t)
    od = np.empty_like(t)
    for i, ti in enumerate(t):
        p = _piece_at(pieces, ti)
        om[i], od[i] = p.omega(ti), p.slope
    return om, od


# --------------------------------------------------------------------------- kinematics
def _shapes(md: ModeData, R: np.ndarray, psi):
    """g, g', g'' at the angles psi (length S) with radial values R (S, n): each (S, n)."""
    lf = md.l.astype(float)
    lpsi = np.outer(np.atleast_1d(psi), lf)
    c, s = np.cos(lpsi), np.sin(lpsi)
    g = R * np.where(md.is_sine, s, c)
    gp = R * lf * np.where(md.is_sine, c, -s)
    gpp = -(lf**2) * g
    return g, gp, gpp


def _as_phases(value, S: int, name: str) -> list[int]:
    if np.ndim(value) == 0:
        return [int(value)] * S
    out = [int(v) for v in value]
    if len(out) != S:
        raise ValueError(f"{name} needs {S} entries, got {len(out)}")
    return out


# --------------------------------------------------------------------------- the model
class _Model:
    """Parameters and the right-hand side of any phase combination (dense solves)."""

    def __init__(self, case: Any, md: ModeData):
        fr, sim = case.friction, case.simulation
        self.case = case
        self.md = md
        self.n = md.n
        self.sl = _Sliders.from_case(case)
        self.S = self.sl.S
        self.R = md.radial(self.sl.r)
        self.friction = FrictionLaw(fr)
        self.mu_s = self.friction.mu_s
        self.zeta, self.material = _disc_damping(case, md)
        self.omega_dot_terms = bool(getattr(sim, "omega_dot_terms", True))
        self.impact = bool(getattr(sim, "impact", True))
        self.min_flight_time = float(getattr(sim, "min_flight_time", 1e-11))
        self.partner = md.partner
        # sign of the coupling terms on the right-hand side: -1 for C, +1 for D ...
        self.dsign = np.where(md.is_sine, 1.0, -1.0)
        self.csign = -self.dsign  # material velocity a = qdot + Omega csign l q[partner]
        # ... except the D equations' gyroscopic term with the printed paper's sign
        # (+2 l M Omega Cdot on the left: not skew), an option for comparison only
        printed = bool(getattr(sim, "printed_gyroscopic_sign", False))
        self.printed = printed
        self.gsign = np.where(md.is_sine, -1.0 if printed else 1.0, -1.0)
        self.lf = md.l.astype(float)
        for name in ("r", "m", "kz", "cz", "Kphi", "Cphi", "N0", "I", "hk"):
            setattr(self, "_" + name, [float(x) for x in getattr(self.sl, name)])
        self._sig = [float(x) for x in self.sl.sigma]
        lM = self.lf * md.M
        self._gyro = self.gsign * 2.0 * lM
        self._odt = self.dsign * (1.0 if self.omega_dot_terms else 0.0) * lM
        self._Mw2 = md.M * md.omega**2
        self._Ml2 = md.M * self.lf**2
        self._cl = self.csign * self.lf
        self._damped = bool(np.any(self.zeta))
        self._c2zwM = 2.0 * self.zeta * md.omega * md.M
        self._Rl = self.R * self.lf
        self._l2 = self.lf**2
        self._diag = np.arange(self.n)
        self._cache_key = None
        self._cache_val = None

    # ---- compatibility with the single-slider reference
    @property
    def mu(self):
        """mu(v) of the first slider (angular relative velocity v), as in the old reference."""
        r0 = float(self.sl.r[0])
        return lambda v: self.friction(r0 * abs(v))

    @property
    def r0(self) -> float:
        return float(self.sl.r[0])

    # ---- kinematics
    def shapes(self, phi):
        """g, g', g'' of every slider at psi = theta + phi, each (S, n)."""
        lpsi = np.multiply.outer(self.sl.theta + phi, self.lf)
        c, s = np.cos(lpsi), np.sin(lpsi)
        sine = self.md.is_sine
        g = self.R * np.where(sine, s, c)
        return g, self._Rl * np.where(sine, c, -s), -self._l2 * g

    def split(self, y):
        n, S = self.n, self.S
        return (
            y[:n],
            y[n : 2 * n],
            y[2 * n : 2 * n + S],
            y[2 * n + S : 2 * n + 2 * S],
            y[2 * n + 2 * S : 2 * n + 3 * S],
            y[2 * n + 3 * S : 2 * n + 4 * S],
        )

    @property
    def size(self) -> int:
        return 2 * self.n + 4 * self.S

    def material_velocity(self, q, qd, Om):
        p = self.partner
        return qd + self.csign * self.lf * Om * q[..., p]

    def disc_free(self, q, qd, Om, Omd):
        """Disc terms moved to the right: -gyro - Omegadot terms - stiffness - damping."""
        p = self.partner
        b = (self._gyro * Om) * qd[p] + (self._odt * Omd) * q[p]
        b -= (self._Mw2 - self._Ml2 * (Om * Om)) * q
        if self._damped:
            vel = qd + (self._cl * Om) * q[p] if self.material else qd
            b -= self._c2zwM * vel
        return b

    def option_forces(self, q, qd, Om, Omd):
        """Generalised forces by which the options leave the stated model (written out from
        the option flags, not as a difference of implementations): without the Omegadot
        terms ``-(-/+) l M Omegadot q[partner]`` is missing; with the printed gyroscopic sign
        the D equations carry ``-4 l M Omega Cdot`` more on the right."""
        md, p = self.md, self.partner
        lM = self.lf * md.M
        extra = np.zeros(self.n)
        if not self.omega_dot_terms:
            extra -= self.dsign * lM * Omd * q[p]
        if self.printed:
            extra -= np.where(md.is_sine, 4.0 * lM * Om * qd[p], 0.0)
        return extra

    def stick_force(self, j, t, phi_j, piece):
        """Friction needed to hold slider j at phidot = Omega (its phi equation)."""
        sl = self.sl
        Om, Omd = piece.omega(t), piece.slope
        return (sl.I[j] * Omd + sl.Cphi[j] * Om + sl.Kphi[j] * phi_j) / sl.r[j]

    # ---- the dense solve of one phase combination
    def _combo(self, phases, signs):
        """Normalised (phases, signs) tuples."""
        if isinstance(phases, tuple) and isinstance(signs, tuple) and len(phases) == self.S:
            return phases, signs
        return (
            tuple(_as_phases(phases, self.S, "phases")),
            tuple(_as_phases(signs, self.S, "signs")),
        )

    def solve(self, phases, signs, t, y, piece):
        """Accelerations, N, f, z, zdot of every slider for the phase combination."""
        phases, signs = self._combo(phases, signs)
        y = np.asarray(y, float)
        key = (phases, signs, float(t), y.tobytes(), id(piece))
        if key == self._cache_key:
            return self._cache_val
        n, S = self.n, self.S
        q, qd, phi, phid, e, ed = self.split(y)
        Om, Omd = piece.omega(t), piece.slope
        phid = np.array(phid, float)
        for j in range(S):
            if phases[j] == STICK:
                phid[j] = Om
        G, GP, GPP = self.shapes(phi)
        gpq = GP @ q
        w = G @ q
        wd = G @ qd + phid * gpq
        centr = 2.0 * phid * (GP @ qd) + phid**2 * (GPP @ q)
        z, zd = w.copy(), wd.copy()
        v = Om - phid
        size = n + 3 * S
        A = np.zeros((size, size))
        rhs = np.zeros(size)
        A[self._diag, self._diag] = self.md.M
        rhs[:n] = self.disc_free(q, qd, Om, Omd)
        mu = np.zeros(S)
        f = np.zeros(S)
        for j in range(S):
            ip, iN, ie = n + j, n + S + j, n + 2 * S + j
            sg, m, r, inertia = self._sig[j], self._m[j], self._r[j], self._I[j]
            if phases[j] == SEPARATION:
                z[j] += sg * e[j]
                zd[j] += sg * ed[j]
                A[ip, ip] = inertia
                rhs[ip] = -self._Cphi[j] * phid[j] - self._Kphi[j] * phi[j]
                A[iN, iN] = 1.0
                A[ie, :n] = m * G[j]
                A[ie, ip] = m * gpq[j]
                A[ie, ie] = sg * m
                rhs[ie] = (
                    -(self._cz[j] * zd[j] + self._kz[j] * z[j] + sg * self._N0[j]) - m * centr[j]
                )
                continue
            if phases[j] == SLIP:
                s = float(signs[j])
                mu[j] = muj = self.friction(r * s * v[j])
                A[:n, iN] = sg * (G[j] - self._hk[j] * s * muj * GP[j])
                A[ip, ip] = inertia
                A[ip, iN] = -r * s * muj
                rhs[ip] = -self._Cphi[j] * phid[j] - self._Kphi[j] * phi[j]
            else:  # stick: the friction force is the reaction of the phi equation
                f[j] = (inertia * Omd + self._Cphi[j] * Om + self._Kphi[j] * phi[j]) / r
                A[:n, iN] = sg * G[j]
                rhs[:n] += sg * self._hk[j] * f[j] * GP[j]
                A[ip, ip] = 1.0
                rhs[ip] = Omd
            A[iN, iN] = 1.0
            A[iN, :n] = -sg * m * G[j]
            A[iN, ip] = -sg * m * gpq[j]
            rhs[iN] = self._N0[j] + sg * (m * centr[j] + self._cz[j] * zd[j] + self._kz[j] * z[j])
            A[ie, ie] = 1.0
        x = np.linalg.solve(A, rhs)
        N = x[n + S : n + 2 * S].copy()
        edd = x[n + 2 * S :].copy()
        for j in range(S):
            if phases[j] == SLIP:
                f[j] = signs[j] * mu[j] * N[j]
            elif phases[j] == SEPARATION:
                N[j] = 0.0
                continue
            edd[j] = 0.0
        out = {
            "qdd": x[:n],
            "phidd": x[n : n + S],
            "N": N,
            "f": f,
            "edd": edd,
            "z": z,
            "zd": zd,
            "w": w,
            "wd": wd,
            "v": v,
            "phid": phid,
            "mu": mu,
        }
        self._cache_key, self._cache_val = key, out
        return out

    # single-slider names, kept for callers of the old reference (S = 1 or all alike)
    def solve_slip(self, t, y, piece, s):
        return self.solve([SLIP] * self.S, [s] * self.S, t, y, piece)

    def solve_stick(self, t, y, piece):
        return self.solve([STICK] * self.S, [0] * self.S, t, y, piece)

    def solve_sep(self, t, y, piece):
        return self.solve([SEPARATION] * self.S, [0] * self.S, t, y, piece)

    # ---- right-hand side for solve_ivp
    def rhs(self, phases, signs, piece):
        n, S = self.n, self.S
        phases, signs = self._combo(phases, signs)
        stick = np.array([p == STICK for p in phases])
        sep = np.array([p == SEPARATION for p in phases])

        def fun(t, y):
            r = self.solve(phases, signs, t, y, piece)
            dy = np.zeros(2 * n + 4 * S)
            dy[:n] = y[n : 2 * n]
            dy[n : 2 * n] = r["qdd"]
            dy[2 * n : 2 * n + S] = np.where(stick, piece.omega(t), y[2 * n + S : 2 * n + 2 * S])
            dy[2 * n + S : 2 * n + 2 * S] = np.where(stick, piece.slope, r["phidd"])
            dy[2 * n + 2 * S : 2 * n + 3 * S] = np.where(sep, y[2 * n + 3 * S :], 0.0)
            dy[2 * n + 3 * S :] = np.where(sep, r["edd"], 0.0)
            return dy

        return fun

    def events(self, phases, signs, piece, t0, y0):
        """(event functions, [(slider, cause)]) of a phase combination started at (t0, y0)."""
        n, S = self.n, self.S
        phases = tuple(phases)
        signs = tuple(signs)
        r0 = self.solve(phases, signs, t0, y0, piece)
        evs, names = [], []

        def wrap(fun, x0, rate0):
            """x(t) / (t - t0), limit rate0 at t0, if x(t0) == 0 (module docstring)."""
            if x0 != 0.0:
                return fun

            def g(t, y):
                if t == t0:
                    return rate0
                return fun(t, y) / (t - t0)

            return g

        for j in range(S):
            if phases[j] == SLIP:
                s = signs[j]

                def ev_v(t, y, j=j):
                    return piece.omega(t) - y[2 * n + S + j]

                v0 = ev_v(t0, y0)
                g = wrap(ev_v, v0, piece.slope - r0["phidd"][j])
                g.terminal, g.direction = True, -float(s)
                evs.append(g)
                names.append((j, "v0"))

                def ev_N(t, y, j=j):
                    return self.solve(phases, signs, t, y, piece)["N"][j]

                ev_N.terminal, ev_N.direction = True, -1.0
                evs.append(ev_N)
                names.append((j, "N0"))
            elif phases[j] == STICK:

                def ev_f(t, y, j=j):
                    r = self.solve(phases, signs, t, y, piece)
                    return abs(r["f"][j]) - self.mu_s * r["N"][j]

                ev_f.terminal, ev_f.direction = True, 1.0
                evs.append(ev_f)
                names.append((j, "friction_limit"))

                def ev_N(t, y, j=j):
                    return self.solve(phases, signs, t, y, piece)["N"][j]

                ev_N.terminal, ev_N.direction = True, -1.0
                evs.append(ev_N)
                names.append((j, "N0"))
            else:

                def ev_gap(t, y, j=j):
                    return y[2 * n + 2 * S + j]

                e0 = ev_gap(t0, y0)
                g = wrap(ev_gap, e0, y0[2 * n + 3 * S + j])
                g.terminal, g.direction = True, -1.0
                evs.append(g)
                names.append((j, "gap0"))
        return evs, names

    def z_roundoff(self, j, z):
        """Round-off of slider j's normal coordinate z."""
        sl = self.sl
        scale = max(abs(float(z)), abs(sl.N0[j]) / sl.kz[j] if sl.kz[j] > 0 else 0.0, 1e-12)
        return 8.0 * _EPS * scale


# --------------------------------------------------------------------------- impacts
def solve_impact_lcp(G, gap_rate_minus, forced=()):
    """Moreau's plastic impact LCP, solved exactly by enumerating active sets.

    Find impulses ``lam`` with ``gap_rate_plus = gap_rate_minus + G lam`` and, for every
    contact i not in ``forced``: ``lam_i >= 0``, ``gap_rate_plus_i >= 0``,
    ``lam_i gap_rate_plus_i = 0``; a ``forced`` (bilateral) contact has
    ``gap_rate_plus_i = 0`` and a free-signed impulse.  G = A W^-1 A^T is positive
    definite, so the solution is unique; with round-off the active set of least
    violation is returned.

    Returns ``(lam, gap_rate_plus, active)``: active = sorted indices with ``lam`` from the
    equality solve (their gap_rate_plus is set to exactly 0).
    """
    G = np.atleast_2d(np.asarray(G, float))
    gm = np.atleast_1d(np.asarray(gap_rate_minus, float))
    k = gm.size
    forced = sorted({int(i) for i in forced})
    free = [i for i in range(k) if i not in forced]
    vscale = max(float(np.max(np.abs(gm))) if k else 0.0, 1e-300)
    best = None
    for mask in range(2 ** len(free)):
        J = sorted(forced + [free[b] for b in range(len(free)) if mask >> b & 1])
        lam = np.zeros(k)
        if J:
            lam[J] = np.linalg.solve(G[np.ix_(J, J)], -gm[J])
        gp = gm + G @ lam
        gp[J] = 0.0
        viol = 0.0
        for i in free:
            if i in J:
                viol = max(viol, -lam[i] * G[i, i] / vscale)
            else:
                viol = max(viol, -gp[i] / vscale)
        if best is None or viol < best[0]:
            best = (viol, lam, gp, J)
    _, lam, gp, J = best
    return lam, gp, J


def plastic_impact(M, m, sigma, g, gp, q, qdot, phidot, zdot, forced=()):
    """Plastic impact (restitution 0) of the disc with the contacts i = 0..k-1.

    Parameters: modal masses M (n,); per contact slider masses m (k,), faces sigma (k,),
    shapes g, g' at the sliders (k, n), their phidot (k,) and zdot before (k,); the disc's
    q, qdot (n,).  ``forced``: contacts held with an equality (module docstring).

    Returns a dict: ``qdot`` and ``zdot`` after, ``lam`` (impulses, compressive >= 0),
    ``b`` (= sigma phidot g'.q), ``gap_rate_minus``, ``gap_rate_plus``, ``active``
    (indices), ``du_W2`` (= |u+ - u-|_W^2) and ``dT2`` (= lam.b - du_W2 / 2).
    """
    M = np.asarray(M, float)
    m = np.atleast_1d(np.asarray(m, float))
    sigma = np.atleast_1d(np.asarray(sigma, float))
    g = np.atleast_2d(np.asarray(g, float))
    gp = np.atleast_2d(np.asarray(gp, float))
    q = np.asarray(q, float)
    qdot = np.asarray(qdot, float)
    phidot = np.atleast_1d(np.asarray(phidot, float))
    zdot = np.atleast_1d(np.asarray(zdot, float))
    b = sigma * phidot * (gp @ q)
    gm = sigma * (zdot - g @ qdot) - b  # gammadot = a.u - b
    # G = A W^-1 A^T, a_i = sigma_i (-g_i on qdot, +1 on zdot_i)
    Gm = (sigma[:, None] * sigma[None, :]) * ((g / M) @ g.T) + np.diag(1.0 / m)
    lam, gpl, active = solve_impact_lcp(Gm, gm, forced)
    dqd = -((sigma * lam) @ g) / M
    dzd = sigma * lam / m
    du_w2 = float(np.sum(M * dqd**2) + np.sum(m * dzd**2))
    return {
        "qdot": qdot + dqd,
        "zdot": zdot + dzd,
        "lam": lam,
        "b": b,
        "gap_rate_minus": gm,
        "gap_rate_plus": gpl,
        "active": active,
        "du_W2": du_w2,
        "dT2": float(lam @ b) - 0.5 * du_w2,
    }


def impact_map(md: ModeData, m: float, q, qdot, phi, phidot, zdot_minus):
    """Paper Eqs. 54-56, one top-face slider on the first slider's track: (qdot+, zdot+)."""
    q = np.asarray(q, float)
    qdot = np.asarray(qdot, float)
    lphi = md.l * phi
    g = md.R0 * np.where(md.is_sine, np.sin(lphi), np.cos(lphi))
    gp = md.R0 * md.l * np.where(md.is_sine, np.cos(lphi), -np.sin(lphi))
    w = m * g**2 / md.M
    zd_plus = (g @ qdot + w.sum() * zdot_minus + phidot * (gp @ q)) / (1.0 + w.sum())
    qd_plus = qdot - (m * g / md.M) * (zd_plus - zdot_minus)
    return qd_plus, float(zd_plus)


# --------------------------------------------------------------------------- results
@dataclass
class Segment:
    """One integrated stretch: solve_ivp's result (``ivp``, dense ``sol``) on [t0, t1]."""

    t0: float
    t1: float
    phases: tuple
    signs: tuple  # slip signs s_j (0 outside slip)
    ivp: Any
    piece: _Piece

    @property
    def sol(self):
        return self.ivp.sol

    @property
    def phase(self) -> np.ndarray:
        return np.array(self.phases)

    @property
    def sign(self) -> np.ndarray:
        return np.array(self.signs)


@dataclass
class ReferenceResult:
    """Output of :func:`reference_simulate`.

    events : list of ``(time, from_phase, to_phase, kind, slider)``, kind in
        ``EVENT_KINDS`` = ("stick", "slip", "reversal", "separation", "recontact"),
        slider the 0-based index.
    segments : list of :class:`Segment`.
    impacts : list of dicts, one per re-contact: ``t``, ``slider`` (the landing one),
        ``y_minus``, ``y_plus`` (full states), ``zdot_minus``, ``zdot_plus`` (landing
        slider), ``contacts`` (indices in the impact), ``lam``, ``b``, ``du_W2``, ``dT2``,
        ``forced`` (contacts kept by the cascade rule), ``impact`` (False: impact off),
        ``loss`` (-du_W2 / 2, or the slider's kinetic energy change when impact is off),
        ``surface`` (-sum lam sigma v g'.q).
    mode_data : :class:`ModeData`.
    """

    events: list
    segments: list
    mode_data: ModeData
    impacts: list
    t_end: float
    nfev: int
    _model: _Model = field(repr=False)

    @property
    def n_sliders(self) -> int:
        return self._model.S

    def _segment_index(self, times: np.ndarray) -> np.ndarray:
        starts = np.array([s.t0 for s in self.segments])
        idx = np.searchsorted(starts, times, side="right") - 1  # later segment at a switch
        return np.clip(idx, 0, len(self.segments) - 1)

    def state(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(y, phases, signs) at time t (later segment at a switch)."""
        seg = self.segments[int(self._segment_index(np.array([t]))[0])]
        return seg.sol(t), seg.phase, seg.sign

    def evaluate(self, times) -> dict:
        """Dense output at ``times`` (n_t values).

        Returns a dict: ``t`` (n_t,), ``q``, ``q_dot`` (n_t, n); per slider (n_t, S):
        ``phi``, ``phi_dot``, ``z``, ``z_dot``, ``gap`` (sigma (z - w), 0 in contact),
        ``normal_force``, ``friction_force``, ``phase`` (0 slip, 1 stick, 2 separation),
        ``slip_sign`` (s in slip, else 0); ``disc_speed`` (n_t,), also as ``Omega``, and
        ``Omega_dot`` (n_t,).  At a switch time the later segment is used.
        """
        times = np.atleast_1d(np.asarray(times, float))
        out = self._empty(times)
        idx = self._segment_index(times)
        for k in np.unique(idx):
            sel = np.flatnonzero(idx == k)
            self._fill(out, sel, self.segments[int(k)], times[sel])
        return out

    def evaluate_segment(self, k: int, times) -> dict:
        """Like :meth:`evaluate`, all times on segment k (e.g. quadrature nodes)."""
        times = np.atleast_1d(np.asarray(times, float))
        out = self._empty(times)
        self._fill(out, np.arange(times.size), self.segments[k], times)
        return out

    def _empty(self, times):
        n, S = self._model.n, self._model.S
        nt = times.size
        per = ("phi", "phi_dot", "z", "z_dot", "gap", "normal_force", "friction_force")
        out = {"t": times.copy(), "q": np.empty((nt, n)), "q_dot": np.empty((nt, n))}
        for name in per:
            out[name] = np.empty((nt, S))
        out["phase"] = np.empty((nt, S), dtype=int)
        out["slip_sign"] = np.empty((nt, S), dtype=int)
        out["disc_speed"] = np.empty(nt)
        out["Omega_dot"] = np.empty(nt)
        out["Omega"] = out["disc_speed"]
        return out

    def _fill(self, out, sel, seg, times):
        model = self._model
        n, S = model.n, model.S
        stick = np.array([p == STICK for p in seg.phases])
        sep = np.array([p == SEPARATION for p in seg.phases])
        for i, t in zip(sel, times, strict=True):
            y = np.array(seg.sol(t), float)
            om = seg.piece.omega(t)
            y[2 * n + S : 2 * n + 2 * S] = np.where(stick, om, y[2 * n + S : 2 * n + 2 * S])
            r = model.solve(seg.phases, seg.signs, t, y, seg.piece)
            out["q"][i] = y[:n]
            out["q_dot"][i] = y[n : 2 * n]
            out["phi"][i] = y[2 * n : 2 * n + S]
            out["phi_dot"][i] = y[2 * n + S : 2 * n + 2 * S]
            out["z"][i] = r["z"]
            out["z_dot"][i] = r["zd"]
            out["gap"][i] = np.where(sep, y[2 * n + 2 * S : 2 * n + 3 * S], 0.0)
            out["normal_force"][i] = r["N"]
            out["friction_force"][i] = r["f"]
            out["phase"][i] = seg.phases
            out["slip_sign"][i] = seg.signs
            out["disc_speed"][i] = om
            out["Omega_dot"][i] = seg.piece.slope


# --------------------------------------------------------------------------- energies
def _per_slider(x, S: int) -> np.ndarray:
    """A per-slider quantity as (..., S): S = 1 also accepts (...) shapes."""
    x = np.asarray(x, float)
    if S == 1 and (x.ndim == 0 or x.shape[-1] != 1):
        return x[..., None]
    if x.shape[-1] != S:
        raise ValueError(f"per-slider array must end with {S} entries, got shape {x.shape}")
    return x


def kinetic_energy_t2(case: Any, state: Mapping, mode_data: ModeData | None = None):
    """T2 = 1/2 sum M qdot^2 + sum_j (1/2 I_j phidot_j^2 + 1/2 m_j zdot_j^2)."""
    md = mode_data if mode_data is not None else mode_data_from_case(case)
    sl = _Sliders.from_case(case)
    qd = np.asarray(state["q_dot"], float)
    phid = _per_slider(state["phi_dot"], sl.S)
    zd = _per_slider(state["z_dot"], sl.S)
    return (
        0.5 * np.sum(md.M * qd**2, axis=-1)
        + 0.5 * np.sum(sl.I * phid**2, axis=-1)
        + 0.5 * np.sum(sl.m * zd**2, axis=-1)
    )


def _state_mapping(case: Any, md: ModeData, state, t, omega) -> Mapping:
    """Turn a state vector ``[q, qdot, phi (S), phidot (S) (, z (S), zdot (S))]`` into the
    mapping form (contact assumed without z, zdot)."""
    if isinstance(state, Mapping):
        return state
    sl = _Sliders.from_case(case)
    n, S = md.n, sl.S
    y = np.asarray(state, float)
    q, qd = y[:n], y[n : 2 * n]
    phi, phid = y[2 * n : 2 * n + S], y[2 * n + S : 2 * n + 2 * S]
    if y.size >= 2 * n + 4 * S:
        z, zd = y[2 * n + 2 * S : 2 * n + 3 * S], y[2 * n + 3 * S : 2 * n + 4 * S]
    else:  # in contact: the slider moves with the disc
        g, gp, _ = _shapes(md, md.radial(sl.r), sl.theta + phi)
        z, zd = g @ q, g @ qd + phid * (gp @ q)
    if omega is None:
        omega = float(speed_at(case.speed, 0.0 if t is None else t)[0][0])
    return {"q": q, "q_dot": qd, "phi": phi, "phi_dot": phid, "z": z, "z_dot": zd, "Omega": omega}


def _omega_of(case, state):
    if "Omega" in state:
        return np.asarray(state["Omega"], float)
    if "disc_speed" in state:
        return np.asarray(state["disc_speed"], float)
    return speed_at(case.speed, state["t"])[0]


def _potential(case, md, sl, state):
    q = np.asarray(state["q"], float)
    z = _per_slider(state["z"], sl.S)
    phi = _per_slider(state["phi"], sl.S)
    return 0.5 * np.sum(md.M * md.omega**2 * q**2, axis=-1) + np.sum(
        0.5 * sl.Kphi * phi**2 + 0.5 * sl.kz * z**2 + sl.sigma * sl.N0 * z, axis=-1
    )


def jacobi_integral(
    case: Any,
    state,
    *,
    t: float | None = None,
    omega: float | None = None,
    mode_data: ModeData | None = None,
):
    """Jacobi integral T2 - T0 + V of disc and sliders (conserved without friction and
    damping at constant speed while sum_j N_j phidot_j (g'_j.q) = 0; see the tests).

    ``state``: a mapping with q, q_dot, phi, phi_dot, z, z_dot and Omega (or disc_speed, or
    t), e.g. the dict of :meth:`ReferenceResult.evaluate` (vectorised over its times;
    per-slider arrays (n_t, S), or (n_t,) for S = 1); or one state vector ``[q, qdot, phi,
    phidot]`` (contact) or ``[q, qdot, phi, phidot, z, zdot]`` (each slider entry S long)
    with the speed given by ``omega`` or by the time ``t`` (default t = 0).

    Disc: T2 = 1/2 sum M qdot^2, T0 = 1/2 sum M l^2 Omega^2 q^2, V = 1/2 sum M omega^2 q^2.
    Slider j: 1/2 I phidot^2 + 1/2 m zdot^2 + 1/2 r^2 k_phi phi^2 + 1/2 k_z z^2 + sigma N0 z.
    """
    md = mode_data if mode_data is not None else mode_data_from_case(case)
    state = _state_mapping(case, md, state, t, omega)
    sl = _Sliders.from_case(case)
    Om = _omega_of(case, state)
    q = np.asarray(state["q"], float)
    t2 = kinetic_energy_t2(case, state, md)
    om2 = Om[..., None] ** 2 if q.ndim > 1 else float(np.squeeze(Om)) ** 2
    t0 = 0.5 * np.sum(md.M * md.l**2 * om2 * q**2, axis=-1)
    return t2 - t0 + _potential(case, md, sl, state)


def mechanical_energy(case: Any, state, *, mode_data: ModeData | None = None):
    """Total mechanical energy E (module docstring): disc kinetic energy on the material
    velocity, sliders' kinetic energies, all potentials (preload included).

    ``state``: as for :func:`jacobi_integral` (mapping; e.g. ``evaluate``'s dict).
    """
    md = mode_data if mode_data is not None else mode_data_from_case(case)
    sl = _Sliders.from_case(case)
    Om = _omega_of(case, state)
    q = np.asarray(state["q"], float)
    qd = np.asarray(state["q_dot"], float)
    p = md.partner
    csign = np.where(md.is_sine, -1.0, 1.0)
    om = Om[..., None] if q.ndim > 1 else float(np.squeeze(Om))
    a = qd + csign * md.l * om * q[..., p]
    phid = _per_slider(state["phi_dot"], sl.S)
    zd = _per_slider(state["z_dot"], sl.S)
    kin = 0.5 * np.sum(md.M * a**2, axis=-1) + np.sum(
        0.5 * sl.I * phid**2 + 0.5 * sl.m * zd**2, axis=-1
    )
    return kin + _potential(case, md, sl, state)


def power_terms(case: Any, out: Mapping, *, mode_data: ModeData | None = None) -> dict:
    """Instantaneous powers along an ``evaluate`` output (module docstring), each (n_t,):

    ``friction`` (-sum r f v), ``drive`` (sum r f Omega), ``surface`` (friction moment on
    the disc's slope rate and the normal force along the moving slope), ``slider_damping``,
    ``disc_damping``, ``options`` (model options that leave the stated model: no Omegadot
    terms, printed gyroscopic sign) and their sum ``total`` = dE/dt.
    """
    md = mode_data if mode_data is not None else mode_data_from_case(case)
    return _power_terms(_Model(case, md), out)


def _power_terms(model: _Model, out: Mapping) -> dict:
    case, md = model.case, model.md
    sl = model.sl
    S = sl.S
    q = np.atleast_2d(np.asarray(out["q"], float))
    qd = np.atleast_2d(np.asarray(out["q_dot"], float))
    nt = q.shape[0]
    phi = _per_slider(out["phi"], S).reshape(nt, S)
    phid = _per_slider(out["phi_dot"], S).reshape(nt, S)
    zd = _per_slider(out["z_dot"], S).reshape(nt, S)
    N = _per_slider(out["normal_force"], S).reshape(nt, S)
    f = _per_slider(out["friction_force"], S).reshape(nt, S)
    Om = np.broadcast_to(_omega_of(case, out), (nt,))
    Omd = np.broadcast_to(np.asarray(out.get("Omega_dot", 0.0), float), (nt,))
    res = {
        k: np.zeros(nt)
        for k in ("friction", "drive", "surface", "slider_damping", "disc_damping", "options")
    }
    for i in range(nt):
        _, GP, GPP = model.shapes(phi[i])
        v = Om[i] - phid[i]
        gpq, gpqd, gppq = GP @ q[i], GP @ qd[i], GPP @ q[i]
        res["friction"][i] = -np.sum(sl.r * f[i] * v)
        res["drive"][i] = np.sum(sl.r * f[i] * Om[i])
        res["surface"][i] = np.sum(
            sl.sigma * sl.hk * f[i] * (gpqd + Om[i] * gppq) - sl.sigma * N[i] * v * gpq
        )
        res["slider_damping"][i] = -np.sum(sl.Cphi * phid[i] ** 2 + sl.cz * zd[i] ** 2)
        a = model.material_velocity(q[i], qd[i], Om[i])
        if np.any(model.zeta):
            vel = a if model.material else qd[i]
            res["disc_damping"][i] = -np.sum(2.0 * model.zeta * md.omega * md.M * vel * a)
        res["options"][i] = a @ model.option_forces(q[i], qd[i], Om[i], Omd[i])
    res["total"] = sum(res[k] for k in list(res))
    return res


def energy_terms(result: ReferenceResult, times=None, *, n_gauss: int = 8) -> dict:
    """Energy balance along a reference trajectory.

    For each of ``times`` (default: the run's end) returns, as arrays: ``energy`` (E at t),
    the work from t = 0 to t of ``friction``, ``drive``, ``surface``, ``slider_damping``,
    ``disc_damping``, ``options`` (the integrals of :func:`power_terms`, Gauss-Legendre
    with ``n_gauss`` nodes on every solver step of every segment), ``impact_loss`` (sum of
    -|du|_W^2 / 2; impact off: the landing sliders' kinetic energy changes) and
    ``impact_surface`` (sum of -lam sigma v g'.q) of the impacts at times <= t, their sum
    ``work`` and ``residual`` = E(t) - E(0) - work (zero up to integration error).
    """
    case, md = result._model.case, result.mode_data
    t_out = np.atleast_1d(np.asarray(result.t_end if times is None else times, float))
    x, wts = np.polynomial.legendre.leggauss(n_gauss)
    names = ("friction", "drive", "surface", "slider_damping", "disc_damping", "options")
    # work on [0, t] per name: integrate every step panel, cut at the requested times
    cum = {k: np.zeros(t_out.size) for k in names}
    for k, seg in enumerate(result.segments):
        edges = np.asarray(seg.ivp.t, float)
        edges = np.unique(np.concatenate([edges, t_out[(t_out > seg.t0) & (t_out < seg.t1)]]))
        edges = edges[(edges >= seg.t0) & (edges <= seg.t1)]
        for a, b in itertools.pairwise(edges):
            if b <= a:
                continue
            nodes = 0.5 * (a + b) + 0.5 * (b - a) * x
            p = _power_terms(result._model, result.evaluate_segment(k, nodes))
            for name in names:
                w = 0.5 * (b - a) * float(np.sum(wts * p[name]))
                cum[name][t_out >= b] += w
    loss = np.zeros(t_out.size)
    surf = np.zeros(t_out.size)
    for imp in result.impacts:
        hit = t_out >= imp["t"]
        loss[hit] += imp["loss"]
        surf[hit] += imp["surface"]
    e = mechanical_energy(case, result.evaluate(t_out), mode_data=md)
    e0 = mechanical_energy(case, result.evaluate([0.0]), mode_data=md)[0]
    out = {"t": t_out, "energy": e, **cum, "impact_loss": loss, "impact_surface": surf}
    out["work"] = sum(cum[k] for k in names) + loss + surf
    out["residual"] = e - e0 - out["work"]
    return out


# --------------------------------------------------------------------------- equilibrium
def sliding_equilibrium(case: Any, mode_data: ModeData | None = None) -> dict:
    """Sliding equilibrium at constant speed (every slider in slip, s = +1, rates zero).

    With v = Omega, mu_j = mu(r_j Omega): ``K q = -sum_j sigma_j N_j (g_j - h_j mu_j g'_j)``,
    ``K = M (omega^2 - l^2 Omega^2)`` plus, for material damping, its ``2 zeta omega M l
    Omega`` coupling of C and D (the material velocity does not vanish at rest);
    ``N_j = N0_j + sigma_j k_zj g_j.q``; ``r_j^2 k_phij phi_j = r_j mu_j N_j``.  Solved in
    phi (secant for S = 1, hybr for S > 1).

    Returns q, q_dot (n,), phi, phi_dot, N (floats for S = 1, else arrays of S).
    """
    from scipy.optimize import newton, root

    md = mode_data if mode_data is not None else mode_data_from_case(case)
    model = _Model(case, md)
    sl, S, n = model.sl, model.S, md.n
    if str(case.speed.profile) != "constant":
        raise ValueError("a sliding equilibrium exists only at constant speed")
    Om = float(case.speed.value)
    mu = np.array([model.friction(sl.r[j] * Om) for j in range(S)])
    K = np.diag(md.M * (md.omega**2 - md.l**2 * Om**2))
    if np.any(model.zeta) and model.material:
        p = model.partner
        for i in range(n):
            if md.l[i] >= 1:
                K[i, p[i]] += (
                    2.0 * model.zeta[i] * md.omega[i] * md.M[i] * model.csign[i] * (md.l[i] * Om)
                )

    def parts(phi):
        g, gp, _ = model.shapes(phi)
        c = g - (sl.hk * mu)[:, None] * gp  # (S, n)
        if n == 0:
            return np.zeros(0), sl.N0.copy()
        Kinv_cT = np.linalg.solve(K, (sl.sigma[:, None] * c).T)  # (n, S)
        A = np.eye(S) + (sl.sigma * sl.kz)[:, None] * (g @ Kinv_cT)
        N = np.linalg.solve(A, sl.N0)
        return -Kinv_cT @ N, N

    def residual(phi):
        return phi - sl.r * mu * parts(phi)[1] / sl.Kphi

    phi_start = sl.r * mu * sl.N0 / sl.Kphi
    if S == 1:
        phi = np.array(
            [
                float(
                    newton(
                        lambda x: residual(np.array([x]))[0], phi_start[0], tol=1e-15, maxiter=100
                    )
                )
            ]
        )
    else:
        sol = root(residual, phi_start, method="hybr", tol=1e-15)
        if not sol.success and np.max(np.abs(residual(sol.x))) > 1e-12:
            raise RuntimeError(f"sliding equilibrium not found: {sol.message}")
        phi = sol.x
    q, N = parts(phi)
    if S == 1:
        return {
            "q": q,
            "q_dot": np.zeros(n),
            "phi": float(phi[0]),
            "phi_dot": 0.0,
            "N": float(N[0]),
        }
    return {"q": q, "q_dot": np.zeros(n), "phi": phi, "phi_dot": np.zeros(S), "N": N}


def free_doublet_eigenvalues(omega: float, l: int, Omega: float, zeta: float, frame: str):
    """Closed-form eigenvalues of a free, damped disc doublet (l >= 1) or mode (l = 0) at
    constant speed (module docstring): the two roots of ``X = C + i D``; the other two are
    their conjugates.  For l = 0 the pair belongs to the real coordinate C."""
    if frame == "material":
        wd = omega * np.sqrt(1.0 - zeta**2 + 0j)
        return np.array(
            [1j * l * Omega - zeta * omega + 1j * wd, 1j * l * Omega - zeta * omega - 1j * wd]
        )
    root_ = np.sqrt(omega**2 * (1.0 - zeta**2) + 2j * zeta * omega * l * Omega)
    return np.array(
        [1j * l * Omega - zeta * omega + 1j * root_, 1j * l * Omega - zeta * omega - 1j * root_]
    )


# --------------------------------------------------------------------------- driver
def _initial_state(case: Any, model: _Model, y0, phase0):
    """Full state, and the given phases (list or None), from y0 / case.simulation."""
    md, n, S = model.md, model.n, model.S
    y = np.zeros(model.size)
    if y0 is None:
        init = getattr(case.simulation, "initial_state", "rest")
        if isinstance(init, str) and init == "rest":
            return y, None if phase0 is None else _as_phases(phase0, S, "phase0")
        if isinstance(init, str) and init == "equilibrium":
            eq = sliding_equilibrium(case, md)
            pert = case.simulation.perturbation
            eq["phi"] = np.asarray(eq["phi"], float) + float(pert.phi)
            eq["phi_dot"] = np.asarray(eq["phi_dot"], float) + float(pert.phi_dot)
            y0 = eq
        elif isinstance(init, Mapping):
            y0 = init
        else:
            raise NotImplementedError(
                f"initial_state {init!r} is not supported by the reference; pass y0"
            )
    if isinstance(y0, Mapping):
        y[:n] = np.asarray(y0.get("q", np.zeros(n)), float)
        y[n : 2 * n] = np.asarray(y0.get("q_dot", np.zeros(n)), float)
        y[2 * n : 2 * n + S] = np.broadcast_to(np.asarray(y0.get("phi", 0.0), float), (S,))
        y[2 * n + S : 2 * n + 2 * S] = np.broadcast_to(
            np.asarray(y0.get("phi_dot", 0.0), float), (S,)
        )
        zz = (y0.get("z"), y0.get("z_dot"))
    else:
        arr = np.asarray(y0, float)
        if arr.size not in (2 * n + 2 * S, 2 * n + 4 * S):
            raise ValueError(
                f"y0 must have 2n+2S or 2n+4S = {2 * n + 4 * S} entries, got {arr.size}"
            )
        y[: 2 * n + 2 * S] = arr[: 2 * n + 2 * S]
        if arr.size == 2 * n + 4 * S:
            zz = (arr[2 * n + 2 * S : 2 * n + 3 * S], arr[2 * n + 3 * S :])
        else:
            zz = (None, None)
    phases = None if phase0 is None else _as_phases(phase0, S, "phase0")
    if phases is not None and SEPARATION in phases:
        if zz[0] is None:
            raise ValueError("a separated start needs z and z_dot")
        q, qd = y[:n], y[n : 2 * n]
        phi, phid = y[2 * n : 2 * n + S], y[2 * n + S : 2 * n + 2 * S]
        g, gp, _ = model.shapes(phi)
        z = np.broadcast_to(np.asarray(zz[0], float), (S,))
        zd = np.broadcast_to(np.asarray(zz[1], float), (S,))
        sg = model.sl.sigma
        for j in range(S):
            if phases[j] == SEPARATION:
                y[2 * n + 2 * S + j] = sg[j] * (z[j] - g[j] @ q)
                y[2 * n + 3 * S + j] = sg[j] * (zd[j] - (g[j] @ qd + phid[j] * (gp[j] @ q)))
    return y, phases


class _Runner:
    """The phase machine: integrates stretches and switches the sliders' phases."""

    def __init__(self, model: _Model, pieces, t_end, rtol, atol, method, max_step, max_switches):
        self.model = model
        self.pieces = pieces
        self.t_end = t_end
        self.rtol, self.atol, self.method = rtol, atol, method
        self.max_step = max_step
        self.max_switches = max_switches
        self.events: list = []
        self.segments: list = []
        self.impacts: list = []
        self.nfev = 0
        self.switches = 0
        n, S = model.n, model.S
        self.i_phi = 2 * n
        self.i_phid = 2 * n + S
        self.i_e = 2 * n + 2 * S
        self.i_ed = 2 * n + 3 * S

    # ---- bookkeeping
    def record(self, t, j, old, new, old_s, new_s, recontact=False):
        if recontact:
            kind = "recontact"
        elif new == SEPARATION and old != SEPARATION:
            kind = "separation"
        elif old == SLIP and new == STICK:
            kind = "stick"
        elif old == STICK and new == SLIP:
            kind = "slip"
        elif old == SLIP and new == SLIP and old_s != new_s:
            kind = "reversal"
        else:
            return
        self.events.append((t, old, new, kind, j))
        self.switches += 1
        if self.switches > self.max_switches:
            raise RuntimeError(f"more than {self.max_switches} phase switches before t = {t}")

    def set_phase(self, t, y, ph, sg, j, new, new_s, recontact=False):
        old, old_s = ph[j], sg[j]
        if new == SEPARATION and old != SEPARATION:
            y[self.i_e + j] = y[self.i_ed + j] = 0.0  # gap and its rate start at 0
        ph[j], sg[j] = new, (new_s if new == SLIP else 0)
        self.record(t, j, old, new, old_s, sg[j], recontact)

    # ---- phase choice from the state
    def choose_contact(self, t, y, ph, sg, j, piece, v_zero):
        """(phase, s) for slider j in contact, the others in their phases ph."""
        model = self.model
        if v_zero:
            y[self.i_phid + j] = piece.omega(t)
            trial_ph, trial_sg = list(ph), list(sg)
            trial_ph[j], trial_sg[j] = STICK, 0
            st = model.solve(trial_ph, trial_sg, t, y, piece)
            if st["N"][j] < 0.0:
                return SEPARATION, 0
            if abs(st["f"][j]) <= model.mu_s * st["N"][j]:
                return STICK, 0
            s = 1 if st["f"][j] > 0.0 else -1
        else:
            v = piece.omega(t) - y[self.i_phid + j]
            s = 1 if v > 0.0 else -1
        trial_ph, trial_sg = list(ph), list(sg)
        trial_ph[j], trial_sg[j] = SLIP, s
        if model.solve(trial_ph, trial_sg, t, y, piece)["N"][j] < 0.0:
            return SEPARATION, 0
        return SLIP, s

    def vtol(self, piece, t):
        return 1e-13 * max(1.0, abs(piece.omega(t)))

    def settle(self, t, y, ph, sg, piece, fresh, only_separations=False):
        """Re-check every slider in contact; the lowest-index violator switches, repeatedly."""
        model = self.model
        S = model.S
        log = self.set_phase
        if only_separations:

            def log(t_, y_, ph_, sg_, j_, new, new_s, recontact=False):
                old = ph_[j_]
                if new == SEPARATION and old != SEPARATION:
                    y_[self.i_e + j_] = y_[self.i_ed + j_] = 0.0
                ph_[j_], sg_[j_] = new, (new_s if new == SLIP else 0)
                if new == SEPARATION and old != SEPARATION:
                    self.record(t_, j_, old, new, 0, 0)

        for _ in range(8 * S * S + 8):
            r = model.solve(ph, sg, t, y, piece)
            for j in range(S):
                if ph[j] == SEPARATION:
                    continue
                if r["N"][j] < 0.0:
                    if ph[j] == STICK:
                        y[self.i_phid + j] = piece.omega(t)
                    log(t, y, ph, sg, j, SEPARATION, 0)
                    fresh.add(j)
                    break
                if ph[j] == STICK and abs(r["f"][j]) > model.mu_s * r["N"][j]:
                    s = 1 if r["f"][j] > 0.0 else -1
                    trial_ph, trial_sg = list(ph), list(sg)
                    trial_ph[j], trial_sg[j] = SLIP, s
                    new = SLIP
                    if model.solve(trial_ph, trial_sg, t, y, piece)["N"][j] < 0.0:
                        new, s = SEPARATION, 0
                    log(t, y, ph, sg, j, new, s)
                    fresh.add(j)
                    break
                if (
                    ph[j] == SLIP
                    and j not in fresh
                    and sg[j] * (piece.omega(t) - y[self.i_phid + j]) <= self.vtol(piece, t)
                ):
                    fresh.add(j)
                    new, s = self.choose_contact(t, y, ph, sg, j, piece, v_zero=True)
                    if (new, s) != (ph[j], sg[j]):
                        log(t, y, ph, sg, j, new, s)
                        break
            else:
                return
        # no fixed point within the cap: go on with the current phases (cannot loop in time)

    # ---- re-contact
    def recontact(self, t, y, ph, sg, j, piece, fresh):
        model = self.model
        md, sl, n, S = model.md, model.sl, model.n, model.S
        for i in range(S):  # a sticking slider moves with the disc exactly
            if ph[i] == STICK:
                y[self.i_phid + i] = piece.omega(t)
        y_minus = y.copy()
        q, qd = y[:n].copy(), y[n : 2 * n].copy()
        phi, phid = y[self.i_phi : self.i_phi + S], y[self.i_phid : self.i_phid + S]
        G, GP, _ = model.shapes(phi)
        r_minus = model.solve(ph, sg, t, y, piece)
        zd_minus = r_minus["zd"].copy()
        z_now = r_minus["z"].copy()
        y[self.i_e + j] = 0.0
        Om = piece.omega(t)
        if not model.impact:
            wd_j = G[j] @ qd + phid[j] * (GP[j] @ q)
            y[self.i_ed + j] = 0.0
            loss = 0.5 * sl.m[j] * (wd_j**2 - zd_minus[j] ** 2)
            landing = [j]
            released: list[int] = []
            info = {
                "contacts": [j],
                "lam": np.zeros(1),
                "b": np.zeros(1),
                "du_W2": 0.0,
                "dT2": loss,
                "forced": [],
                "impact": False,
                "loss": loss,
                "surface": 0.0,
                "zdot_minus": float(zd_minus[j]),
                "zdot_plus": float(wd_j),
                "gap_rate_minus": np.array([sl.sigma[j] * (zd_minus[j] - wd_j)]),
                "gap_rate_plus": np.zeros(1),
            }
        else:
            contacts = [
                i
                for i in range(S)
                if i == j or ph[i] != SEPARATION or y[self.i_e + i] <= model.z_roundoff(i, z_now[i])
            ]
            cidx = np.array(contacts)
            forced: set[int] = set()
            while True:
                imp = plastic_impact(
                    md.M,
                    sl.m[cidx],
                    sl.sigma[cidx],
                    G[cidx],
                    GP[cidx],
                    q,
                    qd,
                    phid[cidx],
                    zd_minus[cidx],
                    forced=sorted(forced),
                )
                active = set(imp["active"])
                rel = [k for k in range(len(contacts)) if k not in active]
                # flight of each released contact: gap rate gp+ > 0, gap acceleration below
                y_try = y.copy()
                y_try[n : 2 * n] = imp["qdot"]
                ph_try, sg_try = list(ph), list(sg)
                for k, i in enumerate(contacts):
                    y_try[self.i_e + i] = 0.0
                    if k in active:
                        y_try[self.i_ed + i] = 0.0
                        if ph_try[i] == SEPARATION:
                            ph_try[i], sg_try[i] = STICK, 0  # any contact phase: only eddot
                    else:
                        y_try[self.i_ed + i] = imp["gap_rate_plus"][k]
                        ph_try[i], sg_try[i] = SEPARATION, 0
                if not rel:
                    break
                edd = model.solve(ph_try, sg_try, t, y_try, piece)["edd"]
                newly = set()
                for k in rel:
                    i = contacts[k]
                    rate = imp["gap_rate_plus"][k]
                    acc = edd[i]
                    if acc < 0.0:
                        flight = 2.0 * rate / -acc
                        peak = rate**2 / (-2.0 * acc)
                        if flight < model.min_flight_time or peak < model.z_roundoff(i, z_now[i]):
                            newly.add(k)
                if not newly:
                    break
                forced |= newly
            qd_new = imp["qdot"]
            y[n : 2 * n] = qd_new
            # a slider in flight is not struck: its zdot stays, so its gap rate (relative to
            # the disc, whose velocity jumps) changes by -sigma G (qdot+ - qdot-)
            for i in range(S):
                if i not in contacts and ph[i] == SEPARATION:
                    y[self.i_ed + i] -= sl.sigma[i] * (G[i] @ (qd_new - qd))
            landing, released = [], []
            for k, i in enumerate(contacts):
                y[self.i_e + i] = 0.0
                if k in active:
                    y[self.i_ed + i] = 0.0
                    if ph[i] == SEPARATION:
                        landing.append(i)
                else:
                    y[self.i_ed + i] = imp["gap_rate_plus"][k]
                    released.append(i)
            lam = imp["lam"]
            v = Om - phid[cidx]
            surface = float(-np.sum(lam * sl.sigma[cidx] * v * (GP[cidx] @ q)))
            k_j = contacts.index(j)
            info = {
                "contacts": contacts,
                "lam": lam,
                "b": imp["b"],
                "du_W2": imp["du_W2"],
                "dT2": imp["dT2"],
                "forced": [contacts[k] for k in sorted(forced)],
                "impact": True,
                "loss": -0.5 * imp["du_W2"],
                "surface": surface,
                "zdot_minus": float(zd_minus[j]),
                "zdot_plus": float(imp["zdot"][k_j]),
                "gap_rate_minus": imp["gap_rate_minus"],
                "gap_rate_plus": imp["gap_rate_plus"],
            }
        # phases, in slider order: released contacts separate, landing sliders choose
        for i in range(S):
            if i in released and ph[i] != SEPARATION:
                if ph[i] == STICK:
                    y[self.i_phid + i] = Om
                old, old_s = ph[i], sg[i]
                ph[i], sg[i] = SEPARATION, 0  # gap rate set above (not reset to 0)
                self.record(t, i, old, SEPARATION, old_s, 0)
                fresh.add(i)
            elif i in landing:
                v = Om - y[self.i_phid + i]
                v_zero = abs(v) <= self.vtol(piece, t)
                new, s = self.choose_contact(t, y, ph, sg, i, piece, v_zero=v_zero)
                self.set_phase(t, y, ph, sg, i, new, s, recontact=True)
                fresh.add(i)
            elif i == j:  # released by the impact itself: a touch, still separated
                self.record(t, i, SEPARATION, SEPARATION, 0, 0, recontact=True)
                fresh.add(i)
        info.update({"t": t, "slider": j, "y_minus": y_minus, "y_plus": y.copy()})
        self.impacts.append(info)

    # ---- the main loop
    def run(self, y, phases0) -> None:
        model, pieces = self.model, self.pieces
        S = model.S
        t = 0.0
        piece = _piece_at(pieces, t)
        if phases0 is None:
            ph, sg = [], []
            for j in range(S):
                v = piece.omega(t) - y[self.i_phid + j]
                if v == 0.0:
                    ph.append(STICK)
                    sg.append(0)
                else:
                    ph.append(SLIP)
                    sg.append(1 if v > 0.0 else -1)
            fresh: set[int] = set()
            # a v = 0 start takes the stick test; stick -> slip here is not logged
            for j in range(S):
                if ph[j] == STICK:
                    new, s = self.choose_contact(t, y, ph, sg, j, piece, v_zero=True)
                    if new != SEPARATION:
                        ph[j], sg[j] = new, s
                    fresh.add(j)
            self.settle(t, y, ph, sg, piece, fresh, only_separations=True)
        else:
            ph = list(phases0)
            sg = [0] * S
            fresh = set()
            for j in range(S):
                if ph[j] == SEPARATION:
                    continue
                v = piece.omega(t) - y[self.i_phid + j]
                if ph[j] == STICK:
                    new, s = self.choose_contact(t, y, ph, sg, j, piece, v_zero=True)
                    ph[j], sg[j] = (new, s) if new != SEPARATION else (STICK, 0)
                    fresh.add(j)
                else:
                    sg[j] = 1 if v >= 0.0 else -1
            self.settle(t, y, ph, sg, piece, fresh, only_separations=True)

        stalled = 0
        fresh: set[int] = set()  # sliders switched at the current instant
        while t < self.t_end:
            piece = _piece_at(pieces, t)
            t_stop = min(piece.t_b, self.t_end)
            fun = model.rhs(ph, sg, piece)
            evs, names = model.events(ph, sg, piece, t, y)
            ivp = solve_ivp(
                fun,
                (t, t_stop),
                y,
                method=self.method,
                rtol=self.rtol,
                atol=self.atol,
                dense_output=True,
                events=evs,
                max_step=self.max_step,
            )
            if ivp.status < 0:
                raise RuntimeError(f"solve_ivp failed at t = {t!r} in {ph}: {ivp.message}")
            self.nfev += ivp.nfev
            t_new = float(ivp.t[-1])
            y_new = np.array(ivp.y[:, -1], float)
            if ivp.status == 1:
                which = next(i for i, te in enumerate(ivp.t_events) if te.size)
                t_new = float(ivp.t_events[which][0])
                y_new = np.array(ivp.y_events[which][0], float)
            if t_new > t:
                self.segments.append(Segment(t, t_new, tuple(ph), tuple(sg), ivp, piece))
                stalled = 0
            else:
                stalled += 1
                if stalled > 50:
                    raise RuntimeError(f"phase switches do not advance in time at t = {t}")
            new_piece = _piece_at(pieces, t_new)
            if t_new > t:
                fresh = set()
            if ivp.status == 1:
                for j, cause in self.simultaneous(ivp, evs, names, which, t_new, y_new):
                    self.handle(t_new, y_new, ph, sg, j, cause, new_piece, fresh)
                self.settle(t_new, y_new, ph, sg, new_piece, fresh)
            elif t_new < self.t_end:  # a speed breakpoint: re-check with the new Omegadot
                for j in range(S):
                    if ph[j] == STICK:
                        new, s = self.choose_contact(t_new, y_new, ph, sg, j, new_piece, True)
                    elif ph[j] == SLIP:
                        v = new_piece.omega(t_new) - y_new[self.i_phid + j]
                        new, s = self.choose_contact(
                            t_new, y_new, ph, sg, j, new_piece, v_zero=(v == 0.0)
                        )
                    else:
                        continue
                    self.set_phase(t_new, y_new, ph, sg, j, new, s)
                    fresh.add(j)
                self.settle(t_new, y_new, ph, sg, new_piece, fresh)
            t, y = t_new, y_new

    def simultaneous(self, ivp, evs, names, which, t, y):
        """The event ``names[which]`` at t and every other exit of the stretch whose root lies
        within ``t_tol = 1e-14 max(1, t)`` s after it (or that has already crossed at t, to
        round-off), in slider order: [(slider, cause)].

        scipy stops at the earliest root; the others are found by brentq on the dense output
        of the same step (``ivp.sol.interpolants[-1]``, valid to the step's end).  Two exits
        that mathematically coincide (symmetric sliders) are located ~1e-16 s apart by
        round-off; 1e-14 s is ~20x brentq's location accuracy.  N = 0 takes precedence over
        the other exit of the same slider."""
        from scipy.optimize import brentq

        interp = ivp.sol.interpolants[-1]
        t_b = float(interp.t)
        t_tol = 1e-14 * max(1.0, abs(t))
        j0, cause0 = names[which]
        found = {j0: cause0}
        for k, (ev, (j, cause)) in enumerate(zip(evs, names, strict=True)):
            if k == which:
                continue
            d = ev.direction
            g_t = ev(t, y)
            hit = d * g_t >= 0.0
            if not hit and t_b > t:
                g_b = ev(t_b, interp(t_b))
                if d * g_b >= 0.0:
                    root = brentq(
                        lambda tt, ev=ev: ev(tt, interp(tt)), t, t_b, xtol=4 * _EPS, rtol=4 * _EPS
                    )
                    hit = root - t <= t_tol
            if hit and (j not in found or cause == "N0"):
                found[j] = cause
        return sorted(found.items())

    def handle(self, t, y, ph, sg, j, cause, piece, fresh):
        model = self.model
        fresh.add(j)
        if cause == "v0":
            new, s = self.choose_contact(t, y, ph, sg, j, piece, v_zero=True)
            self.set_phase(t, y, ph, sg, j, new, s)
        elif cause == "friction_limit":
            y[self.i_phid + j] = piece.omega(t)
            f = model.solve(ph, sg, t, y, piece)["f"][j]
            s = 1 if f > 0.0 else -1
            trial_ph, trial_sg = list(ph), list(sg)
            trial_ph[j], trial_sg[j] = SLIP, s
            new = SLIP
            if model.solve(trial_ph, trial_sg, t, y, piece)["N"][j] < 0.0:
                new, s = SEPARATION, 0
            self.set_phase(t, y, ph, sg, j, new, s)
        elif cause == "N0":
            if ph[j] == STICK:
                y[self.i_phid + j] = piece.omega(t)
            self.set_phase(t, y, ph, sg, j, SEPARATION, 0)
        else:  # gap0
            self.recontact(t, y, ph, sg, j, piece, fresh)


def reference_simulate(
    case: Any,
    t_end: float | None = None,
    *,
    rtol: float = 1e-12,
    atol: float = 1e-14,
    method: str = "DOP853",
    y0=None,
    phase0=None,
    mode_data: ModeData | None = None,
    max_step: float | None = None,
    max_switches: int | None = None,
) -> ReferenceResult:
    """Integrate the phase machine of equations.md from t = 0 to ``t_end``.

    Parameters
    ----------
    case : fivdisc.case.Case, or an object with the attributes of the module docstring
    t_end : float, default ``case.simulation.duration`` [s]
    rtol, atol : solve_ivp tolerances (atol applies to every state component)
    method : solve_ivp method ("DOP853" for the reference, "RK45" for the speed baseline)
    y0 : optional initial state: a mapping with ``q``, ``q_dot`` (n), ``phi``, ``phi_dot``
        (S, or scalars for S = 1 / the same for all) and, for separated starts, ``z``,
        ``z_dot`` (S); or an array ``[q, qdot, phi (S), phidot (S)]`` (+ ``[z (S), zdot
        (S)]``).  Default: ``case.simulation.initial_state`` ("rest" or "equilibrium").
    phase0 : optional initial phase, one for all or one per slider (0 slip, 1 stick,
        2 separation: needs z, z_dot); default: chosen from the state.
    mode_data : optional :class:`ModeData` instead of computing it from ``case.disc``.
    max_step : largest solve_ivp step [s]; default ``case.simulation.max_step`` (0 = none).
    max_switches : raise RuntimeError after that many phase switches; default
        ``case.simulation.max_switches`` (else 200000).
    """
    md = mode_data if mode_data is not None else mode_data_from_case(case)
    model = _Model(case, md)
    if t_end is None:
        t_end = float(case.simulation.duration)
    if max_step is None:
        max_step = float(getattr(case.simulation, "max_step", 0.0))
    if not max_step or max_step <= 0.0:
        max_step = math.inf
    if max_switches is None:
        max_switches = int(getattr(case.simulation, "max_switches", 200_000))
    pieces = _speed_pieces(case.speed, t_end)
    y, phases = _initial_state(case, model, y0, phase0)
    runner = _Runner(model, pieces, float(t_end), rtol, atol, method, max_step, max_switches)
    runner.run(y, phases)
    return ReferenceResult(
        runner.events, runner.segments, md, runner.impacts, float(t_end), runner.nfev, model
    )
