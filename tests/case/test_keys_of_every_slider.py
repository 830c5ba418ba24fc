"""Keys that act on every slider (issue 36, item 5): ``sliders.*.KEY``, the rule for
``slider.KEY`` with several sliders, ``[slider]`` shared by ``[[sliders]]`` tables, and a
slider's own perturbation."""

from __future__ import annotations

import numpy as np
import pytest

from fivdisc.case import Case, describe_key, is_case_key
from fivdisc.errors import CaseError
from fivdisc.model.build import build_model, model_at

THREE = Case(disc={"modes": [[0, 0], [0, 1]]},
             sliders=[{"angle": 2 * np.pi * k / 3} for k in range(3)])


def test_every_slider_key_sets_and_reads_every_slider():
    new = THREE.replace({"sliders.*.normal_stiffness": 3.2e4})
    assert [s.normal_stiffness for s in new.sliders] == [3.2e4] * 3
    assert new.get("sliders.*.normal_stiffness") == 3.2e4
    # the rule: slider.KEY with several sliders is sliders.*.KEY
    same = THREE.replace({"slider.normal_stiffness": 3.2e4})
    assert same == new
    assert same.get("slider.normal_stiffness") == 3.2e4
    assert is_case_key("sliders.*.preload")
    assert describe_key("sliders.*.normal_stiffness").long_name == \
        "normal stiffness of every slider"
    assert describe_key("sliders.*.normal_stiffness").unit == "N/m"


def test_an_every_slider_value_that_differs_is_refused_by_name():
    one = THREE.replace({"sliders.1.preload": 450.0})
    with pytest.raises(CaseError, match=r"'sliders.\*.preload' has no single value: the "
                       r"sliders' values differ \(500.0, 450.0, 500.0\); set it, or name "
                       r"one slider \(sliders.J.preload, J from 0 to 2\)"):
        one.get("sliders.*.preload")
    with pytest.raises(CaseError, match="slider index '3' is invalid"):
        THREE.get("sliders.3.preload")


def test_a_patched_model_equals_the_model_of_the_replaced_case():
    base = build_model(THREE)
    for key in ("sliders.*.normal_stiffness", "slider.preload", "sliders.2.normal_damping"):
        patched = model_at(base, THREE, {key: 123.0})
        built = build_model(THREE.replace({key: 123.0}))
        np.testing.assert_array_equal(patched.kernel.slider, built.kernel.slider)


def test_a_slider_table_beside_sliders_tables_is_what_they_share():
    case = Case.from_toml("[slider]\nmass = 0.2\npreload = 400.0\n"
                          "[[sliders]]\nangle = 0.0\n"
                          "[[sliders]]\nangle = 3.0\nmass = 0.3\n")
    assert [(s.mass, s.preload, s.angle) for s in case.sliders] == [(0.2, 400.0, 0.0),
                                                                     (0.3, 400.0, 3.0)]


def test_a_slider_perturbation_is_added_to_the_common_one():
    from fivdisc.engine.simulation import initial_state

    case = THREE.replace({"simulation.initial_state": "equilibrium",
                          "simulation.perturbation.phi_dot": 1.0,
                          "sliders.1.perturbation.phi_dot": 0.5,
                          "sliders.2.perturbation.phi": 1e-4})
    plain = THREE.replace({"simulation.initial_state": "equilibrium",
                           "simulation.perturbation.phi_dot": 1.0})
    model = build_model(case)
    y, y0 = initial_state(model), initial_state(build_model(plain))
    dphi = (y - y0)[model.index("phi"): model.index("phi") + 3]
    drate = (y - y0)[model.index("phi_dot"): model.index("phi_dot") + 3]
    np.testing.assert_allclose(dphi, [0.0, 0.0, 1e-4], atol=1e-15)
    np.testing.assert_allclose(drate, [0.0, 0.5, 0.0], atol=1e-15)
    assert Case.from_toml(case.to_toml()) == case


ISSUE_CASE = """
[disc]
modes = [[0, 0], [0, 1], [0, 2], [0, 3]]
damping_ratio = 0.003
[slider]
mass = 0.1
normal_stiffness = 3e4
normal_damping = 0.1
rotational_stiffness = 2e3
rotational_damping = 0.1
preload = 500.0
[[sliders]]
angle = 0.0
[[sliders]]
angle = 2.0943951023931953
[[sliders]]
angle = 4.1887902047863905
[friction]
law = "stribeck"
static = 0.8
kinetic_max = 0.6
kinetic_min = 0.35
stribeck_velocity = 1.0
stribeck_exponent = 2.0
[speed]
value = 22.0
"""


def test_the_speed_and_pad_stiffness_boundary_of_three_pads_is_one_command(tmp_path):
    """``fivdisc stability --boundary speed.value=... sliders.*.normal_stiffness=...`` on
    the issue's three identical pads: one curve through the Hopf point at 19.573 rad/s and
    3e4 N/m, each of whose points is a Hopf point of the case with every pad's stiffness
    set (a second route: the growth rate of the linearisation there)."""
    import xarray as xr

    from fivdisc.analysis.stability import linear_stability

    from support.cli import run_cli

    path = tmp_path / "three.toml"
    path.write_text(ISSUE_CASE, encoding="utf-8")
    case = Case.from_toml(ISSUE_CASE)
    out = tmp_path / "b.nc"
    res = run_cli(["stability", path, "--boundary", "speed.value=5:30",
                   "sliders.*.normal_stiffness=1e4:6e4", "-o", out, "--no-progress"])
    assert res.exit_code == 0, res.output
    ds = xr.open_dataset(out)
    x, y = ds["speed.value"].values, ds["sliders.*.normal_stiffness"].values
    assert x.size > 10
    at = np.interp(3e4, y[::-1], x[::-1]) if y[0] > y[-1] else np.interp(3e4, y, x)
    assert at == pytest.approx(19.5731, abs=2e-3)
    for i in (0, x.size // 2, x.size - 1):
        lam = linear_stability(case.replace({"speed.value": float(x[i]),
                                             "sliders.*.normal_stiffness": float(y[i])}))
        assert abs(lam.max_growth_rate) < 1e-6 * np.max(np.abs(lam.eigenvalues))


def test_a_sweep_axis_of_every_slider_sets_every_slider():
    from fivdisc.sweep.spec import Sweep

    sweep = Sweep(base=THREE, axes={"sliders.*.normal_damping": "0.5:1.5:3"})
    dampings = [[s.normal_damping for s in case.sliders] for case in sweep]
    assert dampings == [[0.5] * 3, [1.0] * 3, [1.5] * 3]
