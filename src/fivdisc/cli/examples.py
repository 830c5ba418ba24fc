"""``fivdisc examples [NAME]``: the packaged example cases and sweeps."""

from __future__ import annotations

import click


@click.command("examples")
@click.argument("name", required=False)
def examples(name: str | None) -> None:
    """List the example cases and sweeps that ship with fivdisc, or print one.

    Without NAME: one line per example, its name and a one-line description. With NAME:
    the example's TOML text, e.g. to start a case of your own with
    ``fivdisc examples fig10 > mycase.toml``. Every command that takes a case file also
    takes an example's name when no file of that name exists, e.g.
    ``fivdisc simulate fig10 -o fig10.nc``.
    """
    from fivdisc import examples as packaged

    if name is not None:
        click.echo(packaged.path(name).read_text(encoding="utf-8"), nl=False)
        return
    listing = packaged.available()
    width = max(map(len, listing))
    for example, description in listing.items():
        click.echo(f"{example:<{width}}  {description}")
