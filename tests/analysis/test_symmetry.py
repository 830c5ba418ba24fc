"""Symmetries of cases with several identical pads (issue 36, item 4): the group, checked
in the independent reference model; what a multiplier crossing of a symmetric orbit is."""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest

from fivdisc.analysis.symmetry import case_symmetry, classify_reduced, isotypic
from fivdisc.case import Case
from fivdisc.model.build import build_model

from reference.model import SLIP, _Model, _speed_pieces, mode_data_from_case

PAD = {"normal_damping": 0.1, "rotational_damping": 0.1}
STRIBECK = {"law": "stribeck", "static": 0.8, "kinetic_max": 0.6, "kinetic_min": 0.35,
            "stribeck_velocity": 1.0}


def ring(n: int, **extra) -> Case:
    return Case(disc={"modes": [[0, 0], [0, 1], [0, 2]], "damping_ratio": 0.003},
                sliders=[{**PAD, "angle": 2 * math.pi * k / n, **extra} for k in range(n)],
                friction=STRIBECK, speed={"value": 10.0})


FACING = Case(disc={"modes": [[0, 0], [0, 1]]},
              sliders=[{**PAD, "face": "top", "angle": 0.5},
                       {**PAD, "face": "bottom", "angle": 0.5}],
              speed={"value": 5.0})


def test_identical_pads_equally_spaced_make_a_cyclic_group():
    three = case_symmetry(build_model(ring(3)))
    assert three.description == "Z3: 3 identical pads 120 degrees apart on the top face"
    assert [(e.label, e.order) for e in three.elements] == [("turn by 120 degrees", 3),
                                                            ("turn by 240 degrees", 3)]
    # pad j of P x takes the values of the pad 120 degrees behind it
    assert three.elements[0].pads.tolist() == [2, 0, 1]
    four = case_symmetry(build_model(ring(4)))
    assert [e.order for e in four.elements] == [4, 2, 4]
    mirror = case_symmetry(build_model(FACING))
    assert mirror.description == "the mid-plane mirror of identical facing pads"
    assert mirror.elements[0].pads.tolist() == [1, 0]


def test_no_group_where_the_pads_differ_or_are_not_equally_spaced():
    uneven = ring(3).replace({"sliders.2.angle": 4.0})
    assert not case_symmetry(build_model(uneven))
    heavier = ring(3).replace({"sliders.1.mass": 0.11})
    assert not case_symmetry(build_model(heavier))
    # a perturbation of one pad is no property of the pad: the group stays
    kicked = ring(3).replace({"sliders.1.perturbation.phi_dot": 1.0})
    assert case_symmetry(build_model(kicked))


def _reference_matrix(case: Case, pads: np.ndarray, alpha: float, mirror: bool
                      ) -> np.ndarray:
    """P in the reference model's layout (q, qdot, phi, phidot, e, edot), written from
    its own mode data: each (C, D) doublet of l diameters turned by l alpha (or every
    modal coordinate negated by the mirror), pad j taking pad ``pads[j]``'s values."""
    md = mode_data_from_case(case)
    n, s = md.n, len(pads)
    rot = np.zeros((n, n))
    for i in range(n):
        ell = int(md.l[i])
        if mirror:
            rot[i, i] = -1.0
        elif ell == 0:
            rot[i, i] = 1.0
        elif not md.is_sine[i]:
            d = int(md.partner[i])
            c, sn = math.cos(ell * alpha), math.sin(ell * alpha)
            rot[i, i], rot[i, d] = c, -sn
            rot[d, i], rot[d, d] = sn, c
    perm = np.zeros((s, s))
    perm[np.arange(s), pads] = 1.0
    return np.block([[rot, np.zeros((n, n + 4 * s))],
                     [np.zeros((n, n)), rot, np.zeros((n, 4 * s))],
                     [np.zeros((4 * s, 2 * n)), np.kron(np.eye(4), perm)]])


@pytest.mark.parametrize("case, alpha, mirror", [(ring(3), 2 * math.pi / 3, False),
                                                 (ring(4), math.pi / 2, False),
                                                 (FACING, 0.0, True)])
def test_every_element_commutes_with_the_reference_model(case, alpha, mirror):
    """f(P x) = P f(x) in the independent reference model (every pad slipping forward),
    with P built there from its own mode data and the pad map fivdisc found: the group
    fivdisc reports is a symmetry of the equations, not of its own implementation."""
    group = case_symmetry(build_model(case))
    pads = group.elements[0].pads
    md = mode_data_from_case(case)
    model = _Model(case, md)
    s = len(case.sliders)
    fun = model.rhs([SLIP] * s, [1] * s, _speed_pieces(case.speed, 1.0)[0])
    matrix = _reference_matrix(case, pads, alpha, mirror)
    rng = np.random.default_rng(7)
    n = md.n
    for _ in range(3):
        y = np.zeros(2 * n + 4 * s)
        y[:n] = 1e-6 * rng.standard_normal(n)
        y[n:2 * n] = 1e-3 * rng.standard_normal(n)
        y[2 * n:2 * n + s] = 1e-3 * rng.standard_normal(s)
        y[2 * n + s:2 * n + 2 * s] = case.speed.value * (0.2 + 0.5 * rng.random(s))
        f, fp = fun(0.0, y), fun(0.0, matrix @ y)
        assert np.linalg.norm(fp - matrix @ f) <= 1e-11 * np.linalg.norm(f)
    # and without the pad map, no symmetry (the check can fail)
    f, fp = fun(0.0, y), fun(0.0, _reference_matrix(case, np.arange(s), alpha, mirror) @ y)
    assert np.linalg.norm(fp - _reference_matrix(case, np.arange(s), alpha, mirror) @ f) \
        > 1e-6 * np.linalg.norm(f)


@pytest.mark.parametrize("turns, k, kind", [
    (1 / 3 - 6.1e-6, 3, "symmetry breaking"),   # the "torus" at 19.7231
    (1 / 3 + 9.5e-4, 3, "symmetry breaking"),
    (1 / 3 - 1.1e-3, 3, None),                  # outside the resonance window: a torus
    (0.21, 3, None),
    (0.5, 4, "symmetry breaking"),              # a real -1 of the T/4 map: +1 of M
    (0.5, 3, None),                             # a real -1 of the T/3 map: -1 of M too
    (1 / 4 + 2e-4, 4, "symmetry breaking"),
    (1e-4, 3, None),                            # near 1:1: M's own kind
])
def test_crossings_of_the_reduced_map_are_told_by_their_angle(turns, k, kind):
    mu = cmath.exp(2j * math.pi * turns)
    found = classify_reduced(mu, k)
    assert (found.kind if found else None) == kind
    if found is not None and abs(mu.imag) > 1e-6:
        # the multiplier of the period it stands for lies at k times the angle: a small
        # rotation, the "torus" the symmetry hid
        m = mu**k
        assert abs(cmath.phase(m)) / (2 * math.pi) == pytest.approx(
            k * abs(turns - round(turns * k) / k), rel=1e-6)


def test_an_eigenvector_is_placed_in_its_eigenspace_of_p():
    group = case_symmetry(build_model(ring(3)))
    el = group.elements[0]
    rng = np.random.default_rng(1)
    x = rng.standard_normal(el.matrix.shape[0])
    # the symmetric part (P x = x) and a part with P v = exp(2 pi i / 3) v
    sym = (x + el.matrix @ x + el.matrix @ el.matrix @ x) / 3
    w = cmath.exp(-2j * math.pi / 3)
    one = (x + w * (el.matrix @ x) + w**2 * (el.matrix @ el.matrix @ x)) / 3
    assert isotypic(sym, el) == 0
    assert isotypic(one, el) == 1
    assert np.allclose(el.matrix @ one, cmath.exp(2j * math.pi / 3) * one)
