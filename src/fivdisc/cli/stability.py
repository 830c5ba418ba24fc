"""``fivdisc stability``: linear stability of the sliding equilibrium and stability maps."""

from __future__ import annotations

from pathlib import Path

import click

from fivdisc.cli._case import CASE
from fivdisc.errors import FivdiscError


@click.command()
@click.argument("case_file", required=False, type=CASE)
@click.option("--x", "x_spec", metavar="KEY=START:STOP:N",
              help="Horizontal axis, e.g. normal_damping=0:12:200. Alone: the eigenvalue "
              "branches, mode couplings and Hopf points along it; with --y: a map.")
@click.option("--y", "y_spec", metavar="KEY=START:STOP:N", help="Vertical axis.")
@click.option("--curves", "curve_spec", metavar="KEY=v1,v2,...",
              help="One map and boundary curve per value, e.g. decay=0,1,10.")
@click.option("--boundary", "boundary_spec", nargs=2, metavar="KEY1=START:STOP KEY2=START:STOP",
              help="Trace the exact stability boundary (Hopf curves) in this box.")
@click.option("--hopf-curves", "hopf_spec", nargs=2, metavar="KEY1=START:STOP KEY2=START:STOP",
              help="Trace every Hopf curve in this box (each eigenvalue pair's zero-growth "
              "curve, with its first Lyapunov coefficient) and locate the codimension-two "
              "points on them: Bautin (sub- and supercritical meet), double Hopf, "
              "zero-Hopf, and where the equilibrium ceases to exist.")
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="map.nc (netCDF dataset) or a figure in any format matplotlib writes "
              "(map.png, map.pdf, map.svg, ...). Default: beside the case file, "
              "CASE-branches.nc, CASE-stability.nc, CASE-boundary.nc or "
              "CASE-hopf-curves.nc.")
@click.option("--json", "as_json", is_flag=True,
              help="Print the equilibrium and the eigenvalues as JSON (without a map).")
@click.option("--growth-scale", type=click.Choice(("auto", "linear", "symlog")),
              default=None, help="With --x and a figure: the growth-rate axis, symmetric "
              "log (linear near zero) or linear [default: auto, symlog where a small "
              "rate would be a flat line beside the largest].")
@click.option("--progress/--no-progress", default=True, show_default=True)
def stability(case_file: Path | None, x_spec: str | None, y_spec: str | None,
              curve_spec: str | None, boundary_spec: tuple[str, str] | None,
              hopf_spec: tuple[str, str] | None, output: Path | None, as_json: bool,
              growth_scale: str | None,
              progress: bool) -> None:
    """Stability of the sliding equilibrium of CASE_FILE (default: Table 1 at 2 pi rad/s).

    CASE_FILE is a TOML case file or the name of a packaged example (``fivdisc examples``).
    Without options: prints the equilibrium and the eigenvalues of the linearised slip
    equations. With --x alone: follows every eigenvalue along one key, with the mode
    couplings, Hopf points and limits of the equilibrium's existence. With --x and --y:
    the largest growth rate over the grid and where it changes sign. With --boundary:
    the exact boundary curves in a box of two keys (a figure draws them on a grid map).
    With --hopf-curves: every Hopf curve in a box of two keys, solid where the Hopf
    point is supercritical and dashed where subcritical (sliding stable, but a large
    enough disturbance starts a vibration), with the Bautin, double Hopf and zero-Hopf
    points and the ends of the equilibrium's existence (a figure draws them on a grid
    map).
    """
    from fivdisc.analysis.stability import linear_stability
    from fivdisc.case import Case, load_case

    case = load_case(case_file) if case_file else Case()
    if growth_scale is not None and not (x_spec is not None and y_spec is None
                                         and output is not None
                                         and output.suffix.lower() != ".nc"):
        raise FivdiscError("--growth-scale is used only by the figure of --x alone (the "
                           "eigenvalue branches): give -o FIGURE.png")
    for name, spec in (("--boundary", boundary_spec), ("--hopf-curves", hopf_spec)):
        if spec and (x_spec or y_spec or curve_spec):
            raise FivdiscError(f"{name} takes its own two keys: leave out --x, --y and "
                               "--curves")
    if boundary_spec and hopf_spec:
        raise FivdiscError("--boundary and --hopf-curves are two scans: give one (the Hopf "
                           "curves hold the boundary: their on_boundary points)")
    if x_spec is None and y_spec is None and not boundary_spec and not hopf_spec:
        if curve_spec is not None:
            raise FivdiscError("--curves is used only by a stability map: give --x and --y "
                               "too (KEY=START:STOP:N)")
        if output is not None:
            raise FivdiscError("-o is used only by a scan: give --x (and --y), --boundary "
                               "or --hopf-curves")
        res = linear_stability(case)
        if as_json:
            import json

            click.echo(json.dumps(res.to_dict(), indent=2))
            return
        click.echo(str(res))
        return
    if as_json:
        raise FivdiscError("--json prints the equilibrium and eigenvalues: leave out --x, --y, "
                           "--boundary and --hopf-curves")
    if y_spec is not None and x_spec is None:
        raise FivdiscError("--y needs --x too (KEY=START:STOP:N)")
    if x_spec is not None and y_spec is None:
        if curve_spec is not None:
            raise FivdiscError("--curves is used only by a map: give --y too")
        _branches(case, case_file, x_spec, output, progress, growth_scale or "auto")
    elif boundary_spec:
        _boundary(case, case_file, boundary_spec, output)
    elif hopf_spec:
        _hopf_curves(case, case_file, hopf_spec, output)
    else:
        _map(case, case_file, x_spec, y_spec, curve_spec, output, progress)


def _target(case_file: Path | None, output: Path | None, default: str) -> tuple[Path, bool]:
    """Checked output path, and whether it is a figure. Without `output`: beside the case
    file, named after it (``CASE-branches.nc``; a packaged example's in the working
    directory), as ``fivdisc simulate`` writes; without a case, `default` here."""
    from fivdisc.cli._case import default_output
    from fivdisc.extras import require
    from fivdisc.files import check_output, figure_suffixes

    if output is None and case_file is not None:
        beside = default_output(case_file, ".nc")
        output = beside.with_name(f"{beside.stem}-{Path(default).stem}.nc")
    target = output or Path(default)
    figure = target.suffix.lower() != ".nc"
    if figure:
        require("plot", f"fivdisc stability -o {target.name} (a figure)")
    out = check_output(target, "-o", (".nc", *figure_suffixes()) if figure else (".nc",),
                       inputs=[case_file])
    return out, figure


def _write(out: Path, figure, ds) -> None:
    from fivdisc.files import write_atomic, write_netcdf

    if figure is None:
        write_netcdf(out, ds.to_netcdf)
    else:
        write_atomic(out, lambda path: figure.savefig(path, dpi=150))
    click.echo(f"wrote {out}")


def _branches(case, case_file, x_spec: str, output: Path | None, progress: bool,
              growth_scale: str = "auto") -> None:

    from fivdisc.analysis.eigenbranches import branch_bytes, eigen_branches
    from fivdisc.analysis.hopf import hopf_points, with_hopf_points
    from fivdisc.analysis.stability import parse_range

    key, values = parse_range(x_spec, "--x", branch_bytes(case))
    out, figure = _target(case_file, output, "branches.nc")
    ds = eigen_branches(case, key, values, option="--x", progress=progress)
    hopf = hopf_points(case, key, values, option="--x", branches=ds)
    ds = with_hopf_points(ds, hopf)
    if case_file is not None:
        ds.attrs["case_name"] = case_file.stem
    if figure:
        from fivdisc.plots.stability import plot_eigen_branches

        _write(out, plot_eigen_branches(ds, hopf, growth_scale=growth_scale), ds)
    else:
        _write(out, None, ds)
    unstable = ds["max_growth_rate"].values > 0.0
    click.echo(f"{ds.sizes['branch']} eigenvalue branches at {values.size} values of {key}; "
               f"unstable at {unstable.mean():.1%} of them")
    for value, a, b in zip(ds["coupling"].values, ds["coupling_first"].values,
                           ds["coupling_second"].values, strict=True):
        click.echo(f"mode coupling near {key} = {value:.6g}: branches {a} "
                   f"({ds['mode'].values[a]}) and {b} ({ds['mode'].values[b]})")
    for value in ds["existence_limit"].values:
        click.echo(f"the sliding equilibrium ceases to exist at {key} = {value:.10g} "
                   "(a normal force reaches zero)")
    for hp in hopf:
        click.echo(str(hp))
    if not hopf:
        click.echo(f"no Hopf point between {key} = {values[0]:g} and {values[-1]:g}")


def _box(specs: tuple[str, str], option: str) -> list[tuple[str, tuple[float, float]]]:
    """The two ``KEY=START:STOP`` of a box, the keys resolved."""
    from fivdisc.analysis.stability import resolve_key

    box = []
    for spec in specs:
        usage = f"{option} {spec!r} is invalid: write KEY=START:STOP"
        if "=" not in spec or spec.split("=", 1)[1].count(":") != 1:
            raise FivdiscError(usage)
        key, ends = spec.split("=", 1)
        try:
            start, stop = (float(v) for v in ends.split(":"))
        except ValueError:
            raise FivdiscError(usage) from None
        box.append((resolve_key(key.strip(), option), (start, stop)))
    return box


def _hopf_curves(case, case_file, specs: tuple[str, str], output: Path | None) -> None:
    import numpy as np

    from fivdisc.analysis.codimension import hopf_curve_lines, hopf_curves
    from fivdisc.analysis.stability import stability_map

    box = _box(specs, "--hopf-curves")
    out, figure = _target(case_file, output, "hopf-curves.nc")
    ds = hopf_curves(case, box[0], box[1])
    if case_file is not None:
        ds.attrs["case_name"] = case_file.stem
    if figure:
        from fivdisc.plots.stability import plot_hopf_curves

        grid = stability_map(case, *[(key, np.linspace(*ends, 40)) for key, ends in box])
        _write(out, plot_hopf_curves(ds, grid=grid), ds)
    else:
        _write(out, None, ds)
    for line in hopf_curve_lines(ds):
        click.echo(line)


def _boundary(case, case_file, specs: tuple[str, str], output: Path | None) -> None:
    import numpy as np

    from fivdisc.analysis.boundary import stability_boundary
    from fivdisc.analysis.stability import stability_map

    box = _box(specs, "--boundary")
    out, figure = _target(case_file, output, "boundary.nc")
    ds = stability_boundary(case, box[0], box[1])
    if case_file is not None:
        ds.attrs["case_name"] = case_file.stem
    if figure:
        from fivdisc.plots.stability import plot_stability_map

        grid = stability_map(case, *[(key, np.linspace(*ends, 40)) for key, ends in box])
        if case_file is not None:
            grid.attrs["case_name"] = case_file.stem
        _write(out, plot_stability_map(grid, boundary=ds), ds)
    else:
        _write(out, None, ds)
    curves = np.unique(ds["branch"].values)
    if curves.size == 0:
        m = int(ds.attrs["seeds"])
        counts = [(int(ds.attrs[f"seeds_{name}"]), words) for name, words in (
            ("stable", "stable"), ("unstable", "unstable"),
            ("without_equilibrium", "without a sliding equilibrium"))]
        found = " and ".join(f"{words} at {n}" if n < m * m else f"{words} at all {n}"
                             for n, words in counts if n)
        spacing = ", ".join(f"{(hi - lo) / (m - 1):.3g} in {key}" for key, (lo, hi) in box)
        click.echo(f"no stability boundary found at this resolution: the sliding equilibrium "
                   f"is {found} of the {m} x {m} points of the seed grid (spacing {spacing}); "
                   "a boundary around a region smaller than that is not seen: trace a "
                   "smaller box to look closer")
    for b in curves:
        sel = ds["branch"].values == b
        freq = ds["frequency"].values[sel]
        modes = ", ".join(dict.fromkeys(ds["mode"].values[sel]))
        shape = "closed" if ds["closed"].values[b] else "open"
        click.echo(f"boundary curve {b} ({shape}, {int(sel.sum())} points): {modes} at "
                   f"{freq.min():.6g}-{freq.max():.6g} Hz")


def _map(case, case_file, x_spec, y_spec, curve_spec, output, progress) -> None:
    import numpy as np

    from fivdisc.analysis.stability import (
        check_map_size,
        parse_range,
        range_size,
        resolve_key,
        stability_map,
    )

    out, figure = _target(case_file, output, "stability.nc")
    specs = {"--x": x_spec, "--y": y_spec, **({"--curves": curve_spec} if curve_spec else {})}
    # The map's size before any axis' values are made.
    sizes = [range_size(spec, option) for option, spec in specs.items()]
    check_map_size(case, sizes)
    if figure and curve_spec:
        from fivdisc.plots.stability import check_curves

        check_curves(sizes[2], resolve_key(curve_spec.split("=", 1)[0].strip(), "--curves"),
                     "--curves")
    axes = {"--x": parse_range(x_spec, "--x"), "--y": parse_range(y_spec, "--y")}
    if curve_spec is not None:
        axes["--curves"] = parse_range(curve_spec, "--curves")
    varied: dict[str, str] = {}  # case key -> option
    for option, (key, _) in axes.items():
        if key in varied:
            raise FivdiscError(f"{option} {key} is invalid: {varied[key]} varies the same key; "
                               "give each axis its own key")
        varied[key] = option
    ds = stability_map(case, axes["--x"], axes["--y"], axes.get("--curves"), progress=progress)
    if not np.isfinite(ds["max_growth_rate"].values).any():
        # A map of NaN would read as "stable at 0 %": nothing is written.
        keys = ", ".join(f"{option} {key}" for option, (key, _) in axes.items())
        raise FivdiscError(f"stability map: no point of the grid ({keys}) has a sliding "
                           "equilibrium, so there is no stability to map; check the case "
                           "(e.g. slider.preload > 0) and the axes' ranges")
    if case_file is not None:
        ds.attrs["case_name"] = case_file.stem
    if figure:
        from fivdisc.plots.stability import plot_stability_map

        _write(out, plot_stability_map(ds), ds)
    else:
        _write(out, None, ds)
    ckey = ds.attrs.get("curve_key", "")
    for value in ds[ckey].values if ckey else [None]:
        one = ds if value is None else ds.sel({ckey: value})
        growth = one["max_growth_rate"].values
        label = "" if value is None else f"{ckey} = {value:g}: "
        known = np.isfinite(growth)
        if not known.any():
            click.echo(f"{label}no sliding equilibrium at any point of the grid (no stability "
                       "to map)")
            continue
        stable = one["stable"].values.astype(bool)[known]
        share = f"stable at {stable.mean():.1%} of the grid"
        if not known.all():
            share = (f"stable at {stable.mean():.1%} of the {known.sum()} grid points with a "
                     f"sliding equilibrium ({growth.size - known.sum()} of {growth.size} "
                     "have none)")
        signs = np.sign(growth)
        crossed = (np.any(signs[:, 1:] * signs[:, :-1] < 0, axis=1).sum()
                   + np.any(signs[1:, :] * signs[:-1, :] < 0, axis=0).sum())
        where = (f"the boundary crosses {crossed} of {sum(growth.shape)} grid lines"
                 if crossed else "no stability boundary in the grid")
        click.echo(f"{label}{share}; {where}")
