"""``fivdisc modes``: natural frequencies and modal masses of a case's disc modes."""

from __future__ import annotations

import json
from pathlib import Path

import click

from fivdisc.cli._case import CASE


@click.command("modes")
@click.argument("case", required=False, type=CASE)
@click.option(
    "--json",
    "as_json",
    is_flag=True,
    help="Print a JSON list of {k, l, omega, frequency_hz, modal_mass} instead of a table.",
)
def modes(case: Path | None, as_json: bool) -> None:
    """Natural frequencies and modal masses of the disc modes of CASE.

    CASE is a TOML case file or the name of a packaged example (``fivdisc examples``);
    without it the paper's Table 1 disc is used. One line per (k, l) of the case's mode
    list (k nodal circles, l nodal diameters; every l >= 1 mode is a doublet). omega is in
    rad/s, the frequency in Hz and the modal mass in kg, for the mode shape scaled to
    max |R| = 1.
    """
    # Imported here so that `fivdisc --help` does not pay for scipy and pydantic.
    from fivdisc.case import Case, load_case
    from fivdisc.model.plate import AnnularPlate

    disc = (load_case(case) if case is not None else Case()).disc
    rows = [
        {
            "k": mode.k,
            "l": mode.l,
            "omega": mode.omega,
            "frequency_hz": mode.frequency_hz,
            "modal_mass": mode.modal_mass,
        }
        for mode in AnnularPlate.from_disc(disc).modes(disc.modes)
    ]
    if as_json:
        click.echo(json.dumps(rows, indent=2))
        return
    click.echo(
        f"{'k':>3} {'l':>3} {'omega [rad/s]':>14} {'frequency [Hz]':>15} {'modal mass [kg]':>16}"
    )
    for row in rows:
        click.echo(
            f"{row['k']:>3d} {row['l']:>3d} {row['omega']:>14.2f} "
            f"{row['frequency_hz']:>15.3f} {row['modal_mass']:>16.6g}"
        )
