"""The sliding equilibrium and its eigenvalues followed along one key, by continuity.

Re-sorting the eigenvalues at every value of a parameter (by frequency, by growth rate)
swaps modes wherever two of them cross in that order, which hides what happens there.
Here each eigenvalue is followed from one value to the next: the eigenvalues at the next
value are assigned to the branches so that the total distance from each branch's linear
extrapolation is least (an assignment problem, :func:`scipy.optimize.linear_sum_assignment`).
Veering modes then keep their branch, and coupling modes (two frequencies that merge
while one growth rate leaves zero, the flutter of brake squeal) show as such.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import xarray as xr

from fivdisc.analysis.points import (
    ParameterPoints,
    check_box,
    check_keys,
    check_values,
    warn_if_long,
)
from fivdisc.analysis.stability import mode_labels
from fivdisc.case import Case
from fivdisc.engine.equilibrium import Equilibrium, slip_evaluation
from fivdisc.limits import check_memory
from fivdisc.model.build import Model

# Two branches' frequencies count as merged (a coupling) within this fraction of the
# frequency: inside a flutter region of an undamped system they are equal, damping
# leaves them apart by about the difference of the modes' damping rates.
COUPLING_TOLERANCE = 0.01


def follow(lam: np.ndarray) -> np.ndarray:
    """Eigenvalues at successive parameter values reordered into branches.

    Parameters
    ----------
    lam : ndarray
        ``(values, k)`` complex eigenvalues, each row in any order; rows of NaN (no
        equilibrium) break the branches, which resume from the last finite row.

    Returns
    -------
    ndarray
        The same rows, reordered: column b is branch b. The first finite row is ordered
        by the imaginary part's sign (positive first) and magnitude.

    Notes
    -----
    Row i + 1 is assigned to the branches so that the sum of the distances
    ``|lambda_b(i + 1) - (2 lambda_b(i) - lambda_b(i - 1))|`` to the branches' linear
    extrapolations is least (:func:`scipy.optimize.linear_sum_assignment`).
    """
    from scipy.optimize import linear_sum_assignment

    out = np.array(lam, dtype=complex)
    history: list[np.ndarray] = []
    last = None
    for i, row in enumerate(out):
        if not np.isfinite(row).all():
            history = []
            continue
        if last is None:
            out[i] = row[np.lexsort((np.abs(row.imag), row.imag < 0))]
        else:
            prior = history or [last]
            guess = prior[-1] if len(prior) < 2 else 2.0 * prior[-1] - prior[-2]
            _, order = linear_sum_assignment(np.abs(guess[:, None] - row[None, :]))
            out[i] = row[order]
        last = out[i]
        history = [*history[-1:], out[i]]
    return out


def _existence_limit(points: ParameterPoints, inside: float, outside: float,
                     guess: Equilibrium) -> float:
    """Value of the key between `inside` (the equilibrium exists) and `outside` (it does
    not) where it ceases to exist: where the smallest normal force of the solution of the
    slip equations reaches zero, or where that solution itself is lost (a fold); `inside`
    if the solution jumps between the two."""
    from scipy.optimize import brentq

    last = [guess]

    def least_force(value: float) -> float:
        eq = points.equilibrium(points.model((value,)), last[0], contact=False)
        if eq is None:
            # No solution at all counts as outside: Brent's method then converges on
            # the edge of the solutions, the fold.
            return -1.0
        last[0] = eq
        return float(np.min(eq.normal_force))

    if least_force(outside) > 0.0:
        # The solution jumped between the two values (a pole of the disc's static
        # compliance at a critical speed lies between them): no bracket to refine.
        return inside
    span = abs(outside - inside)
    return float(brentq(least_force, inside, outside, xtol=1e-13 * max(span, abs(inside)),
                        rtol=1e-15))


def eigen_branches(case: Case, key: str, values: Sequence[float], option: str = "key",
                   progress: bool = False) -> xr.Dataset:
    """Eigenvalues of the linearised slip equations followed along one numeric key.

    Parameters
    ----------
    case : Case
        Base case at constant speed.
    key : str
        Dotted case key to vary, e.g. ``"friction.kinetic_max"``.
    values : sequence of float
        Its values, in the order to follow (at least 2; close enough that an eigenvalue
        moves less than its distance to the others between neighbours).
    option : str
        What names `key` in error messages (``"--x"`` from the command line).
    progress : bool
        Show a progress bar.

    Returns
    -------
    xarray.Dataset
        Dimension named after the key (with its units), ``branch`` (one per eigenvalue,
        ``2 (n + S)``) and ``slider``. Variables: ``growth_rate`` and ``frequency`` (key,
        branch) [1/s], [Hz]: the real part and the imaginary part / 2 pi (signed: each
        complex pair has a positive and a negative branch); ``mode`` (branch): its
        mode's label (:func:`~fivdisc.analysis.stability.mode_labels`, one per mode,
        the two branches of a pair sharing it) at the value nearest the case's own
        value of the key (``mode.labelled_at``), carried along the branch;
        ``max_growth_rate`` (key); ``normal_force``, ``phi``, ``w`` (key, slider): the
        equilibrium's normal forces, slider angles and disc deflections under the
        sliders (NaN where there is none); ``existence_limit`` (limit): the values
        of the key where a slider's normal force reaches zero and the equilibrium ceases
        to exist; ``coupling`` (coupling) with ``coupling_first``, ``coupling_second``:
        the values (at the grid's resolution) where two branches' frequencies meet
        (:func:`mode_couplings`) while their growth rates part, and the branches.
        Attributes ``x_key`` and the base case's TOML (``case``).

    Raises
    ------
    CaseError
        A key that is not a number of this case, fewer than two values, an empty range,
        values outside the key's allowed range, or no sliding equilibrium at the first
        value.

    See Also
    --------
    fivdisc.hopf_points : Where a complex pair of the branches crosses the imaginary
        axis, located.
    fivdisc.linear_stability : The eigenvalues at one value.
    fivdisc.plots.plot_eigen_branches : Draws them.

    Examples
    --------
    A slider on a rigid disc (no modes) has one complex pair, its own mode at
    ``sqrt(k_phi / I) / 2 pi`` = 225 Hz; as the disc speeds up the friction law flattens
    and the pair's growth rate falls through zero:

    >>> import numpy as np
    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5})
    >>> branches = fivdisc.eigen_branches(rigid, "speed.value", np.linspace(1.0, 19.0, 7))
    >>> branches["growth_rate"].dims, branches["mode"].values.tolist()
    (('speed.value', 'branch'), ['phi', 'phi'])
    >>> print(branches["max_growth_rate"].values.round(2))  # [1/s]
    [ 315.52  168.95   60.37  -20.08  -79.67 -123.81 -156.52]
    >>> print(branches["frequency"].values[:, 0].round(1))  # [Hz]
    [219.4 223.5 224.9 225.1 224.7 224.2 223.7]
    """
    values = check_values(option, key, values)
    check_memory(branch_bytes(case) * values.size, f"{option} with {values.size} values",
                 "use fewer values")
    check_keys(case, [key], [option])
    check_box(case, [(key, values)], [option])
    points = ParameterPoints(case, [key])
    points.require_equilibrium((values[0],), option)
    warn_if_long(points, (values[0],), values.size, f"eigenvalue branches along {key}",
                 f"fewer values of {option}")
    size, ns = points.size, points.base.n_sliders
    lam = np.full((values.size, size), np.nan + 1j * np.nan)
    force = np.full((values.size, ns), np.nan)
    angle = np.full((values.size, ns), np.nan)
    under = np.full((values.size, ns), np.nan)
    own = float(case.get(key))
    labelled = None  # (row, model, Jacobian) nearest the case's own value so far
    limits: list[float] = []
    guess = None
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=values.size, desc="eigenvalue branches", unit="pt")
    for i, value in enumerate(values):
        point = points.linearise((value,), guess)
        if bar is not None:
            bar.update()
        if point is None:
            if guess is not None:
                limits.append(_existence_limit(points, values[i - 1], value, guess))
            guess = None
            continue
        model, eq, jac = point
        if guess is None and i > 0:
            # The equilibrium reappears: the limit lies between the last two values.
            limits.append(_existence_limit(points, value, values[i - 1], eq))
        guess = eq
        lam[i] = np.linalg.eigvals(jac)
        if labelled is None or abs(value - own) < abs(values[labelled[0]] - own):
            labelled = (i, model, jac)
        force[i], angle[i] = eq.normal_force, eq.phi
        under[i] = slip_evaluation(model, eq.state)[1]["w"]
    if bar is not None:
        bar.close()
    lam = follow(lam)
    # The branches are named where the scan comes nearest the case's own value of the
    # key (the first of two as near): a scan names its modes as ``fivdisc stability
    # CASE`` does wherever its range holds that value, whatever else it spans.
    row, model, jac = labelled
    modes = _branch_labels(model, jac, lam[row])
    ds = _dataset(case, key, values, lam, modes, force, angle, under, limits)
    ds["mode"].attrs["labelled_at"] = float(values[row])
    return ds


def _branch_labels(model: Model, jac: np.ndarray, row: np.ndarray) -> tuple[str, ...]:
    """The labels (:func:`~fivdisc.analysis.stability.mode_labels`) of the eigenvalues
    of `jac`, in the order of the followed `row` (the same eigenvalues, reordered)."""
    from scipy.optimize import linear_sum_assignment

    lam, vec = np.linalg.eig(jac)
    labels = mode_labels(model, lam, vec)
    # The same Jacobian solved again: each followed eigenvalue is one of these to
    # round-off; the assignment keeps a double eigenvalue's two apart.
    _, order = linear_sum_assignment(np.abs(row[:, None] - lam[None, :]))
    return tuple(labels[j] for j in order)


def branch_bytes(case: Case) -> float:
    """Memory of :func:`eigen_branches` per value of the key [bytes]: the eigenvalues
    (complex), their copy followed into branches, the dataset's growth rates and
    frequencies, the equilibrium's forces, angles and deflections, and the netCDF
    writer's copies."""
    size = 2 * (sum(1 if l == 0 else 2 for _, l in case.disc.modes) + len(case.sliders))
    return 2.0 * (16 * 2 * size + 16 * size + 24 * len(case.sliders) + 8)


def _last_valid(lam: np.ndarray, i: int) -> int:
    rows = np.flatnonzero(np.isfinite(lam[:i, 0]))
    return int(rows[-1])


def mode_couplings(lam: np.ndarray, tolerance: float = COUPLING_TOLERANCE
                   ) -> list[tuple[int, int, int]]:
    """Where pairs of branches couple: ``(index, first, second)`` at each edge of an
    interval of values where the two positive frequencies meet, and the growth rates are
    further apart than just outside it, where they agree within `tolerance` of the
    frequency (the eigenvalues meet; modes already apart in growth rate that cross in
    frequency do not couple); `index` is the edge's value inside the interval (where the
    modes merge, and where they part again).

    Two frequencies meet where they agree within `tolerance` (relative) and lie closer
    together than the growth rates: the pair of eigenvalues has turned from lying side
    by side in frequency to lying side by side in growth rate, as coupled modes do (in
    an undamped flutter the frequencies are then equal; damping leaves them apart by
    less than the growth rates). The growth rates must also have parted by at least
    their mean distance from zero, what it takes for the coupling to drive one of them
    through zero. Two modes that only approach, 1 % apart in frequency and further apart
    than their growth rates, do not couple; nor do the near-equal modes of identical
    pads, whose growth rates shuffle by a few per cent of their size.

    Parameters
    ----------
    lam : ndarray
        ``(values, branches)`` complex eigenvalues, followed by continuity.
    """
    found = []
    upper = [b for b in range(lam.shape[1]) if np.nanmedian(lam[:, b].imag) > 0.0]
    for ia, a in enumerate(upper):
        for b in upper[ia + 1:]:
            wa, wb = lam[:, a].imag, lam[:, b].imag
            split = np.abs(lam[:, a].real - lam[:, b].real)
            gap = np.abs(wa - wb)
            merged = (gap <= tolerance * np.maximum(np.abs(wa), np.abs(wb))) & (gap <= split)
            mean = 0.5 * np.abs(lam[:, a].real + lam[:, b].real)
            for i in range(1, lam.shape[0]):
                if merged[i] == merged[i - 1] or not np.isfinite(wa[i - 1] + wb[i]):
                    continue
                inside, outside = (i, i - 1) if merged[i] else (i - 1, i)
                # The growth rates part on the merged side (a coupling, not a veering),
                # by at least their mean distance from zero, and just outside it they
                # agree as closely as the frequencies do: the eigenvalues meet. Modes
                # whose growth rates are already apart only cross in frequency.
                near = tolerance * max(abs(wa[outside]), abs(wb[outside]))
                if (split[outside] <= near and split[inside] > split[outside]
                        and split[inside] >= mean[inside]):
                    found.append((inside, a, b))
    # An interval of one value is entered and left there: one coupling.
    return sorted(set(found))


def _dataset(case: Case, key: str, values: np.ndarray, lam: np.ndarray,
             modes: tuple[str, ...], force: np.ndarray, angle: np.ndarray,
             under: np.ndarray, limits: list[float]) -> xr.Dataset:
    from fivdisc.engine.conventions import global_attrs, key_attrs

    couplings = mode_couplings(lam)
    growth = lam.real
    return xr.Dataset(
        {
            "growth_rate": ((key, "branch"), growth, {
                "units": "1/s", "long_name": "real part of the eigenvalue"}),
            "frequency": ((key, "branch"), lam.imag / (2.0 * np.pi), {
                "units": "Hz", "long_name": "imaginary part of the eigenvalue / 2 pi"}),
            "mode": (("branch",), np.array(modes, dtype=str), {
                "long_name": "coordinate with most of the kinetic energy where the branch "
                             "starts"}),
            "max_growth_rate": ((key,), np.max(growth, axis=1), {
                "units": "1/s", "long_name": "largest real part of the eigenvalues (nan: no "
                                             "sliding equilibrium)"}),
            "normal_force": ((key, "slider"), force, {
                "units": "N", "long_name": "normal force at the sliding equilibrium"}),
            "phi": ((key, "slider"), angle, {
                "units": "rad", "long_name": "slider angle at the sliding equilibrium"}),
            "w": ((key, "slider"), under, {
                "units": "m", "long_name": "disc deflection under the slider at the sliding "
                                           "equilibrium"}),
            "existence_limit": (("limit",), np.array(limits, dtype=float), {
                "units": key_attrs(key)["units"],
                "long_name": "where a slider's normal force at the equilibrium reaches "
                             "zero"}),
            "coupling": (("coupling",), np.array([values[i] for i, _, _ in couplings]), {
                "units": key_attrs(key)["units"],
                "long_name": "where two frequencies merge and their growth rates part "
                             "(at the resolution of the values)"}),
            "coupling_first": (("coupling",), np.array([a for _, a, _ in couplings],
                                                      dtype=np.int64)),
            "coupling_second": (("coupling",), np.array([b for _, _, b in couplings],
                                                       dtype=np.int64)),
        },
        coords={key: (key, values, key_attrs(key)), "branch": np.arange(lam.shape[1]),
                "slider": np.arange(force.shape[1])},
        attrs={**global_attrs(f"fivdisc eigenvalue branches along {key}",
                              "fivdisc.eigen_branches"),
               "fivdisc_kind": "eigen_branches", "x_key": key, "case": case.to_toml()},
    )
