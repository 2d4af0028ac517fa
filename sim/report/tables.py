"""Numbers and tables as Markdown text: the formatting every report section shares."""

from __future__ import annotations

import math
import re

import numpy as np

__all__ = ["fmt", "md_table"]


def fmt(x, digits: int = 3) -> str:
    if x is None:
        return ""
    if isinstance(x, (bool, np.bool_)):
        return "yes" if x else "no"
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    if isinstance(x, (float, np.floating)):
        if not math.isfinite(x):
            return ""
        if x == 0:
            return "0"
        mag = math.floor(math.log10(abs(x)))
        dec = max(0, digits - 1 - mag)
        if dec > 9:  # nine decimals would print a nonzero 1e-11 as 0.000000000
            return f"{x:.{digits - 1}e}"
        return f"{x:.{dec}f}"
    return str(x)


def _cell(s) -> str:
    """A table cell's text: a pipe escaped (``\\|``), and the backslashes just before it
    doubled, so that a name ending in a backslash (``P\\``) does not escape the pipe's
    escape and split the row into one cell more (GitHub reads ``\\\\|`` as a backslash and a
    cell's end); a line break made a space."""
    s = re.sub(r"(\\*)\|", lambda m: m[1] * 2 + "\\|", str(s))
    return s.replace("\n", " ")


def md_table(header: list[str], rows: list[list]) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(_cell(c) for c in r) + " |" for r in rows]
    return "\n".join(out)
