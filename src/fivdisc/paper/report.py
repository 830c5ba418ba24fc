"""The reproduction report: REPORT.md and a self-contained REPORT.html.

Both are rendered from the same blocks (headings, paragraphs, tables, images), so
they say the same thing; the HTML embeds the PNG images (base64), so it can be
mailed or archived as one file.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from fivdisc.paper.figures import Row

__all__ = ["Block", "figure_blocks", "render_html", "render_markdown", "summary_blocks"]

_COLUMNS = ("quantity", "paper", "fivdisc", "printed sign", "verdict")


@dataclass(frozen=True)
class Block:
    """One piece of the report.

    Attributes
    ----------
    kind
        "h1", "h2", "p", "table" or "image".
    text
        Heading or paragraph text; the image's file name for "image".
    rows
        Table rows (the first is the header) for "table".
    """

    kind: str
    text: str = ""
    rows: tuple[tuple[str, ...], ...] = ()


def summary_blocks(title: str, intro: Sequence[str], figures: dict[int, list[Row]],
                   missing: Sequence[int]) -> list[Block]:
    """Title, introduction and the table of verdict counts per figure.

    Parameters
    ----------
    title
        Report title.
    intro
        Introductory paragraphs.
    figures
        Figure number -> its comparison rows, for the figures in the report.
    missing
        Figures not computed (yet) in the output directory.
    """
    blocks = [Block("h1", title), *(Block("p", p) for p in intro)]
    table = [("Fig.", "agrees", "partly", "differs", "measured only", "differing quantities")]
    for number, rows in figures.items():
        count = {v: sum(r.verdict == v for r in rows) for v in ("agrees", "partly", "differs", "")}
        differing = "; ".join(r.quantity for r in rows if r.verdict == "differs")
        table.append((str(number), str(count["agrees"]), str(count["partly"]),
                      str(count["differs"]), str(count[""]), differing))
    blocks += [Block("h2", "Summary"), Block("table", rows=tuple(table))]
    if missing:
        blocks.append(Block("p", "Not computed in this directory: Figs. "
                            + ", ".join(map(str, missing)) + "."))
    return blocks


def figure_blocks(number: int, title: str, caption: str, choices: str, image: str,
                  rows: Sequence[Row], seconds: float) -> list[Block]:
    """The section of one figure: caption, choices, image and comparison table."""
    table = [_COLUMNS] + [(r.quantity, r.paper, r.fivdisc, r.printed, r.verdict or "-")
                          for r in rows]
    return [
        Block("h2", f"Fig. {number}: {title}"),
        Block("p", f"Paper's caption: {caption}."),
        Block("p", f"Choices: {choices} Computed in {seconds:.1f} s."),
        Block("image", image),
        Block("table", rows=tuple(table)),
    ]


def _md_cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def render_markdown(blocks: Sequence[Block]) -> str:
    """The blocks as Markdown; images are linked by file name."""
    out = []
    for block in blocks:
        if block.kind == "h1":
            out.append(f"# {block.text}")
        elif block.kind == "h2":
            out.append(f"## {block.text}")
        elif block.kind == "p":
            out.append(block.text)
        elif block.kind == "image":
            out.append(f"![{block.text}]({block.text})")
        elif block.kind == "table":
            head, *body = block.rows
            lines = ["| " + " | ".join(_md_cell(c) for c in head) + " |",
                     "|" + "---|" * len(head)]
            lines += ["| " + " | ".join(_md_cell(c) for c in row) + " |" for row in body]
            out.append("\n".join(lines))
    return "\n\n".join(out) + "\n"


_STYLE = """
body { font-family: sans-serif; max-width: 1200px; margin: 2em auto; padding: 0 1em; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 0.3em 0.5em; vertical-align: top; text-align: left; }
th { background: #eee; }
td.agrees { background: #dff0d8; } td.partly { background: #fcf8e3; }
td.differs { background: #f2dede; }
img { max-width: 100%; }
"""


def render_html(blocks: Sequence[Block], directory: Path) -> str:
    """The blocks as one HTML page with the images of `directory` embedded."""
    out = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
           f"<title>{html.escape(blocks[0].text)}</title><style>{_STYLE}</style></head><body>"]
    for block in blocks:
        text = html.escape(block.text)
        if block.kind in ("h1", "h2"):
            out.append(f"<{block.kind}>{text}</{block.kind}>")
        elif block.kind == "p":
            out.append(f"<p>{text}</p>")
        elif block.kind == "image":
            data = base64.b64encode((directory / block.text).read_bytes()).decode("ascii")
            out.append(f'<img alt="{text}" src="data:image/png;base64,{data}">')
        elif block.kind == "table":
            head, *body = block.rows
            out.append("<table><tr>" + "".join(f"<th>{html.escape(c)}</th>" for c in head)
                       + "</tr>")
            for row in body:
                cells = "".join(
                    f'<td class="{html.escape(c)}">{html.escape(c)}</td>' if c in
                    ("agrees", "partly", "differs") else f"<td>{html.escape(c)}</td>"
                    for c in row)
                out.append(f"<tr>{cells}</tr>")
            out.append("</table>")
    out.append("</body></html>")
    return "\n".join(out) + "\n"
