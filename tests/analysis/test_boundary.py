"""Exact stability boundaries: the curve tracer on functions whose zero sets are known,
and the traced boundary of the paper's Fig. 3a against the plain eigen-solve and the
grid map."""

from __future__ import annotations

import numpy as np
import pytest

from fivdisc.analysis.boundary import stability_boundary, zero_curves
from fivdisc.analysis.stability import linear_stability, stability_map
from fivdisc.case import load_case
from fivdisc.errors import CaseError
from fivdisc.examples import path

X, Y = "slider.normal_damping", "slider.rotational_damping"


def _circle(cx, cy, r, sign=1.0):
    return lambda u: sign * (np.hypot(u[0] - cx, u[1] - cy) - r)


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_closed_curves_either_side_stable(sign):
    one, two = _circle(0.3, 0.5, 0.15, sign), _circle(0.75, 0.45, 0.12, sign)
    curves = zero_curves(lambda u: one(u) * two(u) * -1.0)
    assert len(curves) == 2 and all(closed for _, closed in curves)
    for points, _ in curves:
        on = [min(abs(one(p)), abs(two(p))) for p in points]
        # Points are roots of Brent's method to 1e-10 of the box.
        assert max(on) < 1e-9


def test_a_curve_leaving_and_reentering_the_box_gives_one_branch_per_visit():
    # y = 0.5 + 0.7 sin(2 pi x) leaves through the top and bottom: three visits.
    def wave(u):
        return 0.5 + 0.7 * np.sin(2 * np.pi * u[0]) - u[1]

    curves = zero_curves(wave)
    assert len(curves) == 3 and not any(closed for _, closed in curves)
    for points, _ in curves:
        assert max(abs(wave(p)) for p in points) < 1e-9
        # Each visit ends on the box's edges.
        for end in (points[0], points[-1]):
            assert np.min(np.minimum(end, 1.0 - end)) < 1e-12
    # Together the visits span the whole width.
    xs = np.concatenate([[p[0] for p in points] for points, _ in curves])
    assert xs.min() == pytest.approx(0.0) and xs.max() == pytest.approx(1.0)


@pytest.fixture(scope="module")
def fig3a():
    case = load_case(path("fig03a"))
    return case, stability_boundary(case, (X, (0.0, 12.0)), (Y, (0.0, 3.0)))


def test_every_boundary_point_has_zero_growth_rate(fig3a):
    case, ds = fig3a
    assert ds.sizes["point"] > 20
    for i in range(0, ds.sizes["point"], 6):
        point = case.replace({X: float(ds[X][i]), Y: float(ds[Y][i])})
        lam = linear_stability(point).eigenvalues
        critical = lam[np.argmax(lam.real)]
        assert abs(critical.real) < 1e-9 * abs(critical)
        assert abs(critical.imag) / (2 * np.pi) == pytest.approx(float(ds["frequency"][i]),
                                                                 rel=1e-6)


def test_grid_map_crossings_lie_on_the_curves(fig3a):
    case, ds = fig3a
    xs, ys = np.linspace(0.0, 12.0, 40), np.linspace(0.0, 3.0, 40)
    grid = stability_map(case, (X, xs), (Y, ys))
    curve = np.c_[ds[X].values / 12.0, ds[Y].values / 3.0]
    spacing = max(np.diff(xs)[0] / 12.0, np.diff(ys)[0] / 3.0)
    crossings = [(x / 12.0, b / 3.0) for x, b in zip(xs, grid["boundary"].values, strict=True)
                 if np.isfinite(b)]
    assert len(crossings) > 10
    for c in crossings:
        assert np.min(np.hypot(*(curve - c).T)) < spacing


def test_bad_boxes_are_refused():
    case = load_case(path("fig03a"))
    with pytest.raises(CaseError, match="empty"):
        stability_boundary(case, (X, (1.0, 1.0)), (Y, (0.0, 3.0)))
    with pytest.raises(CaseError, match="same key"):
        stability_boundary(case, (X, (0.0, 1.0)), (X, (0.0, 3.0)))
    with pytest.raises(CaseError, match=r"slider\.rotational_damping = -1"):
        stability_boundary(case, (X, (0.0, 1.0)), (Y, (-1.0, 3.0)))


def test_a_box_without_sliding_equilibrium_is_refused():
    case = load_case(path("fig10"))  # a decelerating disc: no equilibrium
    with pytest.raises(CaseError, match="no sliding equilibrium"):
        stability_boundary(case, (X, (0.0, 12.0)), (Y, (0.0, 3.0)))
