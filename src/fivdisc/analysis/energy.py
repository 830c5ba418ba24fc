"""Energy accounting of a run: the energy stored in the system against the work of every
force, integrated by the kernel alongside the state (``simulation.energy_balance``)."""

from __future__ import annotations

import numpy as np
import xarray as xr

from fivdisc.analysis.spectra import AnalysisError, as_dataset

__all__ = ["energy_balance", "stored_energy"]


def stored_energy(ds: xr.Dataset, model) -> np.ndarray:
    """Energy stored in the disc and the sliders at each sample [J].

    Parameters
    ----------
    ds : xarray.Dataset
        A simulation dataset.
    model : fivdisc.model.build.Model
        The run's model (modal masses, frequencies, sliders).

    Notes
    -----
    With the disc's modal coordinates q (modal masses M, frequencies omega, nodal
    diameters l) and the disc speed Omega,

    .. math::

        E = \\sum_i \\tfrac12 M_i \\dot q_i^2 + \\tfrac12 M_i (\\omega_i^2 - l_i^2 \\Omega^2)
        q_i^2 + \\sum_j \\tfrac12 I_j \\dot\\phi_j^2 + \\tfrac12 r_j^2 k_{\\phi j} \\phi_j^2
        + \\tfrac12 m_j \\dot z_j^2 + \\tfrac12 k_{zj} z_j^2 + \\sigma_j N_{0j} z_j,

    the Jacobi integral of the spinning disc plus the sliders' energies (the preload's
    potential included). Its rate is the sum of the powers that
    :func:`energy_balance` integrates.
    """
    kern = model.kernel
    omega = ds["disc_speed"].values[:, None]
    q = ds["q"].values
    disc = 0.5 * np.sum(
        model.modal_mass * ds["q_dot"].values ** 2
        + model.modal_mass * (model.omega**2 - model.l**2 * omega**2) * q**2,
        axis=1,
    )
    z = ds["z"].values
    sliders = np.sum(
        0.5 * kern.row("inertia") * ds["phi_dot"].values ** 2
        + 0.5 * kern.row("kphi") * ds["phi"].values ** 2
        + 0.5 * kern.row("mass") * ds["z_dot"].values ** 2
        + 0.5 * kern.row("kz") * z**2
        + kern.row("sigma") * kern.row("n0") * z,
        axis=1,
    )
    return disc + sliders


def energy_balance(data: xr.Dataset | object) -> xr.Dataset:
    """Change of the stored energy against the work of every force since t = 0.

    Parameters
    ----------
    data : Result or xarray.Dataset
        A run made with ``simulation.energy_balance = true``.

    Returns
    -------
    xarray.Dataset
        ``energy`` [J], the stored energy (:func:`stored_energy`); ``work`` [J] on
        ``(time, energy_term)``: the work done since t = 0 by friction at the contacts
        (its dissipation), the drive that keeps the disc at Omega(t), the friction's
        bending moment, the normal forces on the sloped disc surface, the sliders' and the
        disc's dampers, the kinetic energy lost in impacts and the work of the moving
        surface during impacts; ``residual`` [J] = energy - energy(0) - sum of work.
        Attribute ``relative_residual`` is max |residual| over the largest of
        |energy - energy(0)| and the work terms: small (integration error) when the
        energy is accounted for.

    Raises
    ------
    AnalysisError
        If the run did not record the work (``simulation.energy_balance`` false).

    Notes
    -----
    The powers are, per slider j with friction f_j, normal force N_j, face sigma_j and
    ``g'_j = dg/dphi`` at its place:

    - friction: ``f_j r_j (phidot_j - Omega)`` (negative while slipping, 0 in stick);
    - drive: ``f_j r_j Omega`` plus, on the disc, the gyroscopic and dOmega/dt terms and
      ``-sum M l^2 Omega Omegadot q^2``;
    - friction moment: ``sigma_j (h / 2 r_j) f_j g'_j . qdot``;
    - normal slope: ``sigma_j N_j phidot_j g'_j . q``;
    - slider damping: ``-c_zj zdot_j^2 - r_j^2 c_phij phidot_j^2``;
    - disc damping: ``-qdot . D`` with D the modal damping forces;
    - at an impact the kinetic energy changes by ``lambda . b - 1/2 |du|_W^2``: the
      loss ``1/2 |du|_W^2`` and the surface's work ``lambda . b``.

    Examples
    --------
    Over the first 10 ms of the paper's Table 1 case the drive puts in 0.8 J, friction
    and the slider's dampers take most of it out, and the stored energy accounts for
    the rest to the integration's error [J]:

    >>> import fivdisc
    >>> case = fivdisc.Case(simulation={"duration": 0.01, "energy_balance": True})
    >>> balance = fivdisc.energy_balance(fivdisc.simulate(case))
    >>> work = balance["work"].isel(time=-1)
    >>> for term in ("drive", "friction", "slider_damping"):
    ...     print(f"{term}: {float(work.sel(energy_term=term)):.3f}")
    drive: 0.803
    friction: -0.559
    slider_damping: -0.091
    >>> print(f"stored: {float(balance['energy'][-1]):.3f}")
    stored: 0.154
    >>> balance.attrs["relative_residual"] < 1e-6
    True
    """
    from fivdisc.case import Case
    from fivdisc.model.build import build_model

    ds = as_dataset(data)
    if "energy_work" not in ds:
        raise AnalysisError(
            "the run did not record the work of its forces: run it with "
            "[simulation] energy_balance = true"
        )
    model = build_model(Case.from_toml(ds.attrs["case"]))
    energy = stored_energy(ds, model)
    work = ds["energy_work"].values
    residual = energy - energy[0] - np.sum(work, axis=1)
    scale = max(float(np.max(np.abs(energy - energy[0]))), float(np.max(np.abs(work))))
    relative = float(np.max(np.abs(residual)) / scale) if scale > 0 else 0.0
    return xr.Dataset(
        {
            "energy": ("time", energy, {"units": "J", "long_name": "stored energy"}),
            "work": ds["energy_work"],
            "residual": ("time", residual,
                         {"units": "J", "long_name": "energy change not accounted for"}),
        },
        coords={"time": ds["time"]},
        attrs={"relative_residual": relative},
    )
