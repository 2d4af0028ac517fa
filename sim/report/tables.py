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


#: outside code spans, what a markdown reader takes for HTML: a tag's start (``<D>``,
#: ``</x``, ``<!--``) but the suite's own ``<br>``, and an entity (``&lt;``, ``&#60;``)
_HTML = re.compile(r"<(?!br>)(?=[A-Za-z/!?])|&(?=#?\w+;)")
#: a code span of a cell (its text shown as it is)
_CODE = re.compile(r"(`+)(?:(?!\1).)+?\1")


def _plain(s: str) -> str:
    """``s`` with what reads as HTML outside its code spans escaped: a point named ``<D>``
    vanished from a README's table (an unknown tag), ``&lt;`` showed as ``<``."""

    def esc(t: str) -> str:
        return _HTML.sub(lambda h: "&lt;" if h[0] == "<" else "&amp;", t)

    out, at = [], 0
    for m in _CODE.finditer(s):
        out += [esc(s[at : m.start()]), m[0]]
        at = m.end()
    return "".join([*out, esc(s[at:])])


def _cell(s) -> str:
    """A table cell's text: a pipe escaped (``\\|``), and the backslashes just before it
    doubled, so that a name ending in a backslash (``P\\``) does not escape the pipe's
    escape and split the row into one cell more (GitHub reads ``\\\\|`` as a backslash and a
    cell's end); a line break made a space; a tag or an entity outside code spans escaped
    (:func:`_plain`)."""
    s = re.sub(r"(\\*)\|", lambda m: m[1] * 2 + "\\|", _plain(str(s)))
    return s.replace("\n", " ")


def md_table(header: list[str], rows: list[list]) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(_cell(c) for c in r) + " |" for r in rows]
    return "\n".join(out)
