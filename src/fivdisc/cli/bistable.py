"""``fivdisc bistable``: the region of two keys where stable sliding and a stable
stick-slip vibration coexist."""

from __future__ import annotations

from pathlib import Path

import click

from fivdisc.cli._case import CASE


@click.command(name="bistable")
@click.argument("case_file", type=CASE)
@click.option("--x", "x_spec", metavar="KEY=START:STOP", required=True,
              help="The key the orbits are continued in (the disc speed, typically) and "
              "its range.")
@click.option("--y", "y_spec", metavar="KEY=START:STOP", required=True,
              help="The second key and its range.")
@click.option("--points", type=int, default=12, show_default=True,
              help="Points of each curve followed in --y, from the case's value to each "
              "side of the box.")
@click.option("--grid", "grid_spec", default="41:21", show_default=True, metavar="NX:NY",
              help="Values of --x and --y of the grid the regions are shaded on.")
@click.option("--threshold", is_flag=True,
              help="Also follow where the unstable orbits born at the Hopf point end (their "
              "grazing or fold).")
@click.option("--vibration", "vibration_file",
              type=click.Path(dir_okay=False, exists=True, path_type=Path),
              help="A branch of the stable vibration in --x at the case's value of --y "
              "(fivdisc continue -o), instead of the one found from a start stuck to the "
              "disc: where several stable vibrations coexist, each has its own region.")
@click.option("-o", "--output", type=click.Path(dir_okay=False, path_type=Path),
              help="The region's netCDF file (.nc; default: beside CASE_FILE, "
              "CASE-bistable.nc), for fivdisc plot.")
@click.option("--figure", type=click.Path(dir_okay=False, path_type=Path),
              help="Also draw the region to this figure file (.png, .pdf, .svg).")
@click.option("--progress/--no-progress", default=True, show_default=True,
              help="Say what is being computed, on stderr.")
def bistable(case_file: Path, x_spec: str, y_spec: str, points: int, grid_spec: str,
             threshold: bool, vibration_file: Path | None, output: Path | None,
             figure: Path | None, progress: bool) -> None:
    """Map where sliding is stable and yet a large kick starts a stable vibration.

    In the box --x by --y: the Hopf curves of the sliding equilibrium (with their first
    Lyapunov coefficients and Bautin points), the stable stick-slip vibration found from
    a start stuck to the disc past the subcritical Hopf point at the case's value of
    --y, continued in --x to where it ends (a fold of cycles or a grazing), that end
    followed in --y across the box, and on a grid the regions: sliding unstable,
    bistable, sliding stable only. Prints the curves with each point's residuals and
    writes a netCDF file (fivdisc plot draws it).
    """
    from fivdisc.case import load_case
    from fivdisc.cli._case import default_output
    from fivdisc.cli.stability import _box
    from fivdisc.continuation.region import REGIONS, bistable_region
    from fivdisc.errors import FivdiscError
    from fivdisc.files import check_output, figure_suffixes, write_netcdf

    box = _box((x_spec, y_spec), "--x/--y")
    usage = f"--grid {grid_spec!r} is invalid: write NX:NY, two integers from 2 to 1000"
    try:
        nx, ny = (int(v) for v in grid_spec.split(":"))
    except ValueError:
        raise FivdiscError(usage) from None
    if not (2 <= nx <= 1000 and 2 <= ny <= 1000):
        raise FivdiscError(usage)
    if isinstance(points, bool) or points < 2:
        raise FivdiscError(f"--points = {points!r} is invalid: must be an integer >= 2")
    if output is None:
        beside = default_output(case_file, ".nc")
        output = beside.with_name(f"{beside.stem}-bistable.nc")
    out = check_output(output, "-o", (".nc",), inputs=[case_file])
    fig_out = None
    if figure is not None:
        from fivdisc.extras import require

        require("plot", "fivdisc bistable --figure")
        fig_out = check_output(figure, "--figure", figure_suffixes(), inputs=[case_file])
    case = load_case(case_file)
    vibration = None
    if vibration_file is not None:
        from fivdisc.continuation.branch import open_branch

        vibration = open_branch(vibration_file)
    ds = bistable_region(case, box[0], box[1], points=points, grid=(nx, ny),
                         threshold=threshold, vibration=vibration, progress=progress)
    ds.attrs["case_name"] = case_file.stem
    write_netcdf(out, ds.to_netcdf)
    click.echo(f"wrote {out}")
    if fig_out is not None:
        from fivdisc.cli.plot import _save
        from fivdisc.plots.region import plot_bistable_region

        _save(plot_bistable_region(ds), fig_out, 150)
    for line in region_lines(ds):
        click.echo(line)
    counts = {REGIONS[c]: int((ds["region"].values == c).sum()) for c in REGIONS}
    click.echo("grid: " + ", ".join(f"{n} {name}" for name, n in counts.items() if n))


def region_lines(ds) -> list[str]:
    """What a bistable region's dataset holds, as lines of text: the Hopf point and the
    vibration it starts from, each curve with every point's residuals."""
    xkey, ykey = ds.attrs["x_key"], ds.attrs["y_key"]
    lines = [f"at {ykey} = {ds.attrs['y_start']:.10g}: {ds.attrs['hopf']}",
             f"stable vibration: {ds.attrs['vibration']}",
             f"it ends: {ds.attrs['vibration_end']}"]
    for c in range(ds.sizes["curve"]):
        sel = ds["curve"].values == c
        lines.append(f"{ds['curve_role'].values[c]} ({ds['curve_kind'].values[c]}), "
                     f"{int(sel.sum())} points; {ds['curve_stop'].values[c]}")
        lines.append(f"  {ykey:>22} {xkey:>16} {'residual':>9} {'condition':>10}")
        for q, p, r, g in zip(ds["curve_y"].values[sel], ds["curve_x"].values[sel],
                              ds["curve_residual"].values[sel],
                              ds["curve_condition"].values[sel], strict=True):
            lines.append(f"  {q:>22.10g} {p:>16.10g} {r:>9.1e} {g:>10.1e}")
    for kind, x, y in zip(ds["special_kind"].values, ds["special_x"].values,
                          ds["special_y"].values, strict=True):
        if kind in ("bautin", "double_hopf"):
            lines.append(f"{'Bautin' if kind == 'bautin' else 'double Hopf'} point at "
                         f"{xkey} = {x:.10g}, {ykey} = {y:.10g}")
    return lines
