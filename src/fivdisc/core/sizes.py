"""Sizes of a model's state and the row offsets of the kernels' work array."""

from numba import njit

from fivdisc.model.layout import N_AUX


@njit(cache=True)
def work_rows(n_sliders):
    """Row offsets of the work array: g' (rows ``gp + j``; g is rows ``j``), the disc
    forces, cos(l psi_j) (rows ``trig + j``; sin at ``trig + S + j``), the auxiliary
    block (rows ``aux + A_*``, column j), the normal forces' system (rows
    ``system + a``, its right-hand side in column S) and, with several sliders, each
    contact's force on the disc per unit normal force, times M^-1 (row ``contact + i``
    for modal coordinate i, column j; n rows).
    """
    gp = n_sliders
    fq = 2 * n_sliders
    trig = fq + 1
    aux = trig + 2 * n_sliders
    system = aux + N_AUX
    contact = system + n_sliders
    return gp, fq, trig, aux, system, contact


@njit(cache=True)
def sizes(mdl):
    """``(n, S, half)``: modal coordinates, sliders, and the offset of the velocities."""
    n = mdl.disc.shape[1]
    s = mdl.slider.shape[1]
    return n, s, n + 2 * s


@njit(cache=True)
def n_dynamic(mdl):
    """Length of the state without the energy accumulators, ``2 (n + 2 S)``."""
    return 2 * (mdl.disc.shape[1] + 2 * mdl.slider.shape[1])
