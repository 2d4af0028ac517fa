"""Short labels of values that stay apart: a tick of ``sweep.png``, a swept key's values in a
sweep's configuration line (``sim.report.config_diff``) and its column in ``sim show`` keep
what tells one value from another when they are cut. ``dots``: the ellipsis (``...`` where a
terminal of any encoding reads the text)."""

from __future__ import annotations

import os
from typing import Callable

__all__ = ["middle", "apart", "column"]

ELLIPSIS = "\u2026"


def middle(text: str, n: int, dots: str = ELLIPSIS) -> str:
    """``text`` in at most ``n`` characters keeping both ends (values that differ only at
    their end, ``variant 01`` and ``variant 02``, stay apart), each cut where a word or number
    ends or starts: the start is kept up to its half of the room, back to the last such
    place, and the end from the first such place in what is left (a sweep's configuration
    line read ``[{ prefix = "G", n...sigma_mm = 0.001 }]`` and ``...pacing_mm = 40.0``). A text
    without such places on either side is cut by count."""
    if len(text) <= n:
        return text
    room = n - len(dots)
    head = room // 2
    i = next((p for p in range(head, 0, -1) if _between(text, p)), 0)
    j = next((p for p in range(len(text) - (room - i), len(text)) if _between(text, p)), None)
    if i and j is not None:
        return text[:i] + dots + text[j:]
    return text[:head] + dots + text[len(text) - (room - head) :]


def _between(text: str, p: int) -> bool:
    """Whether ``text`` may be cut before position ``p``: not inside a word or number."""
    return not (_word(text[p - 1]) and _word(text[p]))


def _word(c: str) -> bool:
    """A character of a word or a number (``spacing_mm``, ``0.0012``, ``-3``): no cut inside."""
    return c.isalnum() or c in "_.-"


#: where a shortened label may start (after one of the first) or end (before one of the
#: second): a value's own text is kept whole
_STARTS, _ENDS = " ,:;=([{", " ,:;)]}"


def apart(texts: list[str], n: int, dots: str = ELLIPSIS) -> list[str]:
    """Labels of at most ``n`` characters that tell the distinct ``texts`` apart: each text
    with both its ends (:func:`middle`), or when two of those read the same, without the text
    all of them share at their start and at their end (cut where a value's text starts or
    ends; as much of the shared start kept as fits), ``dots`` in its place, the rest shortened
    keeping both its ends. Swept grids (``[{'prefix': 'G', 'nx': 3, ...}]`` and ``nx = 4``)
    differ in their middle: each label kept both ends of its text, and every tick of
    ``sweep.png`` read ``"[{'pre…0012}]"``. Texts that still read alike (differing in three
    places or more, in their middle too) are labelled by the window where they differ
    (:func:`_unique`)."""
    plain = [middle(t, n, dots) for t in texts]
    if len(set(plain)) == len(plain):
        return plain
    head = len(os.path.commonprefix(texts))
    tail = len(os.path.commonprefix([t[::-1] for t in texts]))
    short = min(len(t) for t in texts)
    tail = min(tail, short - head)  # "ab" and "abab": the two never overlap
    first = texts[0]
    while head and first[head - 1] not in _STARTS:
        head -= 1
    while tail and first[len(first) - tail] not in _ENDS:
        tail -= 1
    k = len(dots)
    longest, shared = max(len(t) for t in texts) - head - tail, head
    for h in range(shared - 1, -1, -1):  # as much of the shared start as fits: "nx = 3"
        if (shared - h) + longest > n - k * bool(h) - k * bool(tail):
            break
        if h == 0 or (first[h - 1] in _STARTS and first[h] not in _STARTS):
            head = h
    out = []
    for t in texts:
        core = t[head : len(t) - tail]
        room = n - k * bool(head) - k * bool(tail)
        out.append(dots * bool(head) + middle(core, room, dots) + dots * bool(tail))
    return _unique(texts, out, n, dots)


def _unique(texts: list[str], out: list[str], n: int, dots: str) -> list[str]:
    """``out`` with the labels two texts share replaced by :func:`_windows` of those texts:
    cores that differ in three places or more (a swept list's first, middle and last values)
    kept both their ends, which two of them shared."""
    groups: dict[str, list[int]] = {}
    for i, label in enumerate(out):
        groups.setdefault(label, []).append(i)
    for same in groups.values():
        if len(same) > 1 and len({texts[i] for i in same}) == len(same):
            for i, label in zip(same, _windows([texts[i] for i in same], n, dots)):
                out[i] = label
    if len(set(out)) < len(out):  # (windows of different texts that read alike)
        out = [middle(f"{j + 1}: {t}", n, dots) for j, t in enumerate(texts)]
    return out


def _windows(texts: list[str], n: int, dots: str) -> list[str]:
    """Labels of at most ``n`` characters of the distinct ``texts``, each the window of its
    text from where they first differ (from the start of that value), with those that agree
    there told apart from where they differ next."""
    at = len(os.path.commonprefix(texts))
    start = at
    while start and at - start < n // 2 and texts[0][start - 1] not in _STARTS:
        start -= 1
    room = n - len(dots) * (bool(start) + 1)
    out = [dots * bool(start) + t[start : start + room] for t in texts]
    out = [o + dots if len(t) - start > room else o for o, t in zip(out, texts)]
    groups: dict[str, list[int]] = {}
    for i, label in enumerate(out):
        groups.setdefault(label, []).append(i)
    for same in groups.values():
        if len(same) > 1:  # they agree beyond "at": their next difference is further on
            for i, label in zip(same, _windows([texts[i] for i in same], n, dots)):
                out[i] = label
    return out


def column(texts: list[str], cut: Callable[[str], str], n: int) -> list[str]:
    """A table's column (a value's text on each row) each shortened by ``cut``, or, when two
    values would read the same so, by :func:`apart` of its distinct values (``...`` for its
    ellipsis): ``sim show`` of a sweep over ``network.grids`` gave every cell's grids as
    ``[{'prefix': 'GRID', '...``, which told no cell's setting."""
    distinct = list(dict.fromkeys(texts))
    if len({cut(t) for t in distinct}) == len(distinct):
        return [cut(t) for t in texts]
    label = dict(zip(distinct, apart(distinct, n, "...")))
    return [label[t] for t in texts]
