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
    string from a file shows as what it holds and does nothing to the terminal; ``lines``:
    its line feeds and tabs kept (a text of several lines)."""
    if not isinstance(text, str):
        text = str(text)
    if text.isascii() and text.isprintable():
        return text
    return "".join(
        c
        if (lines and c in "\n\t") or unicodedata.category(c) not in _UNPRINTED
        else f"\\x{ord(c):02x}"
        if ord(c) < 0x100
        else f"\\u{ord(c):04x}"
        if ord(c) < 0x10000
        else f"\\U{ord(c):08x}"
        for c in text
    )
