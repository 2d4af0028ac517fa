"""A word too long for a one-line message, shown cut.

A refusal quotes what it refuses: a key, a value, a path. Given a string of 100,000
characters (``sim.load(f, plate__pattern="y" * 100_000)``, ``--set plate.pattern=yyy...``, a
key of that length), the one line was 100 KB, the key's name and the reason lost in a
terminal's scroll-back. :func:`clipped` cuts every run of more than :data:`LONG_WORD`
characters without white space to its start and end, saying how long it was, and writes
every character that does not print escaped (:func:`sim.mc.message_text.printable`: an escape
sequence or a bidi override in a value, a key or a recorded string is shown, not obeyed).
"""

from __future__ import annotations

import re

from sim.mc.message_text import LONG_WORD, cut_text, printable

__all__ = ["LONG_WORD", "clipped"]

_LONG = re.compile(r"\S{%d,}" % (LONG_WORD + 1))
#: a word's quotes and brackets before it, and those and its punctuation after it
_EDGES = re.compile(r"""(['"(\[{]*)(.*?)(['")\]}:,;.]*)""", re.S)


def clipped(text: str) -> str:
    """``text`` with every word of more than :data:`LONG_WORD` characters cut:
    ``'yyyy...yyyy' (100002 characters)``, the length that of the word without the quotes,
    brackets and punctuation around it (it counted them: a value of 100,003 characters was
    "100006 characters" in ``(got 'yyy...')``); its characters that do not print escaped."""
    return _LONG.sub(_cut, printable(text))


def _cut(m: re.Match) -> str:
    core = _EDGES.fullmatch(m[0])[2] or m[0]
    return cut_text(m[0], len(core))
