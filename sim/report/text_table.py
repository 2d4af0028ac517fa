"""Plain-text tables for the terminal (``sim show``, the end of ``sim run``): columns aligned
by the width a terminal gives each character, the first column shortened with ``...`` when the
table is wider than the terminal."""

from __future__ import annotations

import unicodedata

__all__ = ["text_table", "cut"]


def text_table(header: list[str], rows: list[list], width: int) -> str:
    """Columns aligned by the width a terminal gives each character (:func:`_cols`): a
    network's or a swept value's CJK name takes two columns, an accent none."""
    cols = list(zip(header, *rows)) if rows else [(h,) for h in header]
    w = [max(_cols(str(c)) for c in col) for col in cols]
    if sum(w) + 2 * (len(w) - 1) > width and len(w) > 1:  # shorten the first column
        w[0] = max(12, width - sum(w[1:]) - 2 * (len(w) - 1))

    def line(cells):
        return "  ".join(_pad(cut(str(c), w[i]), w[i]) for i, c in enumerate(cells)).rstrip()

    return "\n".join([line(header), line(["-" * x for x in w])] + [line(r) for r in rows])


def _cols(s: str) -> int:
    """Terminal columns of ``s``: East Asian wide and full-width characters two, combining
    marks and zero-width characters none, every other character one."""
    return sum(
        0
        if unicodedata.combining(ch) or unicodedata.category(ch) in ("Mn", "Me", "Cf")
        else 2
        if unicodedata.east_asian_width(ch) in ("W", "F")
        else 1
        for ch in s
    )


def _pad(s: str, n: int) -> str:
    return s + " " * max(n - _cols(s), 0)


def cut(s: str, n: int) -> str:
    """``s`` in at most ``n`` terminal columns, ``...`` ending a shortened one."""
    if _cols(s) <= n:
        return s
    out, room = "", max(n - 3, 0)
    for ch in s:
        if _cols(out + ch) > room:
            break
        out += ch
    return out + "..."
