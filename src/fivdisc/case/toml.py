"""Case files as TOML text: reading it with a one-line error, writing its arrays readably."""

from __future__ import annotations

import json
import tomllib
from typing import Any

from fivdisc.errors import CaseError


def read_toml(text: str, source: str | None) -> dict[str, Any]:
    """The tables of TOML `text`; `source` (a path) prefixes the error message.

    Raises
    ------
    CaseError
        Invalid TOML.
    """
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        message = f"invalid TOML: {exc}"
    except RecursionError:
        message = "invalid TOML: arrays or tables nested too deeply"
    raise CaseError(f"{source}: {message}" if source else message) from None


def inline_arrays(text: str, width: int = 88) -> str:
    """TOML `text` with each array on one line (``modes = [[0, 0], [0, 1]]``), or one line
    per element when that is wider than `width`: tomli_w writes one number per line."""
    out: list[str] = []
    lines = iter(text.splitlines())
    for line in lines:
        key, sep, value = line.partition(" = ")
        if not (sep and value == "["):
            out.append(line)
            continue
        block = [line]
        for inner in lines:
            block.append(inner)
            if inner == "]":
                break
        items = tomllib.loads("\n".join(block))[key.strip().strip('"')]
        inline = [json.dumps(item, separators=(", ", ": ")) for item in items]
        one = f"{key} = [{', '.join(inline)}]"
        out += [one] if len(one) <= width else [f"{key} = [", *(f"    {i}," for i in inline), "]"]
    return "\n".join(out) + "\n"
