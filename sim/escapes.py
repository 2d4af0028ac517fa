"""Text a terminal shows as what it holds: every control, format (bidi override), separator,
surrogate or private-use character of a string written as Python escapes it. A string from a
file (a run record's ``written_as``, a study file's path, a note edited into a table) reached
the terminal as it was: an escape sequence (``\\x1b]0;...\\x07`` retitled the window,
``\\x1b[2J`` cleared it), a carriage return or a bidi override (U+202E) hid or reversed the
words around it. Below every layer that prints (:mod:`sim.standard_error` too), so a note and a
one-line error escape alike."""

from __future__ import annotations

import unicodedata

__all__ = ["printable"]


#: the categories of the characters :func:`printable` writes escaped: controls (C0, C1, DEL),
#: format characters (bidi overrides and isolates, zero-width ones), line and paragraph
#: separators, surrogates and private use
_UNPRINTED = {"Cc", "Cf", "Zl", "Zp", "Cs", "Co"}


def printable(text: str, lines: bool = False) -> str:
    """``text`` with every control, format (bidi override), separator, surrogate or
    private-use character written as Python escapes it (``\\x1b``, ``\\u202e``), so that a
    string from a file shows as what it holds and does nothing to the terminal; a zero-width
    (non-)joiner between two non-ASCII characters that print is kept (:data:`_JOINERS`);
    ``lines``: its line feeds and tabs kept (a text of several lines)."""
    if not isinstance(text, str):
        text = str(text)
    if text.isascii() and text.isprintable():
        return text
    return "".join(
        c
        if (lines and c in "\n\t") or _shown(text, i)
        else f"\\x{ord(c):02x}"
        if ord(c) < 0x100
        else f"\\u{ord(c):04x}"
        if ord(c) < 0x10000
        else f"\\U{ord(c):08x}"
        for i, c in enumerate(text)
    )


#: the zero-width non-joiner and joiner, format characters that a script's words and an emoji
#: sequence hold (Persian's "نقشه\u200cبرداری", a family emoji): kept between two characters
#: that print and are not ASCII (a legit name was shown as "نقشه\\u200cبرداری"), escaped
#: elsewhere (hidden between Latin letters)
_JOINERS = "\u200c\u200d"


def _shown(text: str, i: int) -> bool:
    """Whether ``text[i]`` is written as it is by :func:`printable`."""
    c = text[i]
    if unicodedata.category(c) not in _UNPRINTED:
        return True
    if c not in _JOINERS or not 0 < i < len(text) - 1:
        return False
    return all(
        not n.isascii() and unicodedata.category(n) not in _UNPRINTED
        for n in (text[i - 1], text[i + 1])
    )
