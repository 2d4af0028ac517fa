"""Short labels of values that stay apart: a tick of ``sweep.png`` and a swept key's values
in a sweep's configuration line (``sim.report.config_diff``) keep what tells one value from
another when they are cut."""

from __future__ import annotations

import os

__all__ = ["middle", "apart"]


def middle(text: str, n: int) -> str:
    """A tick label of at most ``n`` characters keeping both ends (values that differ only
    at their end, ``variant 01`` and ``variant 02``, stay apart)."""
    if len(text) <= n:
        return text
    head = (n - 1) // 2
    return text[:head] + "\u2026" + text[len(text) - (n - 1 - head) :]


#: where a shortened tick label may start (after one of the first) or end (before one of the
#: second): a value's own text is kept whole
_STARTS, _ENDS = " ,:;=([{", " ,:;)]}"


def apart(texts: list[str], n: int) -> list[str]:
    """Tick labels of at most ``n`` characters that tell the values apart: each text with
    both its ends (:func:`middle`), or when two of those read the same, without the text all
    of them share at their start and at their end (cut where a value's text starts or ends),
    ``…`` in its place, the rest shortened keeping both its ends. Swept grids
    (``[{'prefix': 'G', 'nx': 3, ...}]`` and ``nx = 4``) differ in their middle: each label
    kept both ends of its text, and every tick read ``"[{'pre…0012}]"``."""
    plain = [middle(t, n) for t in texts]
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
    longest, shared = max(len(t) for t in texts) - head - tail, head
    for h in range(shared - 1, -1, -1):  # as much of the shared start as fits: "nx = 3"
        if (shared - h) + longest > n - bool(h) - bool(tail):
            break
        if h == 0 or (first[h - 1] in _STARTS and first[h] not in _STARTS):
            head = h
    out = []
    for t in texts:
        core = t[head : len(t) - tail]
        room = n - bool(head) - bool(tail)
        out.append("\u2026" * bool(head) + middle(core, room) + "\u2026" * bool(tail))
    return out
