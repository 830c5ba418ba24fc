"""Linear stability of the sliding equilibrium, the paper's perturbation test, and maps."""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from fivdisc.analysis.points import (
    ParameterPoints,
    check_box,
    check_jacobian,
    check_keys,
    check_rates,
    check_values,
    slip_jacobian,
    warn_if_long,
)
from fivdisc.analysis.symmetry import pad_ring
from fivdisc.case import Case, is_case_key, keys_like, unit_of
from fivdisc.engine.equilibrium import Equilibrium, sliding_equilibrium
from fivdisc.errors import CaseError, SimulationError, nearest
from fivdisc.limits import check_memory
from fivdisc.model.build import Model, build_model

if TYPE_CHECKING:
    import pandas as pd

#: Difference of energy shares below which two modes' labels follow their frequencies
#: (:func:`mode_labels`).
LABEL_TIE = 0.1

# Bytes per grid point of a stability map: growth rate and stability flag, and the
# dataset's and the netCDF writer's copies of them.
_GRID_BYTES = 3 * (8 + 1)


@dataclass(frozen=True, repr=False)
class LinearStability:
    """Eigen-analysis of the slip equations linearised about the sliding equilibrium.

    Attributes
    ----------
    equilibrium : Equilibrium
        The sliding equilibrium.
    jacobian : ndarray
        ``(2 (n + S), 2 (n + S))`` Jacobian in the variables ``(q, phi, qdot, phidot)``
        (phi and phidot of every slider).
    eigenvalues : ndarray
        Complex eigenvalues [1/s], sorted by decreasing real part.
    eigenvectors : ndarray
        Right eigenvectors (columns), in the order of ``eigenvalues``.
    dominant : tuple of str
        Per eigenvalue, its mode's label (:func:`mode_labels`): a coordinate
        (``"C01"``, ..., ``"phi"``; ``"phi0"``, ``"phi1"``, ... with several sliders)
        with a large share of the eigenvector's kinetic energy, a different one for
        every mode (the two eigenvalues of a complex pair share theirs).

    See Also
    --------
    linear_stability : Makes it.

    Examples
    --------
    In the paper's Table 1 case (Figs. 8 and 9) the slider's own mode is unstable,
    through the falling friction law, at about 222 Hz:

    >>> import fivdisc
    >>> stability = fivdisc.linear_stability(fivdisc.Case())
    >>> stability.stable, stability.dominant[0]
    (False, 'phi')
    >>> print(f"{stability.max_growth_rate:.2f} 1/s at {stability.frequencies[0]:.2f} Hz")
    239.69 1/s at 221.82 Hz
    >>> stability.jacobian.shape  # (q, phi, qdot, phidot): 7 modal coordinates, 1 slider
    (16, 16)
    """

    equilibrium: Equilibrium
    jacobian: np.ndarray
    eigenvalues: np.ndarray
    eigenvectors: np.ndarray
    dominant: tuple[str, ...]

    @property
    def max_growth_rate(self) -> float:
        """Largest real part of the eigenvalues [1/s]; > 0 means unstable."""
        return float(self.eigenvalues.real[0])

    @property
    def stable(self) -> bool:
        """Whether every eigenvalue has a negative real part (asymptotic stability)."""
        return self.max_growth_rate < 0.0

    @property
    def frequencies(self) -> np.ndarray:
        """Damped natural frequencies ``|Im(lambda)| / 2 pi`` [Hz]."""
        return np.abs(self.eigenvalues.imag) / (2.0 * np.pi)

    def to_dataframe(self) -> pd.DataFrame:
        """The eigenvalues as a table: one row per eigenvalue with a non-negative imaginary
        part (one of each complex pair), in order of decreasing growth rate.

        Columns: ``growth_rate`` [1/s] (the real part), ``frequency_hz`` [Hz] (the damped
        frequency) and ``coordinate`` (its mode's label, :attr:`dominant`).
        """
        import pandas as pd

        rows = [(float(lam.real), float(abs(lam.imag) / (2.0 * np.pi)), name)
                for lam, name in zip(self.eigenvalues, self.dominant, strict=True)
                if lam.imag >= 0.0]
        return pd.DataFrame(rows, columns=["growth_rate", "frequency_hz", "coordinate"])

    def lines(self) -> list[str]:
        """The equilibrium, the eigenvalue table and the verdict, as lines of text."""
        eq = self.equilibrium
        out = [f"sliding equilibrium at Omega = {eq.speed:.6g} rad/s:"]
        for j, (phi, nf, f) in enumerate(zip(eq.phi, eq.normal_force, eq.friction_force,
                                             strict=True)):
            who = f"slider {j}: " if eq.phi.size > 1 else ""
            out.append(f"  {who}phi = {phi:.6g} rad, N = {nf:.6g} N, f = {f:.6g} N")
        out.append(f"{'growth rate [1/s]':>18} {'frequency [Hz]':>15}  mode")
        out += [f"{row.growth_rate:18.6g} {row.frequency_hz:15.6g}  {row.coordinate}"
                for row in self.to_dataframe().itertuples()]
        out.append("stable" if self.stable
                   else f"unstable (max growth {self.max_growth_rate:.4g} 1/s)")
        return out

    def __str__(self) -> str:
        return "\n".join(self.lines())

    def __repr__(self) -> str:
        verdict = "stable" if self.stable else "unstable"
        return (f"<LinearStability at Omega = {self.equilibrium.speed:.6g} rad/s: {verdict}, "
                f"largest growth rate {self.max_growth_rate:.4g} 1/s ({self.dominant[0]}), "
                f"{self.eigenvalues.size} eigenvalues>")

    def _repr_pretty_(self, printer: Any, cycle: bool) -> None:  # IPython, Jupyter
        printer.text(str(self))

    def to_dict(self) -> dict:
        """The equilibrium and every eigenvalue as plain Python values (for JSON).

        Keys: ``speed`` [rad/s]; ``equilibrium`` with ``q`` [m], and per slider ``phi``
        [rad], ``normal_force`` [N], ``friction_force`` [N]; ``eigenvalues``, a list of
        ``real`` [1/s], ``imag`` [rad/s], ``frequency`` [Hz], ``coordinate``;
        ``stable``; ``max_growth_rate`` [1/s].
        """
        eq = self.equilibrium
        return {
            "speed": eq.speed,
            "equilibrium": {
                "q": eq.q.tolist(),
                "phi": eq.phi.tolist(),
                "normal_force": eq.normal_force.tolist(),
                "friction_force": eq.friction_force.tolist(),
            },
            "eigenvalues": [
                {
                    "real": float(lam.real),
                    "imag": float(lam.imag),
                    "frequency": float(abs(lam.imag) / (2.0 * np.pi)),
                    "coordinate": name,
                }
                for lam, name in zip(self.eigenvalues, self.dominant, strict=True)
            ],
            "stable": self.stable,
            "max_growth_rate": self.max_growth_rate,
        }


def _angle_names(model: Model) -> tuple[str, ...]:
    return ("phi",) if model.n_sliders == 1 else tuple(f"phi{j}" for j in range(model.n_sliders))


def linear_stability(case: Case | Model) -> LinearStability:
    """Eigenvalues of the slip equations linearised about the sliding equilibrium.

    Parameters
    ----------
    case : Case or Model
        A case at constant disc speed.

    Returns
    -------
    LinearStability
        The equilibrium, the eigenvalues and eigenvectors, and the coordinate each
        eigenvector moves most; ``print`` it for a table.

    Raises
    ------
    AnalysisError
        A rate of the model too fast for its eigenvalues to decide stability
        (:func:`~fivdisc.analysis.points.check_rates`), or a linearisation that is not
        finite.
    SimulationError
        No sliding equilibrium.

    See Also
    --------
    perturbation_test : The paper's test of the same question by simulation.
    stability_map : The largest growth rate over a grid of two case keys.
    eigen_branches : The eigenvalues followed along one key.

    Examples
    --------
    The paper's Table 1 case is unstable through its slider mode; more rotational
    damping and a little disc damping make it stable:

    >>> import fivdisc
    >>> print(fivdisc.linear_stability(fivdisc.Case()))
    sliding equilibrium at Omega = 6.28319 rad/s:
      phi = 0.0104946 rad, N = 434.226 N, f = 209.893 N
     growth rate [1/s]  frequency [Hz]  mode
               239.687         221.823  phi
              0.391607         411.434  C03
              0.270571         274.007  C02
             0.0153899         238.644  C00
            -0.0595182         241.543  D01
             -0.314983         180.853  C01
             -0.346412         290.487  D02
             -0.446632         441.789  D03
    unstable (max growth 239.7 1/s)
    >>> damped = fivdisc.Case(slider={"rotational_damping": 2.0}, disc={"damping_ratio": 0.01})
    >>> stability = fivdisc.linear_stability(damped)
    >>> print(stability.stable, f"{stability.max_growth_rate:.3f} 1/s", stability.dominant[0])
    True -7.390 1/s C01
    """
    model = case if isinstance(case, Model) else build_model(case)
    check_rates(model)
    try:
        eq = sliding_equilibrium(model)
    except SimulationError:
        # A linearisation that is not finite (the friction law's slope out of range) also
        # stops the root finder, which uses it: that is the cause to name.
        rest = np.zeros(model.state_size)
        check_jacobian(model, rest, slip_jacobian(model, rest))
        raise
    jac = slip_jacobian(model, eq.state)
    check_jacobian(model, eq.state, jac)
    lam, vec = np.linalg.eig(jac)
    order = np.lexsort((-lam.imag, -lam.real))
    lam = lam[order]
    vec = vec[:, order]
    return LinearStability(eq, jac, lam, vec, mode_labels(model, lam, vec))


def coordinate_names(model: Model) -> tuple[str, ...]:
    """The model's coordinates in the order of the slip equations' variables: the disc's
    modal coordinates (``"C00"``, ``"C01"``, ``"D01"``, ...), then the sliders' angles
    (``"phi"``; ``"phi0"``, ``"phi1"``, ... with several sliders)."""
    return (*model.labels, *_angle_names(model))


def energy_shares(model: Model, vectors: np.ndarray) -> np.ndarray:
    """``(coordinates, vectors)``: each coordinate's share of each eigenvector's kinetic
    energy (columns sum to 1; variables ``(q, phi, qdot, phidot)``, coordinates as
    :func:`coordinate_names`)."""
    size = model.n + model.n_sliders
    inertia = np.append(model.modal_mass, model.kernel.row("inertia"))
    # Velocity part of an eigenvector is lambda times its displacement part.
    energy = inertia[:, None] * np.abs(vectors[size:, :]) ** 2
    total = energy.sum(axis=0)
    return energy / np.where(total > 0, total, 1.0)


def dominant_coordinates(model: Model, vectors: np.ndarray) -> tuple[str, ...]:
    """Per eigenvector (columns, variables ``(q, phi, qdot, phidot)``), the coordinate
    with the largest share of its kinetic energy (``"C01"``, ..., ``"phi"``). Two
    eigenvectors may share one; :func:`mode_labels` names every mode apart."""
    names = coordinate_names(model)
    return tuple(names[i] for i in np.argmax(energy_shares(model, vectors), axis=0))


def mode_labels(model: Model, eigenvalues: np.ndarray, vectors: np.ndarray
                ) -> tuple[str, ...]:
    """One label per eigenvalue, a different one for every mode: a complex pair is one
    mode (both its eigenvalues get its label), a real eigenvalue another.

    Each coordinate (:func:`coordinate_names`) names at most one mode: the modes are
    matched to the coordinates so that the sum of the named coordinates' shares of the
    modes' kinetic energy (:func:`energy_shares`) is largest (an assignment problem,
    :func:`scipy.optimize.linear_sum_assignment`). The two modes of a disc mode with
    nodal diameters, which the sliders mix into travelling waves, are then ``C0l`` and
    ``D0l``, never both ``C0l``; identical pads' modes, each spread over every pad, are
    ``phi0``, ``phi1``, ``phi2``. Where two modes' shares leave the choice open (they
    would give up less than :data:`LABEL_TIE` of their shares by trading names: the two
    halves of travelling waves, identical pads) the lower frequency takes the
    coordinate listed first, so that labels do not turn on round-off. Where the pads are
    ``N`` identical ones equally spaced on a face (:func:`fivdisc.analysis.symmetry.
    pad_ring`), their coordinates are their patterns round the ring instead: ``phi~0``
    the pads in phase, ``phi~k`` the pattern whose phase advances by ``k/N`` of a cycle
    from one pad to the next in the direction of their angle (the pads' rates ``~
    exp(2 pi i k j / N)``, pad ``j`` the ``j``-th from pad 0). A mode left
    without a coordinate (real eigenvalues
    outnumber what is left: an overdamped coordinate has two) takes its dominant
    coordinate's name with a prime per earlier use (``"phi0'"``).

    Parameters
    ----------
    model : Model
        The model the eigenvectors belong to.
    eigenvalues : ndarray
        ``(k,)`` complex eigenvalues of the slip equations.
    vectors : ndarray
        ``(2 (n + S), k)`` their right eigenvectors (columns).

    Returns
    -------
    tuple of str
        In the order of `eigenvalues`.
    """
    from scipy.optimize import linear_sum_assignment

    lam = np.asarray(eigenvalues, dtype=complex)
    names = coordinate_names(model)
    scale = max(float(np.abs(lam).max(initial=0.0)), 1e-300)
    # One representative per mode: the eigenvalue with a positive imaginary part of a
    # pair, and each real eigenvalue; the other of a pair is its conjugate.
    real = np.abs(lam.imag) <= 1e-12 * scale
    modes = [i for i in range(lam.size) if real[i] or lam[i].imag > 0]
    shares = energy_shares(model, vectors[:, modes])
    ring = pad_ring(model)
    if ring is not None:
        # Identical pads equally spaced: each mode is spread over every pad alike, so
        # which pad it is named after would turn on round-off. The pads' part is named
        # by its pattern round the ring instead (the discrete Fourier components of the
        # pads' rates, whose energies sum to the pads' by Parseval's theorem).
        ns = model.n_sliders
        rates = vectors[model.n + ns + model.n:, :][ring][:, modes]
        patterns = np.abs(np.fft.fft(rates, axis=0)) ** 2 / ns
        pads = shares[model.n:].sum(axis=0)
        shares[model.n:] = patterns * pads / np.where(patterns.sum(axis=0) > 0,
                                                      patterns.sum(axis=0), 1.0)
        names = (*model.labels, *(f"phi~{k}" for k in range(ns)))
    rows, cols = linear_sum_assignment(-shares)
    coordinate = dict(zip(cols.tolist(), rows.tolist(), strict=True))  # mode -> coordinate
    # Near-ties follow the frequencies: where two modes would give up less than
    # LABEL_TIE of their shares by trading names (a travelling wave's C and D halves,
    # identical pads), the lower frequency takes the coordinate listed first. The
    # labels are then the same for eigenvectors equal to round-off, as the same
    # eigenvalue met in two scans is.
    order = [(abs(lam[i].imag), lam[i].real) for i in modes]
    for _ in range(len(modes) ** 2):
        swapped = False
        for a, b in itertools.combinations(sorted(coordinate), 2):
            ca, cb = coordinate[a], coordinate[b]
            loss = shares[ca, a] + shares[cb, b] - shares[cb, a] - shares[ca, b]
            if loss < LABEL_TIE and (order[a] < order[b]) != (ca < cb):
                coordinate[a], coordinate[b] = cb, ca
                swapped = True
        if not swapped:
            break
    label = {modes[c]: names[r] for c, r in coordinate.items()}
    used = {name: 1 for name in label.values()}
    for k, i in enumerate(modes):
        if i not in label:
            base = names[int(np.argmax(shares[:, k]))]
            label[i] = base + "'" * used.get(base, 0)
            used[base] = used.get(base, 0) + 1
    out = []
    for i in range(lam.size):
        if i in label:
            out.append(label[i])
        else:
            # The lower eigenvalue of a pair: its conjugate's label.
            partner = min((j for j in modes if not real[j]),
                          key=lambda j: abs(lam[j] - np.conj(lam[i])))
            out.append(label[partner])
    return tuple(out)


@dataclass(frozen=True)
class PerturbationTest:
    """The paper's stability test: perturb the equilibrium, simulate, compare amplitudes.

    Amplitudes are square roots of the deviation energy
    ``sum M (qdot^2 + omega^2 (q - q_eq)^2) + sum_j I_j phidot_j^2 + r_j^2 k_phi_j (phi_j -
    phi_eq_j)^2``,
    a norm of the whole state, so slowly growing disc modes count as much as the slider.

    Attributes
    ----------
    initial_amplitude, final_amplitude : float
        Amplitude [sqrt(J)] of the perturbation at the start, and the largest in the last
        tenth of the run.
    growth_rate : float
        ``log(final / initial) / duration`` [1/s], a rough envelope rate.
    decays : bool
        Whether the perturbation shrank.

    See Also
    --------
    perturbation_test : Makes it.

    Examples
    --------
    >>> import fivdisc
    >>> test = fivdisc.perturbation_test(fivdisc.Case(), duration=0.05)
    >>> print(test.decays, f"{test.initial_amplitude:.4f} -> {test.final_amplitude:.3f}")
    False 0.0447 -> 0.490
    """

    initial_amplitude: float
    final_amplitude: float
    growth_rate: float
    decays: bool


def perturbation_test(case: Case, duration: float | None = None) -> PerturbationTest:
    """Simulate from the perturbed sliding equilibrium and see whether it decays (paper 3.1).

    Parameters
    ----------
    case : Case
        Constant-speed case; ``simulation.perturbation`` sets the offsets.
    duration : float, optional
        Simulated time [s]; defaults to the case's ``simulation.duration``. Growth or decay
        slower than a few times 1/duration cannot be told apart from constancy.

    Returns
    -------
    PerturbationTest
        The perturbation's amplitude at the start and at the end, and whether it
        decayed.

    See Also
    --------
    linear_stability : The eigenvalues: growth rates however slow, without a
        simulation.

    Examples
    --------
    Over 50 ms the perturbation of the paper's Table 1 case grows into stick-slip, whose
    amplitude the nonlinearity bounds (so the envelope rate is well below the
    linearisation's 240 1/s), and dies out when the slider is damped:

    >>> import fivdisc
    >>> for damping in (0.1, 2.0):
    ...     case = fivdisc.Case(slider={"rotational_damping": damping},
    ...                         disc={"damping_ratio": 0.01})
    ...     test = fivdisc.perturbation_test(case, duration=0.05)
    ...     print(damping, test.decays, f"{test.growth_rate:.0f} 1/s")
    0.1 False 48 1/s
    2.0 True -77 1/s
    """
    from fivdisc.engine.simulation import simulate

    updates: dict = {"simulation.initial_state": "equilibrium"}
    if duration is not None:
        updates["simulation.duration"] = duration
    run = case.replace(updates)
    model = build_model(run)
    eq = sliding_equilibrium(model)
    ds = simulate(run).dataset
    dq = ds["q"].values - eq.q
    kern = model.kernel
    energy = (
        np.sum(model.modal_mass * (ds["q_dot"].values ** 2 + model.omega**2 * dq**2), axis=1)
        + np.sum(kern.row("inertia") * ds["phi_dot"].values ** 2, axis=1)
        + np.sum(kern.row("kphi") * (ds["phi"].values - eq.phi) ** 2, axis=1)
    )
    amplitude = np.sqrt(energy)
    span = max(1, amplitude.size // 10)
    first = float(amplitude[0])
    last = float(np.max(amplitude[-span:]))
    elapsed = ds["time"].values[-1] - ds["time"].values[0]
    rate = float(np.log(last / first) / elapsed) if first > 0 and last > 0 else float("nan")
    return PerturbationTest(first, last, rate, last < first)


def stability_map(
    case: Case,
    x: tuple[str, Sequence[float]],
    y: tuple[str, Sequence[float]],
    curves: tuple[str, Sequence[float]] | None = None,
    progress: bool = False,
) -> xr.Dataset:
    """Largest growth rate of the linearised slip equations over a parameter grid.

    Parameters
    ----------
    case : Case
        Base case at constant speed.
    x, y : (str, sequence of float)
        Dotted case key and values of the horizontal and vertical axes, for example
        ``("slider.normal_damping", np.linspace(0, 12, 200))``.
    curves : (str, sequence of float), optional
        A third key whose values give one map (and one boundary curve) each, e.g.
        ``("friction.decay", [0, 1, 10])``.
    progress : bool
        Show a progress bar.

    Returns
    -------
    xarray.Dataset
        Dimensions named after the keys, with their values, units and descriptions:
        (curves key, y key, x key), or (y key, x key) without `curves`. Variables
        ``max_growth_rate`` [1/s] (NaN where no sliding equilibrium exists) and
        ``stable`` (1 stable, 0 unstable) on all of them, and ``boundary`` (curves key,
        x key): the lowest value of y where the growth rate changes sign at that x,
        interpolated linearly, whichever side is stable (NaN if it keeps its sign in the
        column). :func:`fivdisc.analysis.boundary.stability_boundary` traces the
        boundary exactly, as curves. Attributes ``x_key``,
        ``y_key`` and (with `curves`) ``curve_key`` name the axes; the CF global
        attributes and the base case's TOML (``case``) are there too.

    See Also
    --------
    stability_boundary : The boundary traced as curves, to the root finder's
        tolerance, instead of sampled on a grid.
    fivdisc.plots.plot_stability_map : Draws the map.

    Examples
    --------
    A slider on a rigid disc (no modes) with the falling exponential friction law is
    stable where its rotational damping ``c`` exceeds the friction's negative damping,
    ``c > r^2 N0 alpha (mu_0 - mu_1) exp(-alpha r Omega) = 1.25 exp(-0.1 Omega)``
    [N m s/rad]:

    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []})
    >>> grid = fivdisc.stability_map(rigid, ("speed.value", [2.0, 6.0, 10.0, 14.0]),
    ...                              ("slider.rotational_damping", [0.25, 0.5, 1.0]))
    >>> print(grid["stable"].values)
    [[0 0 0 0]
     [0 0 1 1]
     [0 1 1 1]]
    >>> print(grid["boundary"].values.round(4))  # the growth rate is linear in c here
    [   nan 0.686  0.4598 0.3082]
    """
    axes = [(x[0], check_values("x", x[0], x[1])), (y[0], check_values("y", y[0], y[1]))]
    if curves:
        axes.append((curves[0], np.asarray(curves[1], dtype=float)))
    (xkey, xs), (ykey, ys) = axes[:2]
    check_map_size(case, [len(values) for _, values in axes])
    names = ["x", "y", "curves"][: len(axes)]
    check_keys(case, [key for key, _ in axes], names)
    check_box(case, axes, names)
    cs = axes[2][1] if curves else [None]
    points = ParameterPoints(case, [key for key, _ in axes])
    warn_if_long(points, [values[0] for _, values in axes],
                 math.prod(len(values) for _, values in axes),
                 f"a stability map of {' x '.join(str(len(v)) for _, v in axes)}",
                 "fewer points per axis")
    growth = np.full((len(cs), ys.size, xs.size), np.nan)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=growth.size, desc="stability map", unit="pt")
    for ic, cval in enumerate(cs):
        fixed = () if cval is None else (cval,)
        for iy, yval in enumerate(ys):
            jacs = []
            guess = None
            for xval in xs:
                point = points.linearise((xval, yval, *fixed), guess)
                if point is None:
                    jacs.append(np.full((points.size,) * 2, np.nan))
                    continue
                _, guess, jac = point
                jacs.append(jac)
            stack = np.stack(jacs)
            ok = np.isfinite(stack).all(axis=(1, 2))
            growth[ic, iy, ok] = np.max(np.linalg.eigvals(stack[ok]).real, axis=1)
            if bar is not None:
                bar.update(xs.size)
    if bar is not None:
        bar.close()
    stable = growth < 0.0
    boundary = np.full((len(cs), xs.size), np.nan)
    for ic in range(len(cs)):
        for ix in range(xs.size):
            # The lowest change of sign in the column, whichever side is stable.
            col = growth[ic, :, ix]
            change = np.flatnonzero(((col[:-1] < 0.0) != (col[1:] < 0.0))
                                    & np.isfinite(col[:-1]) & np.isfinite(col[1:]))
            if change.size == 0:
                continue
            i = change[0]
            g0, g1 = col[i], col[i + 1]
            boundary[ic, ix] = ys[i] + (ys[i + 1] - ys[i]) * g0 / (g0 - g1)
    from fivdisc.engine.conventions import global_attrs, key_attrs, units

    ckey = curves[0] if curves else ""
    dims = (ckey, ykey, xkey) if curves else (ykey, xkey)
    growth = growth if curves else growth[0]
    stable = stable if curves else stable[0]
    boundary = boundary if curves else boundary[0]
    coords = {key: (key, values, key_attrs(key)) for key, values in axes}
    yinfo = key_attrs(ykey)
    attrs = {
        **global_attrs(f"fivdisc stability map over {xkey} and {ykey}"
                       + (f", one per {ckey}" if curves else ""), "fivdisc.stability_map"),
        "fivdisc_kind": "stability_map",
        "x_key": xkey,
        "y_key": ykey,
        **({"curve_key": ckey} if curves else {}),
        "case": case.to_toml(),
    }
    return xr.Dataset(
        {
            "max_growth_rate": (dims, growth, {
                "units": "1/s",
                "long_name": "largest real part of the eigenvalues of the linearised slip "
                             "equations (nan: no sliding equilibrium)"}),
            "stable": (dims, stable.astype(np.int8), {
                "units": "1", "long_name": "sliding equilibrium asymptotically stable",
                "flag_values": np.array([0, 1], dtype=np.int8),
                "flag_meanings": "unstable stable"}),
            "boundary": ((*dims[:-2], xkey), boundary, {
                "units": units(unit_of(ykey)),
                "long_name": f"stability boundary: the lowest {yinfo['long_name']} where the "
                             "growth rate changes sign, either way (nan: none in the "
                             "column)"}),
        },
        coords=coords,
        attrs=attrs,
    )


def check_map_size(case: Case, sizes: Sequence[int]) -> None:
    """Refuse a stability map of `sizes` points per axis (x, y and curves) whose memory
    exceeds what the machine has, before any axis' values are made."""
    n = 2 * sum(1 if l == 0 else 2 for _, l in case.disc.modes) + 2 * len(case.sliders)
    check_memory(
        _GRID_BYTES * math.prod(sizes) + 16.0 * sizes[0] * n * n + 8.0 * sum(sizes),
        f"a stability map of {' x '.join(str(size) for size in sizes)} points",
        "use fewer points per axis",
    )


def range_size(text: str, option: str) -> int:
    """How many values ``KEY=START:STOP:N`` or ``KEY=v1,v2,...`` gives, without making
    them (so that a size can be checked before they are); a usage error if `text` is
    neither."""
    usage = f"{option} = {text!r} is invalid: write KEY=START:STOP:N or KEY=v1,v2,..."
    spec = text.split("=", 1)[1] if "=" in text else None
    if spec is None:
        raise CaseError(usage)
    if ":" not in spec:
        return spec.count(",") + 1
    parts = spec.split(":")
    try:
        count = int(parts[2]) if len(parts) == 3 else -1
    except ValueError:
        raise CaseError(usage) from None
    if count < 1:
        raise CaseError(usage)
    return count


def resolve_key(key: str, option: str) -> str:
    """Full dotted case key from a dotted key or an unambiguous last part (``decay``).

    Raises
    ------
    CaseError
        An ambiguous last part (the message lists the keys it could be), or an unknown
        key (the message names the nearest valid one).
    """
    keys = Case.valid_keys()
    if is_case_key(key):
        return key
    matches = [k for k in keys if k.rsplit(".", 1)[-1] == key]
    if len(matches) == 1:
        return matches[0]
    if len(matches) > 1:
        raise CaseError(f"{option}: key '{key}' is ambiguous: write one of {', '.join(matches)}")
    raise CaseError(f"{option}: unknown case key '{key}'{nearest(key, keys_like(key))} "
                    "(every key, with its unit: fivdisc examples default)")


def parse_range(text: str, option: str, per_value: float = 8.0) -> tuple[str, np.ndarray]:
    """Parse ``KEY=START:STOP:N`` (inclusive linspace) or ``KEY=v1,v2,...``; refuse N
    values whose memory, `per_value` bytes each (the work they are for, default the
    values alone), exceeds what the machine has, before they are made."""
    usage = f"{option} = {text!r} is invalid: write KEY=START:STOP:N or KEY=v1,v2,..."
    if "=" not in text:
        raise CaseError(usage)
    key, spec = text.split("=", 1)
    try:
        if ":" in spec:
            start, stop, num = spec.split(":")
            count = int(num)
            check_memory(per_value * count, f"{option} with N = {count} values", "lower N")
            values = np.linspace(float(start), float(stop), count)
        else:
            values = np.array([float(v) for v in spec.split(",")])
    except ValueError:
        raise CaseError(usage) from None
    if values.size < 1 or not np.all(np.isfinite(values)):
        raise CaseError(usage)
    # -0.0 == 0.0: np.unique counts them as one value.
    if np.unique(values).size != values.size:
        raise CaseError(f"{option} = {text!r} is invalid: its values must be distinct "
                        "(a repeated value gives a map of repeated columns or curves)")
    return resolve_key(key.strip(), option), values
