"""``fivdisc stability``: linear stability of the sliding equilibrium and stability maps."""

from __future__ import annotations

from pathlib import Path

import click

from fivdisc.cli._case import CASE
from fivdisc.errors import FivdiscError


@click.command()
@click.argument("case_file", required=False, type=CASE)
@click.option("--x", "x_spec", metavar="KEY=START:STOP:N",
              help="Horizontal axis, e.g. normal_damping=0:12:200 (with --y: a map).")
@click.option("--y", "y_spec", metavar="KEY=START:STOP:N", help="Vertical axis.")
@click.option("--curves", "curve_spec", metavar="KEY=v1,v2,...",
              help="One map and boundary curve per value, e.g. decay=0,1,10.")
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="map.nc (netCDF dataset) or a figure in any format matplotlib writes "
              "(map.png, map.pdf, map.svg, ...).")
@click.option("--json", "as_json", is_flag=True,
              help="Print the equilibrium and the eigenvalues as JSON (without a map).")
@click.option("--progress/--no-progress", default=True, show_default=True)
def stability(case_file: Path | None, x_spec: str | None, y_spec: str | None,
              curve_spec: str | None, output: Path | None, as_json: bool,
              progress: bool) -> None:
    """Stability of the sliding equilibrium of CASE_FILE (default: Table 1 at 2 pi rad/s).

    CASE_FILE is a TOML case file or the name of a packaged example (``fivdisc examples``).
    Without --x/--y: prints the equilibrium and the eigenvalues of the linearised slip
    equations. With both: computes the largest growth rate over the grid and the
    stability boundary, and writes it with -o.
    """
    import numpy as np

    from fivdisc.analysis.stability import linear_stability, parse_range, stability_map
    from fivdisc.case import Case, load_case
    from fivdisc.extras import require
    from fivdisc.files import check_output, figure_suffixes, write_atomic, write_netcdf

    case = load_case(case_file) if case_file else Case()
    if x_spec is None and y_spec is None:
        for option, given in (("--curves", curve_spec), ("-o", output)):
            if given is not None:
                raise FivdiscError(f"{option} is used only by a stability map: give --x and --y "
                                   "too (KEY=START:STOP:N)")
        res = linear_stability(case)
        if as_json:
            import json

            click.echo(json.dumps(res.to_dict(), indent=2))
            return
        click.echo(str(res))
        return
    if x_spec is None or y_spec is None:
        raise FivdiscError("a stability map needs both --x and --y (KEY=START:STOP:N)")
    if as_json:
        raise FivdiscError("--json prints the equilibrium and eigenvalues: leave out --x/--y")
    target = output or Path("stability.nc")
    figure = target.suffix.lower() != ".nc"
    if figure:
        require("plot", f"fivdisc stability -o {target.name} (a figure)")
    out = check_output(target, "-o", (".nc", *figure_suffixes()) if figure else (".nc",),
                       inputs=[case_file])
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
    if case_file is not None:
        ds.attrs["case_name"] = case_file.stem
    if not figure:
        write_netcdf(out, ds.to_netcdf)
    else:
        from fivdisc.plots import plot_stability_map

        drawn = plot_stability_map(ds)
        write_atomic(out, lambda path: drawn.savefig(path, dpi=150))
    click.echo(f"wrote {out}")
    ckey = ds.attrs.get("curve_key", "")
    for value in ds[ckey].values if ckey else [None]:
        one = ds if value is None else ds.sel({ckey: value})
        boundary, stable = one["boundary"].values, one["stable"].values
        label = "" if value is None else f"{ckey} = {value:g}: "
        click.echo(f"{label}stable at {stable.mean():.1%} of the grid; boundary found at "
                   f"{int(np.sum(~np.isnan(boundary)))} of {boundary.size} x values")
