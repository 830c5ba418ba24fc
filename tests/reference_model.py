"""Slow, plain reference model of the slider on a spinning annular disc.

This module is an *independent* implementation of the model stated in
``docs/model.md`` (the printed paper has errors; that page wins, see
``docs/deviations.md``).  It exists to check the package's fast (numba) simulator and to serve as
the speed baseline of the benchmarks.  It deliberately shares no code with
``fivdisc._kernels`` or ``fivdisc.simulate``: it only takes modal data from
``fivdisc.plate`` and parameters from a ``fivdisc.case.Case`` (or any object with
the same attributes).

How it differs from the fast code, on purpose
---------------------------------------------
* At every right-hand-side evaluation the FULL linear system of the unknown
  accelerations (and of the normal force N) is assembled as a dense
  ``(n+2) x (n+2)`` (slip, separation) or ``(n+1) x (n+1)`` (stick) matrix and
  solved with :func:`numpy.linalg.solve` (no low-rank / Sherman-Morrison trick).
* Each phase is integrated with :func:`scipy.integrate.solve_ivp` (dense output)
  and Python event functions; event times are located by scipy's root finder
  on the dense output (``brentq``, ~4 eps relative in t).
* In separation the state carries the *gap* ``e = z - w(r0, phi)`` and its rate
  instead of ``z`` and ``zdot`` (mathematically the same ODE,
  ``m z'' + c_z z' + k_z z + N0 = 0`` with ``z = w + e``).  The gap starts at
  exactly 0 with exactly zero rate, so the re-contact event ``e = 0`` cannot
  fire spuriously at the start of a separation through integration error in
  ``z - w`` (two O(1e-5 m) numbers).

State vector (all phases): ``y = [q (n), qdot (n), phi, phidot, e, edot]``;
``e = edot = 0`` in contact.  Modal coordinates are ordered, for each ``(k, l)``
of ``case.disc.modes``: ``C_kl`` then ``D_kl`` if ``l >= 1``.

Phases: 0 = slip, 1 = stick, 2 = separation.

Phase choice and event re-arming
--------------------------------
* slip (sign s): exits when ``v = Omega - phidot`` reaches 0 (event direction
  ``-s``) or when ``N`` reaches 0 (direction -1).  At ``v = 0`` the slider's
  ``phidot`` is set to ``Omega`` exactly and the next phase is chosen from the
  state: stick if ``N_stick >= 0`` and ``|f_stick| <= mu_s N_stick``; else slip
  with ``s = sign(f_stick)`` (a "reversal" when s changes); separation if the
  chosen contact phase has ``N < 0``.
* stick: exits when ``|f| - mu_s N`` reaches 0 from below (direction +1): then
  slip with ``s = sign(f)`` (the event itself is the evidence that the
  friction limit was reached; re-testing ``|f| <= mu_s N`` at a point located
  only to round-off could pick stick again and loop); or when ``N`` reaches 0.
* separation: exits when the gap ``e`` reaches 0 from above (direction -1);
  the plastic impact map is applied (unless ``case.simulation.impact`` is
  False), then the phase is chosen from the state as above (``v == 0`` within
  round-off -> stick test; ``N < 0`` -> separate again).
* At the start of a phase the exit functions that are exactly zero there
  (``v`` after stick/reversal, ``e`` after separation) move away from zero on
  the side that their ``direction`` ignores, so they cannot fire again at the
  initial time (scipy counts a root only for a sign change in the given
  direction).  A hard limit on the number of switches, and on switches without
  progress in time, guards against endless loops.
* Kinks of the speed profile (``t_max`` of a decelerating profile, table
  knots) are integration breakpoints: the integration stops there, the phase
  is re-checked with the new ``Omegadot`` and the integration restarts.

Within each integration window the speed is exactly linear in t (all the
profiles are piecewise linear), so ``Omega(t) = Omega_a + Omegadot (t - t_a)``
with a constant ``Omegadot``.

Case options honoured: ``simulation.impact``, ``omega_dot_terms``,
``printed_gyroscopic_sign``, ``initial_state`` ("rest" or "equilibrium" plus
``perturbation``), ``max_step``, ``max_switches``.

Two properties of the stated model (not of this code) that checks must respect
------------------------------------------------------------------------------
* The slider's phi equation has no component of the normal force along the
  disc's slope, so without friction and damping the Jacobi integral changes at
  the rate ``N phidot (g'.q)``; it is a first integral only while that is zero
  (e.g. phi = phidot = 0 and f = 0).
* For the same reason the plastic impact map changes
  ``T2 = 1/2 sum M qdot^2 + 1/2 m zdot^2`` by exactly ``-u (u/2 + b) / K`` with
  ``u`` the approach velocity (< 0), ``b = phidot (g'.q)`` and
  ``K = 1/m + sum g^2/M``: T2 cannot increase when ``b = 0`` but can if
  ``b > |u|/2`` (a grazing re-contact of a fast-moving slider on a sloped disc).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

__all__ = [
    "CONTACT_PHASES",
    "SEPARATION",
    "SLIP",
    "STICK",
    "ModeData",
    "ReferenceResult",
    "Segment",
    "impact_map",
    "jacobi_integral",
    "kinetic_energy_t2",
    "mode_data_from_case",
    "reference_simulate",
    "sliding_equilibrium",
    "speed_at",
]

SLIP, STICK, SEPARATION = 0, 1, 2
CONTACT_PHASES = (SLIP, STICK)
PHASE_NAMES = {SLIP: "slip", STICK: "stick", SEPARATION: "separation"}


# --------------------------------------------------------------------------- modal data
@dataclass(frozen=True)
class ModeData:
    """Per modal coordinate (C and D separately): R(r0), modal mass, omega, l, sine flag."""

    R0: np.ndarray
    M: np.ndarray
    omega: np.ndarray
    l: np.ndarray
    is_sine: np.ndarray

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

    @classmethod
    def from_lists(cls, R0, M, omega, l, is_sine) -> ModeData:
        return cls(
            np.asarray(R0, float),
            np.asarray(M, float),
            np.asarray(omega, float),
            np.asarray(l, int),
            np.asarray(is_sine, bool),
        )


def mode_data_from_case(case: Any) -> ModeData:
    """Modal data of ``case.disc.modes`` at the slider's radius, from ``fivdisc.plate``."""
    modes = list(case.disc.modes)
    R0, M, om, ll, sine = [], [], [], [], []
    if modes:
        from fivdisc.plate import AnnularPlate

        plate = AnnularPlate.from_disc(case.disc)
        r0 = float(case.slider.track_radius)
        for k, l in modes:
            mode = plate.mode(int(k), int(l))
            r = float(np.asarray(mode.shape(r0)))
            for is_sine in (False, True) if l >= 1 else (False,):
                R0.append(r)
                M.append(float(mode.modal_mass))
                om.append(float(mode.omega))
                ll.append(int(l))
                sine.append(is_sine)
    return ModeData.from_lists(R0, M, om, ll, sine)


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


# --------------------------------------------------------------------------- the model
class _Model:
    """Parameters and the phase right-hand sides (plain numpy, full dense solves)."""

    def __init__(self, case: Any, md: ModeData):
        sl, fr, sim = case.slider, case.friction, case.simulation
        self.md = md
        self.n = md.n
        self.r0 = float(sl.track_radius)
        self.m = float(sl.mass)
        self.kz = float(sl.normal_stiffness)
        self.cz = float(sl.normal_damping)
        self.Kphi = float(sl.rotational_stiffness)  # r0^2 k_phi
        self.Cphi = float(sl.rotational_damping)  # r0^2 c_phi
        self.N0 = float(sl.preload)
        self.I = self.m * self.r0**2
        self.mu_s = float(fr.static)
        self.mu0 = float(fr.kinetic_max)
        self.mu1 = float(fr.kinetic_min)
        self.alpha = float(fr.decay)
        self.hk = float(case.disc.thickness) / (2.0 * self.r0)  # h / (2 r0)
        self.omega_dot_terms = bool(getattr(sim, "omega_dot_terms", True))
        self.impact = bool(getattr(sim, "impact", True))
        self.partner = md.partner
        # sign of the coupling terms on the right-hand side: -1 for C, +1 for D ...
        self.dsign = np.where(md.is_sine, 1.0, -1.0)
        # ... except the D equations' gyroscopic term with the printed paper's sign
        # (+2 l M Omega Cdot on the left: not skew), an option for comparison only
        printed = bool(getattr(sim, "printed_gyroscopic_sign", False))
        self.gsign = np.where(md.is_sine, -1.0 if printed else 1.0, -1.0)
        self.lf = md.l.astype(float)

    # ---- kinematics
    def kin(self, phi: float):
        md = self.md
        lphi = self.lf * phi
        c, s = np.cos(lphi), np.sin(lphi)
        g = md.R0 * np.where(md.is_sine, s, c)
        gp = md.R0 * self.lf * np.where(md.is_sine, c, -s)
        gpp = -(self.lf**2) * g
        return g, gp, gpp

    def mu(self, v: float) -> float:
        return self.mu1 + (self.mu0 - self.mu1) * math.exp(-self.alpha * abs(self.r0 * v))

    def split(self, y):
        n = self.n
        return y[:n], y[n : 2 * n], y[2 * n], y[2 * n + 1], y[2 * n + 2], y[2 * n + 3]

    def disc_free(self, q, qd, Om, Omd):
        """Disc terms moved to the right: -gyro - Omegadot terms - stiffness."""
        md, p = self.md, self.partner
        eps = 1.0 if self.omega_dot_terms else 0.0
        lM = self.lf * md.M
        b = self.gsign * 2.0 * lM * Om * qd[p] + self.dsign * eps * lM * Omd * q[p]
        b -= md.M * (md.omega**2 - self.lf**2 * Om**2) * q
        return b

    # ---- phase solves: each returns a dict with the accelerations, N and f
    def solve_slip(self, t, y, piece: _Piece, s: int):
        n, m = self.n, self.m
        q, qd, phi, phid, _, _ = self.split(y)
        Om, Omd = piece.omega(t), piece.slope
        g, gp, gpp = self.kin(phi)
        v = Om - phid
        mu = self.mu(v)
        gpq = gp @ q
        z = g @ q
        zd = g @ qd + phid * gpq
        A = np.zeros((n + 2, n + 2))
        A[np.arange(n), np.arange(n)] = self.md.M
        A[:n, n + 1] = g - self.hk * s * mu * gp
        A[n, n] = self.I
        A[n, n + 1] = -self.r0 * s * mu
        A[n + 1, :n] = -m * g
        A[n + 1, n] = -m * gpq
        A[n + 1, n + 1] = 1.0
        rhs = np.empty(n + 2)
        rhs[:n] = self.disc_free(q, qd, Om, Omd)
        rhs[n] = -self.Cphi * phid - self.Kphi * phi
        rhs[n + 1] = (
            self.N0
            + m * (2.0 * phid * (gp @ qd) + phid**2 * (gpp @ q))
            + self.cz * zd
            + self.kz * z
        )
        x = np.linalg.solve(A, rhs)
        N = x[n + 1]
        return {"qdd": x[:n], "phidd": x[n], "N": N, "f": s * mu * N, "z": z, "zd": zd}

    def solve_stick(self, t, y, piece: _Piece):
        n, m = self.n, self.m
        q, qd, phi, _, _, _ = self.split(y)
        Om, Omd = piece.omega(t), piece.slope
        g, gp, gpp = self.kin(phi)
        f = (self.I * Omd + self.Cphi * Om + self.Kphi * phi) / self.r0
        gpq = gp @ q
        z = g @ q
        zd = g @ qd + Om * gpq
        A = np.zeros((n + 1, n + 1))
        A[np.arange(n), np.arange(n)] = self.md.M
        A[:n, n] = g
        A[n, :n] = -m * g
        A[n, n] = 1.0
        rhs = np.empty(n + 1)
        rhs[:n] = self.disc_free(q, qd, Om, Omd) + self.hk * f * gp
        rhs[n] = (
            self.N0
            + m * (2.0 * Om * (gp @ qd) + Om**2 * (gpp @ q) + Omd * gpq)
            + self.cz * zd
            + self.kz * z
        )
        x = np.linalg.solve(A, rhs)
        return {"qdd": x[:n], "phidd": Omd, "N": x[n], "f": f, "z": z, "zd": zd}

    def solve_sep(self, t, y, piece: _Piece):
        n, m = self.n, self.m
        q, qd, phi, phid, e, ed = self.split(y)
        Om, Omd = piece.omega(t), piece.slope
        g, gp, gpp = self.kin(phi)
        gpq = gp @ q
        z = g @ q + e
        zd = g @ qd + phid * gpq + ed
        A = np.zeros((n + 2, n + 2))
        A[np.arange(n), np.arange(n)] = self.md.M
        A[n, n] = self.I
        A[n + 1, :n] = m * g
        A[n + 1, n] = m * gpq
        A[n + 1, n + 1] = m
        rhs = np.empty(n + 2)
        rhs[:n] = self.disc_free(q, qd, Om, Omd)
        rhs[n] = -self.Cphi * phid - self.Kphi * phi
        rhs[n + 1] = -(self.cz * zd + self.kz * z + self.N0) - m * (
            2.0 * phid * (gp @ qd) + phid**2 * (gpp @ q)
        )
        x = np.linalg.solve(A, rhs)
        return {"qdd": x[:n], "phidd": x[n], "edd": x[n + 1], "N": 0.0, "f": 0.0, "z": z, "zd": zd}

    def solve(self, phase, s, t, y, piece):
        if phase == SLIP:
            return self.solve_slip(t, y, piece, s)
        if phase == STICK:
            return self.solve_stick(t, y, piece)
        return self.solve_sep(t, y, piece)

    # ---- right-hand sides and events for solve_ivp
    def rhs(self, phase, s, piece):
        n = self.n

        if phase == SLIP:

            def fun(t, y):
                r = self.solve_slip(t, y, piece, s)
                dy = np.zeros(2 * n + 4)
                dy[:n] = y[n : 2 * n]
                dy[n : 2 * n] = r["qdd"]
                dy[2 * n] = y[2 * n + 1]
                dy[2 * n + 1] = r["phidd"]
                return dy

        elif phase == STICK:

            def fun(t, y):
                r = self.solve_stick(t, y, piece)
                dy = np.zeros(2 * n + 4)
                dy[:n] = y[n : 2 * n]
                dy[n : 2 * n] = r["qdd"]
                dy[2 * n] = piece.omega(t)  # phidot = Omega exactly in stick
                dy[2 * n + 1] = piece.slope
                return dy

        else:

            def fun(t, y):
                r = self.solve_sep(t, y, piece)
                dy = np.empty(2 * n + 4)
                dy[:n] = y[n : 2 * n]
                dy[n : 2 * n] = r["qdd"]
                dy[2 * n] = y[2 * n + 1]
                dy[2 * n + 1] = r["phidd"]
                dy[2 * n + 2] = y[2 * n + 3]
                dy[2 * n + 3] = r["edd"]
                return dy

        return fun

    def events(self, phase, s, piece):
        """(list of event functions, list of names) for the phase."""
        n = self.n
        if phase == SLIP:

            def ev_v(t, y):
                return piece.omega(t) - y[2 * n + 1]

            ev_v.terminal, ev_v.direction = True, -float(s)

            def ev_N(t, y):
                return self.solve_slip(t, y, piece, s)["N"]

            ev_N.terminal, ev_N.direction = True, -1.0
            return [ev_v, ev_N], ["v0", "N0"]
        if phase == STICK:

            def ev_f(t, y):
                r = self.solve_stick(t, y, piece)
                return abs(r["f"]) - self.mu_s * r["N"]

            ev_f.terminal, ev_f.direction = True, 1.0

            def ev_N(t, y):
                return self.solve_stick(t, y, piece)["N"]

            ev_N.terminal, ev_N.direction = True, -1.0
            return [ev_f, ev_N], ["friction_limit", "N0"]

        def ev_gap(t, y):
            return y[2 * n + 2]

        ev_gap.terminal, ev_gap.direction = True, -1.0
        return [ev_gap], ["gap0"]

    # ---- phase choice from the state (contact assumed, e = edot = 0)
    def choose_contact(self, t, y, piece, v_zero: bool):
        """Return (phase, s) for a contact state; SEPARATION if the contact phase has N < 0.

        ``v_zero``: the relative velocity is zero (phidot has been set to Omega).
        """
        if v_zero:
            st = self.solve_stick(t, y, piece)
            if st["N"] < 0.0:
                return SEPARATION, 0
            if abs(st["f"]) <= self.mu_s * st["N"]:
                return STICK, 0
            s = 1 if st["f"] > 0.0 else -1
        else:
            v = piece.omega(t) - y[2 * self.n + 1]
            s = 1 if v > 0.0 else -1
        if self.solve_slip(t, y, piece, s)["N"] < 0.0:
            return SEPARATION, 0
        return SLIP, s


def _impact(model: _Model, y: np.ndarray) -> tuple[np.ndarray, dict]:
    """Plastic impact map at re-contact for a separation state y (gap ~ 0)."""
    n = model.n
    q, qd, phi, phid, _, ed = model.split(y)
    g, gp, _ = model.kin(phi)
    zd_minus = g @ qd + phid * (gp @ q) + ed
    qd_plus, zd_plus = impact_map(model.md, model.m, q, qd, phi, phid, zd_minus)
    y2 = y.copy()
    y2[n : 2 * n] = qd_plus
    y2[2 * n + 2] = 0.0
    y2[2 * n + 3] = 0.0
    return y2, {"zdot_minus": zd_minus, "zdot_plus": zd_plus}


def impact_map(md: ModeData, m: float, q, qdot, phi, phidot, zdot_minus):
    """Perfectly plastic impact (equations.md): returns (qdot_plus, zdot_plus)."""
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
    """One integrated phase: solve_ivp's result (``ivp``, dense ``sol``) on [t0, t1]."""

    t0: float
    t1: float
    phase: int
    sign: int  # slip sign s (0 outside slip)
    ivp: Any
    piece: _Piece

    @property
    def sol(self):
        return self.ivp.sol


@dataclass
class ReferenceResult:
    """Output of :func:`reference_simulate`.

    events : list of (time, from_phase, to_phase, kind), kind in
        {"stick", "slip", "reversal", "separation", "recontact"}.
    segments : list of :class:`Segment`.
    impacts : list of dicts (time, states before/after the impact map).
    mode_data : :class:`ModeData`.
    """

    events: list
    segments: list
    mode_data: ModeData
    impacts: list
    t_end: float
    nfev: int
    _model: _Model = field(repr=False)

    def _segment_index(self, times: np.ndarray) -> np.ndarray:
        starts = np.array([s.t0 for s in self.segments])
        idx = np.searchsorted(starts, times, side="right") - 1  # later segment at a switch
        return np.clip(idx, 0, len(self.segments) - 1)

    def state(self, t: float) -> tuple[np.ndarray, int, int]:
        """(y, phase, s) at time t (later segment at a switch)."""
        seg = self.segments[int(self._segment_index(np.array([t]))[0])]
        return seg.sol(t), seg.phase, seg.sign

    def evaluate(self, times) -> dict:
        """Dense output at ``times``: phi, phi_dot, q, q_dot, z, z_dot, normal_force,
        friction_force, phase, slip_sign (s in slip, else 0), Omega, t.

        At a switch time the later segment is used (the state just after the switch)."""
        model = self._model
        n = model.n
        times = np.atleast_1d(np.asarray(times, float))
        out = {
            "t": times.copy(),
            "phi": np.empty(times.size),
            "phi_dot": np.empty(times.size),
            "q": np.empty((times.size, n)),
            "q_dot": np.empty((times.size, n)),
            "z": np.empty(times.size),
            "z_dot": np.empty(times.size),
            "normal_force": np.empty(times.size),
            "friction_force": np.empty(times.size),
            "phase": np.empty(times.size, dtype=int),
            "slip_sign": np.empty(times.size, dtype=int),
            "Omega": np.empty(times.size),
        }
        for i, (t, k) in enumerate(zip(times, self._segment_index(times), strict=True)):
            seg = self.segments[k]
            y = np.array(seg.sol(t), float)
            if seg.phase == STICK:
                y[2 * n + 1] = seg.piece.omega(t)
            r = model.solve(seg.phase, seg.sign, t, y, seg.piece)
            out["phi"][i] = y[2 * n]
            out["phi_dot"][i] = y[2 * n + 1]
            out["q"][i] = y[:n]
            out["q_dot"][i] = y[n : 2 * n]
            out["z"][i] = r["z"]
            out["z_dot"][i] = r["zd"]
            out["normal_force"][i] = r["N"]
            out["friction_force"][i] = r["f"]
            out["phase"][i] = seg.phase
            out["slip_sign"][i] = seg.sign
            out["Omega"][i] = seg.piece.omega(t)
        return out


# --------------------------------------------------------------------------- energies
def kinetic_energy_t2(case: Any, state: Mapping, mode_data: ModeData | None = None):
    """T2 = 1/2 sum M qdot^2 + 1/2 I phidot^2 + 1/2 m zdot^2 (quadratic part in velocities)."""
    md = mode_data if mode_data is not None else mode_data_from_case(case)
    m, r0 = float(case.slider.mass), float(case.slider.track_radius)
    qd = np.asarray(state["q_dot"], float)
    return (
        0.5 * np.sum(md.M * qd**2, axis=-1)
        + 0.5 * m * r0**2 * np.asarray(state["phi_dot"]) ** 2
        + 0.5 * m * np.asarray(state["z_dot"]) ** 2
    )


def _state_mapping(case: Any, md: ModeData, state, t, omega) -> Mapping:
    """Turn a state vector [q, qdot, phi, phidot (, z, zdot)] into the mapping form."""
    if isinstance(state, Mapping):
        return state
    n = md.n
    y = np.asarray(state, float)
    q, qd, phi, phid = y[:n], y[n : 2 * n], float(y[2 * n]), float(y[2 * n + 1])
    if y.size >= 2 * n + 4:
        z, zd = float(y[2 * n + 2]), float(y[2 * n + 3])
    else:  # in contact: the slider moves with the disc
        lphi = md.l * phi
        g = md.R0 * np.where(md.is_sine, np.sin(lphi), np.cos(lphi))
        gp = md.R0 * md.l * np.where(md.is_sine, np.cos(lphi), -np.sin(lphi))
        z, zd = g @ q, g @ qd + phid * (gp @ q)
    if omega is None:
        omega = float(speed_at(case.speed, 0.0 if t is None else t)[0][0])
    return {"q": q, "q_dot": qd, "phi": phi, "phi_dot": phid, "z": z, "z_dot": zd, "Omega": omega}


def jacobi_integral(
    case: Any,
    state,
    *,
    t: float | None = None,
    omega: float | None = None,
    mode_data: ModeData | None = None,
):
    """Jacobi integral T2 - T0 + V of disc and slider (conserved without friction and
    damping at constant speed while N phidot (g'.q) = 0; see the tests).

    ``state``: a mapping with q, q_dot, phi, phi_dot, z, z_dot and Omega (or t), e.g. the
    dict of :meth:`ReferenceResult.evaluate` (vectorised over its times); or one state
    vector ``[q, qdot, phi, phidot]`` (contact) or ``[q, qdot, phi, phidot, z, zdot]`` with
    the speed given by ``omega`` or by the time ``t`` (default t = 0).

    Disc: T2 = 1/2 sum M qdot^2, T0 = 1/2 sum M l^2 Omega^2 q^2, V = 1/2 sum M omega^2 q^2.
    Slider: 1/2 I phidot^2 + 1/2 m zdot^2 + 1/2 r0^2 k_phi phi^2 + 1/2 k_z z^2 + N0 z.
    """
    md = mode_data if mode_data is not None else mode_data_from_case(case)
    state = _state_mapping(case, md, state, t, omega)
    sl = case.slider
    if "Omega" in state:
        Om = np.asarray(state["Omega"], float)
    else:
        Om = speed_at(case.speed, state["t"])[0]
    q = np.asarray(state["q"], float)
    t2 = kinetic_energy_t2(case, state, md)
    om2 = Om[..., None] ** 2 if q.ndim > 1 else float(np.squeeze(Om)) ** 2
    t0 = 0.5 * np.sum(md.M * md.l**2 * om2 * q**2, axis=-1)
    z = np.asarray(state["z"], float)
    v = (
        0.5 * np.sum(md.M * md.omega**2 * q**2, axis=-1)
        + 0.5 * float(sl.rotational_stiffness) * np.asarray(state["phi"]) ** 2
        + 0.5 * float(sl.normal_stiffness) * z**2
        + float(sl.preload) * z
    )
    return t2 - t0 + v


# --------------------------------------------------------------------------- driver
def sliding_equilibrium(case: Any, mode_data: ModeData | None = None) -> dict:
    """Sliding equilibrium at constant speed (slip, s = +1, all rates zero): q, phi, N.

    With v = Omega: K_d q = -N (g - (h/(2 r0)) mu g'), K_d = M (omega^2 - l^2 Omega^2);
    N = N0 + k_z g.q; r0^2 k_phi phi = r0 mu N.  Solved for phi by the secant method.
    """
    from scipy.optimize import newton

    md = mode_data if mode_data is not None else mode_data_from_case(case)
    model = _Model(case, md)
    if str(case.speed.profile) != "constant":
        raise ValueError("a sliding equilibrium exists only at constant speed")
    Om = float(case.speed.value)
    mu = model.mu(Om)
    Kd = md.M * (md.omega**2 - md.l**2 * Om**2)

    def parts(phi):
        g, gp, _ = model.kin(phi)
        c = g - model.hk * mu * gp
        N = model.N0 / (1.0 + model.kz * np.sum(g * c / Kd))
        return -N * c / Kd, N

    def residual(phi):
        return phi - model.r0 * mu * parts(phi)[1] / model.Kphi

    phi = float(newton(residual, model.r0 * mu * model.N0 / model.Kphi, tol=1e-15, maxiter=100))
    q, N = parts(phi)
    return {"q": q, "q_dot": np.zeros(md.n), "phi": phi, "phi_dot": 0.0, "N": N}


def _initial_state(case: Any, md: ModeData, y0, phase0) -> tuple[np.ndarray, int | None]:
    n = md.n
    y = np.zeros(2 * n + 4)
    if y0 is None:
        init = getattr(case.simulation, "initial_state", "rest")
        if isinstance(init, str) and init == "rest":
            return y, phase0
        if isinstance(init, str) and init == "equilibrium":
            eq = sliding_equilibrium(case, md)
            pert = case.simulation.perturbation
            eq["phi"] += float(pert.phi)
            eq["phi_dot"] += float(pert.phi_dot)
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
        y[2 * n] = float(y0.get("phi", 0.0))
        y[2 * n + 1] = float(y0.get("phi_dot", 0.0))
        zz = (y0.get("z"), y0.get("z_dot"))
    else:
        arr = np.asarray(y0, float)
        if arr.size not in (2 * n + 2, 2 * n + 4):
            raise ValueError(f"y0 must have 2n+2 or 2n+4 = {2 * n + 4} entries, got {arr.size}")
        y[: 2 * n + 2] = arr[: 2 * n + 2]
        zz = (arr[2 * n + 2], arr[2 * n + 3]) if arr.size == 2 * n + 4 else (None, None)
    if phase0 == SEPARATION:
        if zz[0] is None:
            raise ValueError("a separated start needs z and z_dot")
        q, qd, phi, phid = y[:n], y[n : 2 * n], y[2 * n], y[2 * n + 1]
        lphi = md.l * phi
        g = md.R0 * np.where(md.is_sine, np.sin(lphi), np.cos(lphi))
        gp = md.R0 * md.l * np.where(md.is_sine, np.cos(lphi), -np.sin(lphi))
        y[2 * n + 2] = float(zz[0]) - g @ q
        y[2 * n + 3] = float(zz[1]) - (g @ qd + phid * (gp @ q))
    return y, phase0


def reference_simulate(
    case: Any,
    t_end: float | None = None,
    *,
    rtol: float = 1e-12,
    atol: float = 1e-14,
    method: str = "DOP853",
    y0=None,
    phase0: int | None = None,
    mode_data: ModeData | None = None,
    max_step: float | None = None,
    max_switches: int | None = None,
) -> ReferenceResult:
    """Integrate the phase machine of equations.md from t = 0 to ``t_end``.

    Parameters
    ----------
    case : fivdisc.case.Case (or an object with the same attributes)
    t_end : float, default ``case.simulation.duration`` [s]
    rtol, atol : solve_ivp tolerances (atol applies to every state component)
    method : solve_ivp method ("DOP853" for the reference, "RK45" for the speed baseline)
    y0 : optional initial state: array ``[q, qdot, phi, phidot]`` (+ ``[z, zdot]``), or a
        mapping with those names; default ``case.simulation.initial_state`` ("rest").
    phase0 : optional initial phase (0 slip, 1 stick, 2 separation: needs z, zdot);
        default: chosen from the state (contact).
    mode_data : optional :class:`ModeData` instead of computing it from ``case.disc``.
    max_step : largest solve_ivp step [s]; default ``case.simulation.max_step`` (0 = none).
    max_switches : raise RuntimeError after that many phase switches; default
        ``case.simulation.max_switches`` (else 200000).

    The case options ``simulation.impact``, ``omega_dot_terms`` and
    ``printed_gyroscopic_sign`` are honoured.
    """
    md = mode_data if mode_data is not None else mode_data_from_case(case)
    model = _Model(case, md)
    n = md.n
    if t_end is None:
        t_end = float(case.simulation.duration)
    if max_step is None:
        max_step = float(getattr(case.simulation, "max_step", 0.0))
    if not max_step or max_step <= 0.0:
        max_step = math.inf
    if max_switches is None:
        max_switches = int(getattr(case.simulation, "max_switches", 200_000))
    pieces = _speed_pieces(case.speed, t_end)
    y, phase = _initial_state(case, md, y0, phase0)
    t = 0.0
    piece = _piece_at(pieces, t)
    if phase is None or phase in CONTACT_PHASES:
        v = piece.omega(t) - y[2 * n + 1]
        if phase == STICK or (phase is None and v == 0.0):
            y[2 * n + 1] = piece.omega(t)
            phase, s = model.choose_contact(t, y, piece, v_zero=True)
        elif phase == SLIP:
            s = 1 if v >= 0.0 else -1
        else:
            phase, s = model.choose_contact(t, y, piece, v_zero=False)
        if phase == SEPARATION:
            y[2 * n + 2] = y[2 * n + 3] = 0.0
    else:
        s = 0

    events: list = []
    segments: list = []
    impacts: list = []
    nfev = 0
    switches = 0
    stalled = 0  # switches without progress in time
    last_switch_t = -math.inf

    def record(t_sw, old, new, old_s, new_s, cause):
        if cause == "gap0":
            kind = "recontact"
        elif new == SEPARATION:
            kind = "separation"
        elif old == SLIP and new == STICK:
            kind = "stick"
        elif old == STICK and new == SLIP:
            kind = "slip"
        elif old == SLIP and new == SLIP and old_s != new_s:
            kind = "reversal"
        else:
            return
        events.append((t_sw, old, new, kind))

    while t < t_end:
        piece = _piece_at(pieces, t)
        t_stop = min(piece.t_b, t_end)
        fun = model.rhs(phase, s, piece)
        evs, names = model.events(phase, s, piece)
        ivp = solve_ivp(
            fun,
            (t, t_stop),
            y,
            method=method,
            rtol=rtol,
            atol=atol,
            dense_output=True,
            events=evs,
            max_step=max_step,
        )
        if ivp.status < 0:
            raise RuntimeError(
                f"solve_ivp failed at t = {t!r} in {PHASE_NAMES[phase]}: {ivp.message}"
            )
        nfev += ivp.nfev
        t_new = float(ivp.t[-1])
        if t_new > t:
            segments.append(Segment(t, t_new, phase, s, ivp, piece))
        y_new = np.array(ivp.y[:, -1], float)
        old, old_s = phase, s
        if ivp.status == 1:  # an exit event
            which = next(i for i, te in enumerate(ivp.t_events) if te.size)
            cause = names[which]
            t_new = float(ivp.t_events[which][0])
            y_new = np.array(ivp.y_events[which][0], float)
            new_piece = _piece_at(pieces, t_new)
            if cause == "v0":
                y_new[2 * n + 1] = new_piece.omega(t_new)
                phase, s = model.choose_contact(t_new, y_new, new_piece, v_zero=True)
            elif cause == "friction_limit":
                y_new[2 * n + 1] = new_piece.omega(t_new)
                f = model.solve_stick(t_new, y_new, new_piece)["f"]
                s = 1 if f > 0.0 else -1
                phase = SLIP
                if model.solve_slip(t_new, y_new, new_piece, s)["N"] < 0.0:
                    phase, s = SEPARATION, 0
            elif cause == "N0":
                if old == STICK:
                    y_new[2 * n + 1] = new_piece.omega(t_new)
                phase, s = SEPARATION, 0
            else:  # gap0: re-contact
                y_before = y_new.copy()
                y_new[2 * n + 2] = 0.0
                if model.impact:
                    y_new, info = _impact(model, y_new)
                else:
                    info = {"zdot_minus": None, "zdot_plus": None}
                    y_new[2 * n + 3] = 0.0
                impacts.append({"t": t_new, "y_minus": y_before, "y_plus": y_new.copy(), **info})
                v = new_piece.omega(t_new) - y_new[2 * n + 1]
                v_zero = abs(v) <= 1e-13 * max(1.0, abs(new_piece.omega(t_new)))
                if v_zero:
                    y_new[2 * n + 1] = new_piece.omega(t_new)
                phase, s = model.choose_contact(t_new, y_new, new_piece, v_zero=v_zero)
            if phase == SEPARATION and old != SEPARATION:
                y_new[2 * n + 2] = y_new[2 * n + 3] = 0.0  # gap and its rate start at 0
            record(t_new, old, phase, old_s, s, cause)
            switches += 1
            stalled = stalled + 1 if t_new - last_switch_t <= 1e-12 * max(1.0, t_new) else 0
            last_switch_t = t_new
            if switches > max_switches:
                raise RuntimeError(f"more than {max_switches} phase switches before t = {t_new}")
            if stalled > 50:
                raise RuntimeError(f"phase switches do not advance in time at t = {t_new}")
        elif t_new < t_end:  # a speed breakpoint: re-check the phase with the new Omegadot
            new_piece = _piece_at(pieces, t_new)
            if phase == STICK:
                y_new[2 * n + 1] = new_piece.omega(t_new)
                phase, s = model.choose_contact(t_new, y_new, new_piece, v_zero=True)
            elif phase == SLIP:
                v = new_piece.omega(t_new) - y_new[2 * n + 1]
                phase, s = model.choose_contact(t_new, y_new, new_piece, v_zero=(v == 0.0))
            if phase == SEPARATION and old != SEPARATION:
                y_new[2 * n + 2] = y_new[2 * n + 3] = 0.0
            record(t_new, old, phase, old_s, s, "breakpoint")
        t, y = t_new, y_new

    return ReferenceResult(events, segments, md, impacts, float(t_end), nfev, model)
