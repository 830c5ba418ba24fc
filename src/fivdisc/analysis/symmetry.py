"""Symmetries of a case with several sliders, of its periodic orbits, and what they make
of the Floquet multipliers.

**The case's group.** Identical sliders (every key equal but ``angle``) spaced equally
round a track, on one face and radius, make the equations invariant under turning the
disc by ``2 pi / n`` and relabelling the pads: a linear map ``P`` of the state (each
doublet ``(C, D)`` of ``l`` nodal diameters turned by ``l 2 pi / n``, pad ``j`` taking
the place of the pad ``2 pi / n`` behind it) with ``f(P x) = P f(x)``. Identical pads
facing each other on the two faces, at the same angles and radii, add the reflection in
the disc's mid-plane (``w -> -w``, the faces swapped). Nothing else is a symmetry: the
disc's spin and the friction break every reflection through a diameter. Each element is
checked numerically, ``f(P x) = P f(x)`` at random states, when the group is made.

**An orbit's symmetry.** A periodic orbit of an equivariant system need not be
symmetric itself; when it is, either ``x(t) = P x(t)`` (spatial: the pads move alike,
*in phase*), or ``x(t + T/k) = P x(t)`` (spatio-temporal: the pads take turns, ``T/k``
apart), or both for different elements.

**Multipliers.** On an orbit with ``x(t + T/k) = P x(t)`` the monodromy is
``M = R^k`` with ``R = P^-1 d phi_{T/k}``, the Jacobian of the reduced map. Its
eigenvalues carry what ``M``'s lose: a pair of ``R`` at the angle ``2 pi m / k``
(``m != 0``) is a multiplier ``+1`` of ``M`` that the symmetry does not force, and its
crossing breaks the orbit's symmetry; a pair close to that angle (``M``'s pair at a small
rotation) is a Neimark-Sacker bifurcation of ``R`` next to the ``m:k`` resonance, whose
motion is nearly a period-``T`` orbit without the symmetry. On an in-phase orbit
(``x = P x``), ``M`` commutes with ``P``, and a multiplier whose eigenvector lies in a
non-trivial eigenspace of ``P`` breaks the symmetry (for ``n >= 3`` those come in forced
pairs).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fivdisc.analysis.kinds import BifurcationKind as Kind
from fivdisc.case import Case
from fivdisc.errors import FivdiscError
from fivdisc.model.build import Model

__all__ = ["CaseSymmetry", "Element", "OrbitSymmetry", "case_symmetry", "classify_reduced",
           "pad_ring"]

# Relative change of two angles taken as the same place on the disc [rad].
_ANGLE = 1e-9
# Largest |f(P x) - P f(x)| / |f(x)| accepted when checking an element.
_EQUIVARIANT = 1e-9
# A state within this (scaled, relative to the orbit's size) of its image is symmetric: an
# in-phase orbit whose multiplier in an asymmetric direction is near 1 (1.001 on the two
# facing pads of the tests) is found symmetric only to the residual over |mu - 1|.
ORBIT_SYMMETRY = 1e-6
# A pair of R whose angle lies within this many turns of m / k is near the m:k resonance.
RESONANT = 1e-3
# The pad keys that do not take part in a symmetry (their place) or in the dynamics.
_PLACE = {"angle", "face", "perturbation"}


@dataclass(frozen=True, eq=False)
class Element:
    """One element of a case's symmetry group.

    Attributes
    ----------
    matrix : ndarray
        ``P``, acting on the state (positions and rates alike).
    pads : ndarray of int
        ``pads[j]``: the pad whose values pad ``j`` takes in ``P x``.
    order : int
        The smallest ``k`` with ``P^k = I``.
    label : str
        In words, e.g. ``"turn by 120 degrees"``, ``"mirror in the mid-plane"``.
    """

    matrix: np.ndarray
    pads: np.ndarray
    order: int
    label: str


@dataclass(frozen=True, eq=False)
class CaseSymmetry:
    """The symmetry group of a case (:func:`case_symmetry`).

    Attributes
    ----------
    elements : tuple of Element
        Every element but the identity.
    description : str
        E.g. ``"Z3: 3 identical pads at 120 degrees on the top face"``, or ``"none"``.
    error : float
        The largest relative ``|f(P x) - P f(x)|`` found when checking the elements.
    """

    elements: tuple[Element, ...]
    description: str
    error: float = 0.0

    def __bool__(self) -> bool:
        return bool(self.elements)


@dataclass(frozen=True, eq=False)
class OrbitSymmetry:
    """The symmetry of one periodic orbit (:func:`orbit_symmetry`).

    Attributes
    ----------
    name : str
        In words: ``"pads stick in turn, T/3 apart"``, ``"in phase"``, ``"none"``, ...
    spatial : tuple of Element
        Elements with ``x(t) = P x(t)``.
    shift : Element or None
        The element of the shortest spatio-temporal symmetry ``x(t + T/k) = P x(t)``.
    k : int
        Its ``k`` (1 if none).
    distance : float
        The largest scaled distance of the symmetries found (their accuracy).
    """

    name: str
    spatial: tuple[Element, ...] = ()
    shift: Element | None = None
    k: int = 1
    distance: float = 0.0
    reduced: np.ndarray | None = field(default=None, repr=False)

    def __bool__(self) -> bool:
        return bool(self.spatial) or self.shift is not None


def _pad_key(slider) -> tuple:
    return tuple(sorted((k, v) for k, v in slider.model_dump().items() if k not in _PLACE))


def _rotation(model: Model, alpha: float, pads: np.ndarray) -> np.ndarray:
    """P of a turn of the disc by ``alpha`` with pad j taking pad ``pads[j]``'s values."""
    n, ns = model.n, model.n_sliders
    half = model.slices.q_dot.start
    block = np.zeros((half, half))
    i = 0
    while i < n:
        ell = int(model.l[i])
        if ell == 0:
            block[i, i] = 1.0
            i += 1
            continue
        # w'(theta) = w(theta - alpha): C' = C cos(l a) - D sin(l a), D' = C sin + D cos
        c, s = math.cos(ell * alpha), math.sin(ell * alpha)
        block[i, i], block[i, i + 1] = c, -s
        block[i + 1, i], block[i + 1, i + 1] = s, c
        i += 2
    for offset in (model.slices.phi.start, model.slices.z.start):
        for j in range(ns):
            block[offset + j, offset + pads[j]] = 1.0
    return np.kron(np.eye(2), block)


def _mirror(model: Model, pads: np.ndarray, z_sign: float) -> np.ndarray:
    """P of the reflection in the mid-plane: every modal coordinate and slider deflection
    changes sign, pad j takes its facing pad ``pads[j]``'s values."""
    n, ns = model.n, model.n_sliders
    half = model.slices.q_dot.start
    block = np.zeros((half, half))
    block[:n, :n] = -np.eye(n)
    phi, z = model.slices.phi.start, model.slices.z.start
    for j in range(ns):
        block[phi + j, phi + pads[j]] = 1.0
        block[z + j, z + pads[j]] = z_sign
    return np.kron(np.eye(2), block)


def _rhs(model: Model, x: np.ndarray) -> np.ndarray:
    """The vector field at ``x``, every pad slipping (the start's phases)."""
    from fivdisc.engine.integration import Integration

    run = Integration(model, x, duration=1e-9, rtol=1e-12, atol=1e-19)
    run.advance(0.0)
    return run.rhs()


def equivariance_error(model: Model, matrix: np.ndarray, samples: int = 3,
                       seed: int = 36) -> float:
    """The largest ``|f(P x) - P f(x)| / |f(x)|`` (scaled by the energy scales) over
    random states near the sliding equilibrium with every pad slipping."""
    from fivdisc.engine.equilibrium import sliding_equilibrium

    rng = np.random.default_rng(seed)
    # each coordinate's size: 1/sqrt of its stiffness or inertia (the energy scales of
    # fivdisc.analysis.orbits, written out here to keep this module below that one)
    kern = model.kernel
    scale = 1.0 / np.sqrt(np.r_[model.modal_mass * model.omega**2, kern.row("kphi"),
                                kern.row("kz"), model.modal_mass, kern.row("inertia"),
                                kern.row("mass")])
    base = sliding_equilibrium(model).state
    omega = float(model.speed.omega(0.0))
    rates = model.slices.phi_dot
    worst = 0.0
    for _ in range(samples):
        x = base + 0.1 * scale * rng.standard_normal(base.size) * np.linalg.norm(base / scale)
        # pads slipping forward, clear of the stick boundary
        x[rates] = omega * (0.5 - 0.3 * rng.random(model.n_sliders))
        f, fp = _rhs(model, x), _rhs(model, matrix @ x)
        worst = max(worst, float(np.linalg.norm((fp - matrix @ f) / scale)
                                 / np.linalg.norm(f / scale)))
    return worst


def pad_ring(model: Model) -> np.ndarray | None:
    """The pads in their order round the track (of increasing angle, from pad 0), where
    every pad of the case is one of ``N`` identical pads equally spaced on one face (the
    group ``Z_N``, ``N`` the number of pads): a turn of the disc by ``2 pi / N`` takes
    each pad's values to the next. None for any other case."""
    group = case_symmetry(model, check=False)
    ns = model.n_sliders
    turn = next((el for el in group.elements
                 if el.order == ns and el.label == f"turn by {360 / ns:g} degrees"), None)
    if turn is None:
        return None
    ring = [0]
    while len(ring) < ns:
        # the pad that takes the last one's values: the next in the direction of angle
        ring.append(int(np.flatnonzero(turn.pads == ring[-1])[0]))
    return np.array(ring) if len(set(ring)) == ns else None


def case_symmetry(model: Model, check: bool = True) -> CaseSymmetry:
    """The symmetry group of ``model``'s case: turns of the disc that map identical pads
    onto each other, and the mirror in the mid-plane when identical pads face each other.

    Parameters
    ----------
    model : Model
    check : bool
        Check every element numerically (:func:`equivariance_error`).

    Raises
    ------
    FivdiscError
        An element fails the check (a model that is not what its case says).
    """
    case: Case = model.case
    pads = case.sliders
    ns = len(pads)
    if ns < 2:
        return CaseSymmetry((), "none (one slider)")
    keys = [_pad_key(p) for p in pads]
    where = [(p.face, p.track_radius, p.angle % (2 * math.pi)) for p in pads]

    def find(face: str, radius: float, angle: float, key: tuple) -> int | None:
        for i, (f, r, a) in enumerate(where):
            gap = abs(math.remainder(a - angle, 2 * math.pi))
            if f == face and r == radius and gap <= _ANGLE and keys[i] == key:
                return i
        return None

    def turned(count: int) -> np.ndarray | None:
        alpha = 2 * math.pi / count
        out = np.empty(ns, dtype=np.int64)
        for j, (f, r, a) in enumerate(where):
            # pad j of P x takes the values of the pad alpha behind it
            i = find(f, r, a - alpha, keys[j])
            if i is None:
                return None
            out[j] = i
        return out

    elements: list[Element] = []
    turns = 1
    for count in range(ns, 1, -1):
        mapping = turned(count)
        if mapping is not None:
            turns = count
            break
    words = []
    if turns > 1:
        for step in range(1, turns):
            mapping = turned(turns) if step == 1 else mapping[turned(turns)]
            elements.append(Element(_rotation(model, 2 * math.pi * step / turns, mapping),
                                    mapping.copy(), turns // math.gcd(step, turns),
                                    f"turn by {360 * step / turns:g} degrees"))
        faces = sorted({p.face for p in pads})
        words.append(f"Z{turns}: {ns if len(faces) == 1 else ns // len(faces)} identical "
                     f"pads {360 / turns:g} degrees apart on the {' and '.join(faces)} "
                     f"face{'s' if len(faces) > 1 else ''}")
    facing = np.empty(ns, dtype=np.int64)
    mirrored = True
    for j, (f, r, a) in enumerate(where):
        i = find("bottom" if f == "top" else "top", r, a, keys[j])
        if i is None:
            mirrored = False
            break
        facing[j] = i
    error = 0.0
    if mirrored:
        chosen = None
        for z_sign in (-1.0, 1.0):
            matrix = _mirror(model, facing, z_sign)
            err = equivariance_error(model, matrix) if check else 0.0
            if err < _EQUIVARIANT:
                chosen = matrix
                error = max(error, err)
                break
        if chosen is None:
            raise FivdiscError("the mid-plane mirror of facing pads is not a symmetry of the "
                               "model's equations (f(P x) != P f(x)): a defect of the model")
        mirror = Element(chosen, facing.copy(), 2, "mirror in the mid-plane")
        words.append("the mid-plane mirror of identical facing pads")
        rotations = list(elements)
        elements.append(mirror)
        for rot in rotations:
            elements.append(Element(mirror.matrix @ rot.matrix, rot.pads[facing],
                                    math.lcm(2, rot.order), f"{rot.label} and mirror"))
    if check:
        for el in elements:
            if el.label == "mirror in the mid-plane":
                continue
            err = equivariance_error(model, el.matrix)
            if not err < _EQUIVARIANT:
                raise FivdiscError(f"the {el.label} is not a symmetry of the model's "
                                   f"equations (|f(P x) - P f(x)| = {err:.1e} |f(x)|): a "
                                   "defect of the model")
            error = max(error, err)
    if not elements:
        return CaseSymmetry((), "none (the pads differ, or are not equally spaced)")
    return CaseSymmetry(tuple(elements), "; ".join(words), error)


@dataclass(frozen=True)
class Crossing:
    """What a multiplier crossing is in the light of an orbit's symmetry."""

    kind: str
    note: str


def classify_reduced(mu: complex, k: int) -> Crossing | None:
    """A critical eigenvalue ``mu`` of ``R = P^-1 d phi_{T/k}`` (spatio-temporal symmetry
    of order ``k``): symmetry breaking (an angle ``2 pi m / k``, ``m != 0``, within
    :data:`RESONANT` turns; for even ``k`` a real ``-1``), else None (``M``'s own kind)."""
    theta = abs(math.atan2(mu.imag, mu.real)) / (2 * math.pi)
    m = round(theta * k)
    delta = theta - m / k
    if m % k == 0 or abs(delta) > RESONANT:
        return None
    if abs(mu.imag) <= 1e-6 * abs(mu):
        return Crossing(Kind.SYMMETRY_BREAKING,
                        f"a real multiplier -1 of the T/{k} map (+1 of the period): orbits "
                        f"without the T/{k} symmetry branch off (a pitchfork of the "
                        "symmetry)")
    turns = abs(k * delta)
    every = 1 / max(turns, 1e-300)
    return Crossing(Kind.SYMMETRY_BREAKING,
                    f"a pair of the T/{k} map crosses the unit circle at the angle "
                    f"2 pi ({m}/{k} {'+' if delta >= 0 else '-'} {abs(delta):.2g}): near the "
                    f"{m}:{k} resonance, a Neimark-Sacker bifurcation of the T/{k} map that "
                    f"breaks the T/{k} symmetry (the period's multipliers at "
                    f"+-{turns:.2g} turns: the motion beyond is nearly of period T without "
                    f"the symmetry, drifting through its {k} images every ~{every:.3g} "
                    "periods)")


def isotypic(vector: np.ndarray, element: Element) -> int:
    """The eigenspace of ``P`` (``P v = exp(2 pi i m / order) v``) that holds most of
    ``vector``: ``m`` (0: the symmetric one)."""
    order = element.order
    powers = [np.eye(element.matrix.shape[0])]
    for _ in range(1, order):
        powers.append(element.matrix @ powers[-1])
    norms = []
    for m in range(order):
        w = np.exp(-2j * np.pi * m / order)
        proj = sum(w**j * (powers[j] @ vector) for j in range(order)) / order
        norms.append(float(np.linalg.norm(proj)))
    return int(np.argmax(norms))
