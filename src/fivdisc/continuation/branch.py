"""A branch of periodic orbits from :func:`~fivdisc.continuation.walk.continue_orbit`:
its points, their measures and multipliers, its bifurcations; netCDF in and out."""

from __future__ import annotations

import json
import math
from os import PathLike
from typing import TYPE_CHECKING, Any

import numpy as np

from fivdisc.analysis.cycle import MEASURES
from fivdisc.case import Case, describe_key
from fivdisc.errors import FivdiscError

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["Branch", "open_branch"]

CONTENT = "continuation branch"


class Branch:
    """A branch of periodic orbits along one case key.

    Attributes
    ----------
    dataset : xarray.Dataset
        Dimensions ``point`` (along the branch), ``slider``, ``coordinate``,
        ``multiplier`` and ``bifurcation``. Per point: ``parameter`` (a coordinate, the
        key's value), ``period`` [s], ``state`` (the orbit's point), ``signature`` (per
        slider), ``multiplier_real`` / ``_imag``, ``stable``, ``residual``, and the
        amplitude measures ``phi_max``, ``phi_min``, ``phi_dot_max``, ... per slider
        (:data:`fivdisc.analysis.cycle.MEASURES`). Per bifurcation: ``kind``,
        ``bifurcation_parameter``, ``bifurcation_period``, ``bifurcation_state``,
        multipliers ``before`` and ``after`` it, signatures on either side, ``rotation``
        (torus), ``bifurcation_point`` (index of the point before it) and ``note``.
        Attributes: ``key``, ``case`` (TOML), ``stop_reason``, ``start``.

    See Also
    --------
    fivdisc.continue_orbit, fivdisc.hopf_cycles : Make one.
    open_branch : Reads one written by :meth:`to_netcdf`.

    Examples
    --------
    The first orbits born at the Hopf point of a slider on a rigid disc (no modes):

    >>> import numpy as np
    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5})
    >>> (hopf,) = fivdisc.hopf_points(rigid, "speed.value", np.linspace(1.0, 19.0, 7))
    >>> branch = fivdisc.hopf_cycles(hopf, 19.0, max_points=3)
    >>> len(branch), branch.key, branch.signature(0), branch.stop_reason
    (3, 'speed.value', ('slip+',), 'the largest number of points (3) is reached')
    >>> dict(branch.dataset.sizes)
    {'point': 3, 'coordinate': 4, 'slider': 1, 'multiplier': 4, 'bifurcation': 0}
    >>> print(f"first orbit: {branch.parameter[0]:.4f} rad/s, T = {branch.period[0] * 1e3:.4f} ms")
    first orbit: 9.1630 rad/s, T = 4.4429 ms
    """

    def __init__(self, dataset: xr.Dataset) -> None:
        self.dataset = dataset

    # --- reading ------------------------------------------------------------------------

    @property
    def key(self) -> str:
        """The continued case key."""
        return str(self.dataset.attrs["key"])

    @property
    def case(self) -> Case:
        """The case at the branch's first point."""
        return Case.from_toml(self.dataset.attrs["case"])

    @property
    def parameter(self) -> np.ndarray:
        """The key's value at each point."""
        return self.dataset["parameter"].values

    @property
    def period(self) -> np.ndarray:
        """The period at each point [s]."""
        return self.dataset["period"].values

    @property
    def stable(self) -> np.ndarray:
        """Whether each point's orbit is stable."""
        return self.dataset["stable"].values.astype(bool)

    @property
    def multipliers(self) -> np.ndarray:
        """``(point, multiplier)`` Floquet multipliers, largest modulus first."""
        ds = self.dataset
        return ds["multiplier_real"].values + 1j * ds["multiplier_imag"].values

    @property
    def stop_reason(self) -> str:
        """Why the continuation stopped."""
        return str(self.dataset.attrs["stop_reason"])

    @property
    def lost(self) -> bool:
        """Whether the continuation stopped because the orbit was lost."""
        return bool(self.dataset.attrs["lost"])

    def phases(self, point: int) -> np.ndarray:
        """Each slider's phase at a point's state (files of fivdisc 0.x before issue 36
        have one set of phases for every point)."""
        phase = self.dataset["phase"].values
        return (phase[point] if phase.ndim == 2 else phase).astype(np.int64)

    def symmetries(self) -> list[str]:
        """Each point's orbit symmetry in words ("" where the case has none)."""
        if "symmetry" not in self.dataset:
            return [""] * len(self)
        return [str(s) for s in self.dataset["symmetry"].values]

    def signature(self, point: int) -> tuple[str, ...]:
        """The event signature of a point, per slider."""
        return tuple(str(s) for s in self.dataset["signature"].values[point])

    def bifurcations(self) -> list[dict[str, Any]]:
        """The bifurcations, each as a dict (kind, parameter, period, multipliers before
        and after, signatures before and after, rotation, point, note, state)."""
        ds = self.dataset
        out = []
        for i in range(ds.sizes["bifurcation"]):
            def mult(name: str, i: int = i) -> np.ndarray:
                return (ds[f"{name}_real"].values[i] + 1j * ds[f"{name}_imag"].values[i])

            out.append({
                "kind": str(ds["kind"].values[i]),
                "parameter": float(ds["bifurcation_parameter"].values[i]),
                "period": float(ds["bifurcation_period"].values[i]),
                "before": mult("before"),
                "after": mult("after"),
                "signature_before": tuple(str(s) for s in
                                          ds["signature_before"].values[i]),
                "signature_after": tuple(str(s) for s in ds["signature_after"].values[i]),
                "rotation": float(ds["rotation"].values[i]),
                "point": int(ds["bifurcation_point"].values[i]),
                "note": str(ds["note"].values[i]),
                "state": ds["bifurcation_state"].values[i].copy(),
                "period_after": (float(ds["bifurcation_period_after"].values[i])
                                 if "bifurcation_period_after" in ds else math.nan),
                "phases": (ds["bifurcation_phase"].values[i].astype(np.int64)
                           if "bifurcation_phase" in ds else self.phases(
                               int(ds["bifurcation_point"].values[i]))),
            })
        return out

    def hopf(self) -> dict[str, Any] | None:
        """For a branch from :func:`~fivdisc.continuation.from_hopf.hopf_cycles`: the Hopf
        point's ``value``, ``omega`` [rad/s], ``direction``, ``criticality``
        (``"subcritical"`` or ``"supercritical"``), the ``bistable`` range (low, high;
        nan if none) and whether its end away from the Hopf point is only a bound
        (``bistable_open``: the stick-slip orbits beyond a grazing are not followed),
        and whether a subcritical branch stopped before deciding it
        (``bistable_undetermined``: no fold or grazing reached); the point's first
        Lyapunov coefficient ``l1`` [s^2] and ``l1_error`` (nan in files written before
        they were stored); the Hopf point's ``mode`` (its branch's label), whether the
        equilibrium changes stability there (``on_boundary``; else ``unstable_modes``
        stay unstable, and every orbit born there is unstable), and whether this branch
        ``continued`` one from the point
        (:func:`~fivdisc.continuation.from_hopf.restate_hopf`); else None."""
        attrs = self.dataset.attrs
        if "criticality" not in attrs:
            return None
        unstable = str(attrs.get("hopf_unstable_modes", ""))
        return {"value": float(attrs["hopf_value"]), "omega": float(attrs["hopf_omega"]),
                "direction": int(attrs["hopf_direction"]),
                "criticality": str(attrs["criticality"]),
                "l1": float(attrs.get("hopf_l1", math.nan)),
                "l1_error": float(attrs.get("hopf_l1_error", math.nan)),
                "bistable": (float(attrs["bistable_low"]), float(attrs["bistable_high"])),
                "bistable_open": bool(attrs.get("bistable_open", 0)),
                "bistable_undetermined": bool(attrs.get("bistable_undetermined", 0)),
                "on_boundary": bool(attrs.get("hopf_on_boundary", 1)),
                "mode": str(attrs.get("hopf_mode", "")),
                "unstable_modes": tuple(unstable.split(", ")) if unstable else (),
                "continued": bool(attrs.get("hopf_continued", 0))}

    # --- writing ------------------------------------------------------------------------

    @classmethod
    def from_walk(cls, problem, walk, start: str) -> Branch:
        """Build from the continuation's internals (:mod:`fivdisc.continuation.walk`)."""
        import xarray as xr

        from fivdisc.analysis.orbits import state_labels

        pts = walk.points
        model = problem.base
        ns = model.n_sliders
        params = np.array([p.value for p in pts])
        info = describe_key(problem.key)
        mults = np.array([p.multipliers for p in pts])
        nd = model.state_size
        data: dict[str, Any] = {
            "period": ("point", np.array([p.period for p in pts]),
                       {"long_name": "period", "units": "s"}),
            "state": (("point", "coordinate"), np.array([p.x for p in pts]),
                      {"long_name": "point on the orbit (state layout)"}),
            "signature": (("point", "slider"),
                          np.array([list(p.cycle.signature) for p in pts], dtype=str),
                          {"long_name": "event signature over one period"}),
            "multiplier_real": (("point", "multiplier"), mults.real,
                                {"long_name": "Floquet multiplier, real part", "units": "1"}),
            "multiplier_imag": (("point", "multiplier"), mults.imag,
                                {"long_name": "Floquet multiplier, imaginary part",
                                 "units": "1"}),
            "trivial_multiplier": ("point", np.array([p.trivial for p in pts]),
                                   {"long_name": "index of the flow direction's multiplier"}),
            "stable": ("point", np.array([p.verdict == "stable" for p in pts], dtype=np.int8),
                       {"long_name": "orbit is stable (1) or unstable (0)"}),
            "residual": ("point", np.array([p.residual for p in pts]),
                         {"long_name": "scaled shooting residual", "units": "1"}),
            "phase": (("point", "slider"), np.array([p.phases for p in pts], dtype=np.int64),
                      {"long_name": "phase at the point (0 slip, 1 stick, 2 separation)"}),
            "symmetry": ("point", np.array([p.symmetry for p in pts], dtype=str),
                         {"long_name": "the orbit's symmetry (\"\" where the case has none)"}),
            "near_border": ("point", np.array([p.near_border for p in pts], dtype=np.int8),
                            {"long_name": "d phi_T / dp taken one-sided: the held flow map "
                             "jumps within 1e-6 of the key"}),
        }
        reduced = [p.reduced for p in pts]
        if any(r is not None for r in reduced):
            width = max(r.size for r in reduced if r is not None)
            table_r = np.full((len(pts), width), np.nan + 0j)
            for i, r in enumerate(reduced):
                if r is not None:
                    table_r[i, : r.size] = r[np.argsort(-np.abs(r), kind="stable")]
            for part in ("real", "imag"):
                data[f"reduced_multiplier_{part}"] = (
                    ("point", "reduced"), getattr(table_r, part),
                    {"long_name": "eigenvalue of the reduced map P^-1 d phi_{T/k} of an orbit "
                     f"with a spatio-temporal symmetry (nan: none), {part} part",
                     "units": "1"})
        for name, (long_name, unit) in MEASURES.items():
            for end, word in (("max", "largest"), ("min", "smallest")):
                data[f"{name}_{end}"] = (
                    ("point", "slider"), np.array([p.cycle.measures[f"{name}_{end}"]
                                                   for p in pts]),
                    {"long_name": f"{word} {long_name} over a period", "units": unit})
        bif = walk.bifurcations
        nm = mults.shape[1]

        def table(values, shape):
            return np.array(values) if values else np.zeros(shape)

        data.update({
            "kind": ("bifurcation", np.array([b.kind for b in bif], dtype=str),
                     {"long_name": "kind of bifurcation"}),
            "bifurcation_parameter": ("bifurcation", table([b.parameter for b in bif], 0),
                                      {"long_name": f"{info.long_name} at the bifurcation",
                                       "units": info.unit}),
            "bifurcation_period": ("bifurcation", table([b.period for b in bif], 0),
                                   {"long_name": "period at the bifurcation", "units": "s"}),
            "bifurcation_state": (("bifurcation", "coordinate"),
                                  table([b.state for b in bif], (0, nd)),
                                  {"long_name": "point on the orbit at the bifurcation"}),
            "bifurcation_point": ("bifurcation",
                                  np.array([b.point for b in bif], dtype=np.int64),
                                  {"long_name": "index of the branch point before it"}),
            "rotation": ("bifurcation", table([b.rotation for b in bif], 0),
                         {"long_name": "rotation number of a torus bifurcation",
                          "units": "1"}),
            "note": ("bifurcation", np.array([b.note for b in bif], dtype=str),
                     {"long_name": "what happens there"}),
            "bifurcation_period_after": ("bifurcation",
                                         table([b.period_after for b in bif], 0),
                                         {"long_name": "period on the other side of a jump",
                                          "units": "s"}),
            "bifurcation_phase": (("bifurcation", "slider"),
                                  np.array([b.phases if b.phases is not None
                                            else np.zeros(ns, dtype=np.int64) for b in bif],
                                           dtype=np.int64).reshape(-1, ns),
                                  {"long_name": "phase at the bifurcation's state"}),
            "signature_before": (("bifurcation", "slider"),
                                 np.array([list(b.signature_before) for b in bif],
                                          dtype=str).reshape(-1, ns),
                                 {"long_name": "event signature before"}),
            "signature_after": (("bifurcation", "slider"),
                                np.array([list(b.signature_after) for b in bif],
                                         dtype=str).reshape(-1, ns),
                                {"long_name": "event signature after"}),
        })
        for side in ("before", "after"):
            values = table([getattr(b, side) for b in bif], (0, nm))
            for part in ("real", "imag"):
                data[f"{side}_{part}"] = (
                    ("bifurcation", "multiplier"), getattr(values, part),
                    {"long_name": f"Floquet multipliers {side} the bifurcation, {part} part",
                     "units": "1"})
        ds = xr.Dataset(
            data,
            coords={
                "parameter": ("point", params, {"long_name": info.long_name, "units": info.unit,
                                                "key": problem.key}),
                "point": np.arange(len(pts)),
                "slider": np.arange(ns),
                "coordinate": np.arange(nd),
                "label": ("coordinate", list(state_labels(model))),
                "multiplier": np.arange(nm),
                "bifurcation": np.arange(len(bif)),
            },
            attrs={"content": CONTENT, "key": problem.key, "case": problem.case.to_toml(),
                   "stop_reason": walk.stop.reason, "lost": int(walk.stop.lost),
                   "start": start, "rtol": problem.rtol, "tol": problem.tol,
                   "symmetry_group": problem.group.description if problem.group else "none",
                   "end_check": " | ".join(walk.checks)},
        )
        return cls(ds)

    def to_netcdf(self, path: str | PathLike[str]) -> None:
        """Write the branch to netCDF, with a checksum of its data (written under a
        temporary name, then renamed)."""
        from fivdisc.files import write_netcdf

        write_netcdf(path, self.dataset.to_netcdf)

    # --- showing ------------------------------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        """Points and bifurcations as plain JSON types."""
        def cplx(values: np.ndarray) -> list[dict[str, float]]:
            return [{"real": float(m.real), "imag": float(m.imag), "modulus": float(abs(m))}
                    for m in values]

        syms = self.symmetries()
        points = [{"parameter": float(p), "period": float(t), "stable": bool(s),
                   "signature": list(self.signature(i)), "multipliers": cplx(m),
                   "symmetry": syms[i]}
                  for i, (p, t, s, m) in enumerate(zip(self.parameter, self.period, self.stable,
                                                       self.multipliers, strict=True))]
        bifs = []
        for b in self.bifurcations():
            entry = {k: v for k, v in b.items() if k not in ("state", "before", "after",
                                                             "phases")}
            entry["rotation"] = None if math.isnan(b["rotation"]) else b["rotation"]
            entry["period_after"] = (None if math.isnan(b["period_after"])
                                     else b["period_after"])
            entry["before"], entry["after"] = cplx(b["before"]), cplx(b["after"])
            entry["signature_before"] = list(b["signature_before"])
            entry["signature_after"] = list(b["signature_after"])
            bifs.append(entry)
        return {"key": self.key, "points": points, "bifurcations": bifs,
                "stop_reason": self.stop_reason, "lost": self.lost,
                "symmetry_group": str(self.dataset.attrs.get("symmetry_group", "none")),
                "end_check": str(self.dataset.attrs.get("end_check", "")),
                "start": str(self.dataset.attrs.get("start", "")),
                **({"hopf": {**hopf, "bistable": [None if math.isnan(b) else b
                                                  for b in hopf["bistable"]]}}
                   if (hopf := self.hopf()) else {})}

    def to_json(self) -> str:
        """:meth:`to_dict` as indented JSON (what ``fivdisc continue --json`` prints)."""
        return json.dumps(self.to_dict(), indent=2)

    def __len__(self) -> int:
        return int(self.dataset.sizes["point"])

    def __str__(self) -> str:
        unit = self.dataset["parameter"].attrs.get("units", "")
        unit = f" {unit}" if unit else ""
        p, t = self.parameter, self.period
        # A branch that turned at a fold reaches past its ends.
        span = ("" if p.min() == min(p[0], p[-1]) and p.max() == max(p[0], p[-1])
                else f" (over {p.min():.9g} to {p.max():.9g}{unit})")
        lines = [f"branch of periodic orbits in {self.key}: {len(self)} points from "
                 f"{p[0]:.9g} to {p[-1]:.9g}{unit}{span}, period {t[0]:.9g} to {t[-1]:.9g} "
                 f"s; {int(self.stable.sum())} stable",
                 f"stopped: {self.stop_reason}"]
        hopf = self.hopf()
        if hopf:
            where = "continues the branch from" if hopf["continued"] else "from"
            mode = f" ({hopf['mode']})" if hopf["mode"] else ""
            lines.append(f"{where} the Hopf point at {self.key} = {hopf['value']:.9g}{unit}"
                         f"{mode}: {hopf['criticality']}{_l1_note(hopf)}")
            low, high = hopf["bistable"]
            if not hopf["on_boundary"]:
                others = ", ".join(hopf["unstable_modes"]) or "another mode"
                reach = (f"none: {others} of the sliding equilibrium stay unstable at the "
                         "Hopf point, so the orbits born there are unstable and sliding is "
                         "stable on neither side")
            elif math.isnan(low) and hopf["bistable_undetermined"]:
                # the branch's farthest orbit from the Hopf point, wherever it walked
                farthest = p[np.argmax(np.abs(p - hopf["value"]))]
                reach = (f"not determined up to {self.key} = {farthest:.9g}{unit}: the "
                         "slipping orbits there are unstable and have neither folded nor "
                         "grazed; they bound the basin of stable sliding, and the motion "
                         "beyond them may be a stable vibration (continue further, or "
                         "continue a stick-slip orbit with --from)")
            elif math.isnan(low):
                reach = "none found"
            elif hopf["bistable_open"]:
                near_hopf = high if high == hopf["value"] else low
                far = low if high == hopf["value"] else high
                reach = (f"from {near_hopf:.9g}{unit} to {far:.9g}{unit} at least (where the "
                         "slipping orbits graze; the stick-slip orbits beyond are not "
                         "followed: continue one to find where the range ends)")
            else:
                reach = f"{low:.9g} to {high:.9g}{unit}"
            lines.append("bistable range (stable sliding and a stable vibration): " + reach)
        group = str(self.dataset.attrs.get("symmetry_group", "none"))
        if group != "none":
            syms = self.symmetries()
            runs = []
            for i, sym in enumerate(syms):
                if runs and runs[-1][0] == sym:
                    runs[-1][2] = i
                else:
                    runs.append([sym, i, i])
            lines.append(f"symmetry of the case: {group}; of the orbits: " + "; ".join(
                f"{sym or 'none'} (points {a}-{b})" if a != b else f"{sym or 'none'} (point {a})"
                for sym, a, b in runs))
        bifs = self.bifurcations()
        lines.append(f"bifurcations: {len(bifs) or 'none'}")
        for b in bifs:
            after = (f" -> {b['period_after']:.9g} s" if not math.isnan(b["period_after"])
                     else "")
            lines.append(f"  {b['kind']} at {self.key} = {b['parameter']:.9g}{unit}, "
                         f"T = {b['period']:.9g} s{after}: {b['note']}")
        check = str(self.dataset.attrs.get("end_check", ""))
        if check:
            lines.append(f"end confirmed by: {check}")
        return "\n".join(lines)


def _l1_note(hopf: dict[str, Any]) -> str:
    """The first Lyapunov coefficient beside the orbits' verdict, and whether it agrees."""
    l1, error = hopf["l1"], hopf["l1_error"]
    if not math.isfinite(l1):
        return ""
    text = f" (first Lyapunov coefficient l1 = {l1:.4g} s^2"
    if abs(l1) <= error:
        return text + ", zero within its error: a Bautin point, where the orbits decide)"
    if (l1 > 0.0) == (hopf["criticality"] == "subcritical"):
        return text + ", agrees)"
    return (text + ", says " + ("subcritical" if l1 > 0.0 else "supercritical")
            + ": the first orbit is too large for the normal form to hold, take a "
            "smaller --amplitude)")


def open_branch(path: str | PathLike[str]) -> Branch:
    """Read a branch written by :meth:`Branch.to_netcdf` (``fivdisc continue -o``).

    Raises
    ------
    FivdiscError
        The file is not a branch.

    See Also
    --------
    fivdisc.continue_orbit, fivdisc.hopf_cycles : Compute a branch instead.

    Examples
    --------
    >>> import numpy as np
    >>> import fivdisc
    >>> rigid = fivdisc.Case(disc={"modes": []}, slider={"rotational_damping": 0.5})
    >>> (hopf,) = fivdisc.hopf_points(rigid, "speed.value", np.linspace(1.0, 19.0, 7))
    >>> branch = fivdisc.hopf_cycles(hopf, 19.0, max_points=3)
    >>> branch.to_netcdf("branch.nc")
    >>> again = fivdisc.open_branch("branch.nc")
    >>> again.dataset.equals(branch.dataset), str(again) == str(branch)
    (True, True)
    """
    from fivdisc.files import read_dataset

    ds = read_dataset(path, "branch")
    if ds.attrs.get("content") != CONTENT:
        raise FivdiscError(f"{path} is not a continuation branch (fivdisc continue -o)")
    return Branch(ds)
