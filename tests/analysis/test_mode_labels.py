"""One label per mode, the same for one eigenvalue in the table, the branches, the Hopf
points, the file and the figure, and the same across calls; a mode coupling only where
two frequencies meet (issue 40, item 1). The labels are checked against the eigenvectors
themselves: their kinetic energy, computed here from the modal masses and inertias."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import xarray as xr

from fivdisc.analysis.eigenbranches import eigen_branches, follow, mode_couplings
from fivdisc.analysis.hopf import hopf_points
from fivdisc.analysis.stability import LABEL_TIE, linear_stability
from fivdisc.case import load_case
from fivdisc.examples import path
from fivdisc.model.build import build_model
from fivdisc.paper import FIG8, FIG28

from support.cases import THREE_PADS
from support.cli import run_cli

SPEEDS = ("speed.value", np.linspace(0.5, 30.0, 60))  # 22 rad/s, the case's, among them


def _shares(case, vectors) -> tuple[list[str], np.ndarray]:
    """Coordinates and their shares of each eigenvector's kinetic energy, from the modal
    masses and the sliders' inertias (velocity rows of the eigenvectors). Identical pads
    equally spaced on one face are named by their pattern round the ring instead: the
    energy of the pads' rates in each discrete Fourier component, pads taken by
    increasing angle, ``phi~k`` the one whose phase advances ``k/N`` of a cycle from one
    pad to the next."""
    model = build_model(case)
    pads = case.sliders
    names = [*model.labels, *(["phi"] if len(pads) == 1
                              else [f"phi{j}" for j in range(len(pads))])]
    inertia = np.r_[model.modal_mass, [s.mass * s.track_radius**2 for s in pads]]
    energy = inertia[:, None] * np.abs(vectors[len(names):]) ** 2
    ring = len(pads) > 1 and len({s.face for s in pads}) == 1 and all(
        s.model_dump(exclude={"angle", "perturbation"})
        == pads[0].model_dump(exclude={"angle", "perturbation"}) for s in pads) and np.allclose(
        np.diff(np.sort([s.angle % (2 * np.pi) for s in pads])), 2 * np.pi / len(pads))
    if ring:
        n, ns = model.n, len(pads)
        order = np.argsort([s.angle % (2 * np.pi) for s in pads])
        order = np.roll(order, -int(np.flatnonzero(order == 0)[0]))
        rates = vectors[len(names) + n:][order]
        j = np.arange(ns)
        basis = np.exp(-2j * np.pi * np.outer(j, j) / ns)  # row k: e^{-2 pi i k j / N}
        energy[n:] = inertia[n] * np.abs(basis @ rates) ** 2 / ns
        names = [*model.labels, *(f"phi~{k}" for k in range(ns))]
    return names, energy / energy.sum(axis=0)


def _upper(lin):
    return [i for i, lam in enumerate(lin.eigenvalues) if lam.imag > 0]


@pytest.mark.parametrize("case", [
    THREE_PADS, load_case(path("two-pads")), FIG8.case,
    FIG28.case.replace({"simulation.printed_gyroscopic_sign": True}),
], ids=["three-pads", "two-pads", "fig8", "fig28-printed"])
def test_every_mode_has_its_own_label_and_holds_energy_in_it(case):
    """Distinct labels (argmax gave phi2 twice on three pads, D01, D02, D03 twice each on
    Fig. 28 with the printed sign), a pair's two eigenvalues sharing one; each label a
    coordinate holding a fair share of its mode's energy, and no trade of two labels
    gaining more than the tie margin (the assignment is optimal pair by pair)."""
    lin = linear_stability(case)
    upper = _upper(lin)
    labels = [lin.dominant[i] for i in upper]
    assert len(set(labels)) == len(labels), labels
    for i, lam in enumerate(lin.eigenvalues):
        partner = int(np.argmin(np.abs(lin.eigenvalues - np.conj(lam))))
        assert lin.dominant[partner] == lin.dominant[i]
    names, shares = _shares(case, lin.eigenvectors[:, upper])
    rows = [names.index(label) for label in labels]
    for k, r in enumerate(rows):
        assert shares[r, k] > 0.1, (labels[k], shares[:, k])
    for a, b in itertools.combinations(range(len(rows)), 2):
        gain = (shares[rows[b], a] + shares[rows[a], b]) - (shares[rows[a], a]
                                                             + shares[rows[b], b])
        assert gain < LABEL_TIE


def test_a_single_pad_s_clear_modes_keep_their_dominant_coordinate():
    """Where one coordinate clearly holds each mode (one pad, the skew sign) the label
    is that coordinate, as before."""
    lin = linear_stability(FIG8.case)
    upper = _upper(lin)
    names, shares = _shares(FIG8.case, lin.eigenvectors[:, upper])
    assert [lin.dominant[i] for i in upper] == [names[r] for r in np.argmax(shares, axis=0)]


def test_three_pads_are_named_by_their_pattern_at_every_speed():
    """Three identical pads: the three pad modes (their energy in the pads) are named by
    their pattern round the ring, each by the pattern that holds most of its pads'
    energy, whatever their frequencies' order (it changes between 19.5 and 22 rad/s,
    where naming by frequency swapped the names of one eigenvalue)."""
    for speed in (19.5, 22.0):
        case = THREE_PADS.replace({"speed.value": speed})
        lin = linear_stability(case)
        upper = _upper(lin)
        names, shares = _shares(case, lin.eigenvectors[:, upper])
        pads = [k for k, i in enumerate(upper) if lin.dominant[i].startswith("phi")]
        assert len(pads) == 3
        rows = [names.index(f"phi~{k}") for k in range(3)]
        assert all(shares[rows, k].sum() > 0.9 for k in pads)
        for k in pads:
            assert lin.dominant[upper[k]] == names[rows[int(np.argmax(shares[rows, k]))]]


def test_branches_hopf_points_and_the_table_use_one_label_per_eigenvalue():
    """The branches are named where the scan meets the case's own speed (22 rad/s), as
    the table at that speed names the same eigenvalues; two scans of other ranges name
    them alike; each Hopf point carries its branch's label."""
    lin = linear_stability(THREE_PADS)
    table = {complex(lam): label for lam, label in zip(lin.eigenvalues, lin.dominant,
                                                      strict=True)}
    for values in (SPEEDS[1], np.linspace(8.0, 30.0, 45)):
        ds = eigen_branches(THREE_PADS, "speed.value", values)
        row = int(np.argmin(np.abs(values - 22.0)))
        assert ds["mode"].attrs["labelled_at"] == pytest.approx(22.0)
        lam = ds["growth_rate"].values[row] + 2j * np.pi * ds["frequency"].values[row]
        for b, value in enumerate(lam):
            nearest = min(table, key=lambda t, v=value: abs(t - v))
            assert abs(nearest - value) < 1e-6 * abs(value)
            assert str(ds["mode"].values[b]) == table[nearest]
        hopf = hopf_points(THREE_PADS, "speed.value", values, branches=ds)
        for hp in hopf:
            # Its branch: the one whose growth rate changes sign there at its frequency.
            i = int(np.searchsorted(values, hp.value)) - 1
            growth = ds["growth_rate"].values[i : i + 2]
            crossing = np.flatnonzero((np.sign(growth[0]) != np.sign(growth[1]))
                                      & (ds["frequency"].values[i] > 0))
            b = min(crossing, key=lambda c: abs(ds["frequency"].values[i, c] - hp.frequency))
            assert hp.mode == str(ds["mode"].values[b])
        # Three pad Hopf points near 19.3 rad/s, one per pad mode.
        late = [hp.mode for hp in hopf if 19.0 < hp.value < 20.0]
        assert sorted(late) == ["phi~0", "phi~1", "phi~2"]


def test_the_command_writes_and_prints_the_labels_it_draws(tmp_path):
    out = tmp_path / "branches.nc"
    spec = f"speed.value={SPEEDS[1][0]}:{SPEEDS[1][-1]}:{SPEEDS[1].size}"
    case = tmp_path / "three.toml"
    case.write_text(THREE_PADS.to_toml())
    res = run_cli(["stability", case, "--x", spec, "-o", out, "--no-progress"])
    assert res.exit_code == 0, res.output
    with xr.open_dataset(out) as ds:
        modes, hopf_modes = ds["mode"].values.tolist(), ds["hopf_mode"].values.tolist()
        on_boundary = ds["hopf_on_boundary"].values.tolist()
        unstable = ds["hopf_unstable_modes"].values.tolist()
        ds = ds.load()
    lines = [line for line in res.stdout.splitlines() if line.startswith("Hopf point")]
    assert len(lines) == len(hopf_modes) > 0
    for line, mode, edge, others in zip(lines, hopf_modes, on_boundary, unstable,
                                        strict=True):
        assert f": {mode} at " in line
        assert mode in modes
        assert (edge == 1) == ("stay" not in line)
        if others:
            assert f"({others} stay" in line
    from fivdisc.plots.stability import plot_eigen_branches

    fig = plot_eigen_branches(ds)
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert len(set(legend)) == len(legend)
    assert set(hopf_modes) <= set(legend)


def test_a_coupling_is_reported_only_where_two_frequencies_meet():
    """The trial's report at 6 rad/s (269.1 and 271.8 Hz, rates -1.58 and -5.36 1/s) was
    two modes 1 % apart that never meet; identical pads, always within 0.3 % of each
    other, do not couple either. The one coupling of the three-pad scan is the (0, 2)
    pair's, near 2 rad/s, where the frequency gap is smaller than the growth-rate gap
    and one of them leaves zero at the next Hopf point (second route: the eigenvalues
    and the Hopf points)."""
    ps = np.linspace(0.0, 1.0, 21)
    lam = []
    for p in ps:
        a = -1.58 + 2j * np.pi * (269.1 + 0.5 * p)
        b = -5.36 - 0.5 * p + 2j * np.pi * (271.8 - 0.5 * p)
        lam.append([a, b, a.conjugate(), b.conjugate()])
    assert mode_couplings(follow(np.array(lam))) == []
    ds = eigen_branches(THREE_PADS, *SPEEDS)
    found = list(zip(ds["coupling"].values, ds["coupling_first"].values,
                     ds["coupling_second"].values, strict=True))
    assert len(found) == 1
    value, a, b = found[0]
    assert {str(ds["mode"].values[a]), str(ds["mode"].values[b])} == {"C02", "D02"}
    i = int(np.argmin(np.abs(SPEEDS[1] - value)))
    lam = ds["growth_rate"].values[i] + 2j * np.pi * ds["frequency"].values[i]
    assert abs(lam[a].imag - lam[b].imag) <= abs(lam[a].real - lam[b].real)
    assert 1.0 < value < 3.0
    hopf = hopf_points(THREE_PADS, *SPEEDS, branches=ds)
    assert any(hp.mode in ("C02", "D02") and value < hp.value < value + 1.0 for hp in hopf)


def test_an_overdamped_coordinate_s_two_real_eigenvalues_are_named_apart():
    """A heavily damped slider has two real eigenvalues for one coordinate: the second
    takes a prime, and both are the slider's (second route: their eigenvectors' energy
    is all in phi)."""
    from fivdisc import Case

    case = Case(disc={"modes": [[0, 0], [0, 1]]}, slider={"rotational_damping": 500.0},
                speed={"value": 12.0})
    lin = linear_stability(case)
    real = [i for i, lam in enumerate(lin.eigenvalues) if lam.imag == 0]
    assert sorted(lin.dominant[i] for i in real) == ["phi", "phi'"]
    names, shares = _shares(case, lin.eigenvectors[:, real])
    assert np.all(shares[names.index("phi")] > 0.99)
    labels = [lin.dominant[i] for i in range(lin.eigenvalues.size)
              if lin.eigenvalues[i].imag >= 0]
    assert len(set(labels)) == len(labels)
