"""``fivdisc stability``: linear stability of the sliding equilibrium and stability maps."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

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
              help="map.nc (netCDF dataset) or map.png (figure).")
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
    from fivdisc.analysis.stability import linear_stability, parse_range, stability_map
    from fivdisc.case import Case, load_case

    case = load_case(case_file) if case_file else Case()
    if x_spec is None and y_spec is None:
        res = linear_stability(case)
        if as_json:
            import json

            click.echo(json.dumps(res.to_dict(), indent=2))
            return
        eq = res.equilibrium
        click.echo(f"sliding equilibrium at Omega = {eq.speed:.6g} rad/s:")
        for j, (phi, nf, f) in enumerate(zip(eq.phi, eq.normal_force, eq.friction_force,
                                             strict=True)):
            who = f"slider {j}: " if eq.phi.size > 1 else ""
            click.echo(f"  {who}phi = {phi:.6g} rad, N = {nf:.6g} N, f = {f:.6g} N")
        click.echo(f"{'growth rate [1/s]':>18} {'frequency [Hz]':>15}  mode")
        for row in res.table():
            click.echo(f"{row['growth_rate']:18.6g} {row['frequency_hz']:15.6g}  "
                       f"{row['coordinate']}")
        click.echo("stable" if res.stable else f"unstable (max growth {res.max_growth_rate:.4g}"
                                                " 1/s)")
        return
    if x_spec is None or y_spec is None:
        raise FivdiscError("a stability map needs both --x and --y (KEY=START:STOP:N)")
    if as_json:
        raise FivdiscError("--json prints the equilibrium and eigenvalues: leave out --x/--y")
    if output is not None and output.suffix not in (".nc", ".png"):
        raise FivdiscError(f"-o {output}: the file must end in .nc or .png")
    x = parse_range(x_spec, "--x")
    y = parse_range(y_spec, "--y")
    curves = parse_range(curve_spec, "--curves") if curve_spec else None
    ds = stability_map(case, x, y, curves, progress=progress)
    if output is None or output.suffix == ".nc":
        out = output or Path("stability.nc")
        ds.to_netcdf(out)
    else:
        from fivdisc.plots import plot_stability_map

        out = output
        plot_stability_map(ds).savefig(out, dpi=150)
    click.echo(f"wrote {out}")
    for i, c in enumerate(ds["curve"].values):
        b = ds["boundary"].values[i]
        label = f"{ds.attrs['curve_key']} = {c:g}: " if ds.attrs["curve_key"] else ""
        stable = ds["stable"].values[i]
        click.echo(f"{label}stable at {stable.mean():.1%} of the grid; boundary found at "
                   f"{int(np.sum(~np.isnan(b)))} of {b.size} x values")
