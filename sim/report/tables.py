"""Numbers and tables as Markdown text: the formatting every report section shares."""

from __future__ import annotations

import math
import re
from urllib.parse import quote

import numpy as np

__all__ = ["fmt", "md_table", "md_text", "md_code", "md_link", "md_href", "Md"]


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


class Md(str):
    """Text already in Markdown form (:func:`md_text`): :func:`md_table` writes it as it is."""


#: what Markdown or HTML reads as markup in a line of text: emphasis, code, links, tags,
#: entities, strike-through, a table's pipe, GitHub's math (``$``), and the backslash
_ACTIVE = re.compile(r"[\\`*_\[\]<>&~|$]")


def md_text(s) -> Md:
    """A user's text (a point or network name) as Markdown that shows it as written
    (doors24c): a point named ``<b>`` or ``&amp;`` was HTML in the README (bold for the rest
    of the cell, an ``&``), ``*a*`` italic, a backtick opened code. Each such character is
    escaped with a backslash; an underscore inside a word (``P_1``) cannot mark emphasis and
    is left as it is."""
    s = str(s).replace("\n", " ")

    def esc(m: re.Match) -> str:
        a, b = m.start(), m.end()
        inner = 0 < a and b < len(s) and s[a - 1].isalnum() and s[b].isalnum()
        return m[0] if m[0] == "_" and inner else "\\" + m[0]

    return Md(_ACTIVE.sub(esc, s))


def md_code(s) -> str:
    """``s`` as an inline code span that shows it as written: fenced by more backticks than
    any run inside it (a name with a backtick ended a one-backtick span early)."""
    s = str(s).replace("\n", " ")
    if "`" not in s:
        return f"`{s}`"
    fence = "`" * (max(len(r) for r in re.findall(r"`+", s)) + 1)
    return f"{fence} {s} {fence}"


def md_href(name: str, leaf: str = "README.md") -> str:
    """The link target ``name/leaf``, percent-encoded: a results directory named
    ``my net (v2)`` was no link in REPORT.md (a space ends a link's target)."""
    return quote(f"{name}/{leaf}")


def md_link(name: str, leaf: str = "README.md") -> Md:
    """``[name](name/leaf)``: the name shown as written (:func:`md_text`), the target encoded
    (:func:`md_href`); a plain name (``brown_table1``) is written as it was."""
    return Md(f"[{md_text(name)}]({md_href(name, leaf)})")


def _cell(s) -> str:
    """A table cell's text: a pipe escaped (``\\|``), and the backslashes just before it
    doubled, so that a name ending in a backslash (``P\\``) does not escape the pipe's
    escape and split the row into one cell more (GitHub reads ``\\\\|`` as a backslash and a
    cell's end); a line break made a space; a tag or an entity outside code spans escaped
    (:func:`_plain`). :class:`Md` text is written as it is."""
    if isinstance(s, Md):
        return str(s)
    s = re.sub(r"(\\*)\|", lambda m: m[1] * 2 + "\\|", _plain(str(s)))
    return s.replace("\n", " ")


def md_table(header: list[str], rows: list[list]) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(_cell(c) for c in r) + " |" for r in rows]
    return "\n".join(out)
