"""How a one-line message names a value and a key: an integer of hundreds of digits shortened,
a key that holds white space or a character that does not print quoted.

``shown``: 1e300 given for an integer key is the integer 10**300 (301 digits), which no one
line should print. ``key_text``: a quoted key of a study file with a trailing space
(``"trials " = 5``) was refused as ``trials : unknown key (did you mean trials?)``, the space
easy to miss (a tab, a no-break space or a zero-width space not seen at all); such a key is
named in double quotes, its white space other than a plain space and every character that
does not print written as TOML escapes it (``"tri\\u200bals"``), and the empty key
(``"" = 5``, which named no key) as ``""``, in a table too (``plate.""``: it was ``plate.``).
``near_keys``: ``--set plate.spacing_um=45000`` was "unknown key (did you mean
plate.spacing_mm?)", and the value typed in um, moved to the mm key, was a spacing 1000 times
the one meant: a key meant that differs only in its unit says the unit to convert to.
``unit_hint``: ``--set plate.spacing_mm="45mm"`` was "must be a number (got '45mm')", with
no word that the unit is the key's name's and the value the number alone.
``printable``: a string a run record holds (``written_as``, a study file's path, forged or
edited by hand) reached the terminal as it was in notes and warnings: an escape sequence
(``\\x1b]0;...\\x07`` retitled the window, ``\\x1b[2J`` cleared it), a carriage return or a
bidi override (U+202E) hid or reversed the words around it; such characters are written
escaped.
``cut_text``: a value or a word too long for one line, its start and end and its length
(``sim.mc.config`` and :mod:`sim.long_words` had a copy each).
"""

from __future__ import annotations

import re
import unicodedata
from typing import Any

from sim.mc.numtext import number_text

__all__ = ["LONG_DIGITS", "LONG_WORD", "cut_text", "shown", "shorten", "key_text", "near_keys"]
__all__ += ["unit_hint", "printable"]

#: the longest text (a run without white space) a message shows whole: a path of 200
#: characters is
LONG_WORD = 200

#: digits of an integer above which a message shows it shortened (a 64-bit one has 19 digits)
LONG_DIGITS = 19
#: a run of more digits than that in a message, not part of a word, a path or a decimal
_LONG_RUN = re.compile(r"(?<![\w./])-?\d{%d,}(?![\w./])" % (LONG_DIGITS + 1))
#: TOML's short escapes
_ESCAPES = {
    '"': '\\"',
    "\\": "\\\\",
    "\t": "\\t",
    "\n": "\\n",
    "\r": "\\r",
    "\b": "\\b",
    "\f": "\\f",
}


def shown(v: Any) -> str:
    """``repr(v)`` for a message, with an integer of more than 19 digits shortened (``1e+300``,
    or "a 401-digit number" beyond a float's range)."""
    if isinstance(v, int) and not isinstance(v, bool):
        if abs(v) >= 10**4000:  # str() reads at most 4300 digits
            return f"a {'negative ' if v < 0 else ''}number of over 4000 digits"
        digits = len(str(abs(v)))
        if digits <= LONG_DIGITS:
            return repr(v)
        try:
            return f"{float(v):g}"
        except OverflowError:
            return f"a {'negative ' if v < 0 else ''}{digits}-digit number"
    return repr(v)


def shorten(message: str) -> str:
    """Every run of more than 19 digits in ``message`` shortened as :func:`shown` does (one
    beyond a float's range counted, not converted: Python reads at most 4300 digits)."""

    def short(m: re.Match) -> str:
        t = m.group(0)
        digits = len(t.lstrip("-"))
        if digits > 308:
            return f"a {'negative ' if t.startswith('-') else ''}{digits}-digit number"
        return shown(int(t))

    return _LONG_RUN.sub(short, message)


def _plain(c: str) -> bool:
    return c == " " or (c.isprintable() and not c.isspace())


def key_text(key: str) -> str:
    """``key`` as a message names it: as it is, or in double quotes with TOML's escapes when it
    is empty or holds white space or a character that does not print; a dotted key with an
    empty part is named part by part, that part as ``""`` (``[plate] "" = 5``: ``plate.""``,
    not ``plate.``)."""
    if not isinstance(key, str):
        return str(key)
    parts = key.split(".")
    if len(parts) > 1 and "" in parts:
        return ".".join(map(key_text, parts))
    if key and all(c.isprintable() and not c.isspace() for c in key):
        return key
    esc = (
        _ESCAPES.get(c)
        or (c if _plain(c) else f"\\u{ord(c):04x}" if ord(c) < 0x10000 else f"\\U{ord(c):08x}")
        for c in key
    )
    return '"' + "".join(esc) + '"'


#: the unit suffixes of the studies' keys (and a few a user types for them)
_UNITS = {"m", "mm", "um", "nm", "cm", "km", "deg", "arcsec", "arcmin", "rad", "gon", "mgon"}
_UNITS |= {"ppm", "s", "in", "ft", "mu", "micron", "microns"}


def near_keys(key: str, near: list[str]) -> str:
    """`` (did you mean plate.spacing_mm?)`` for the keys ``near`` a mistyped ``key`` ("" for
    none), with the unit to convert to when the first differs from ``key`` only in its unit
    suffix (``plate.spacing_um``: ``its value is in mm, not um: convert it``)."""
    if not near:
        return ""
    stem, _, typed = key.rpartition("_")
    meant_stem, _, unit = near[0].rpartition("_")
    same = stem and stem == meant_stem and typed != unit
    said = (
        f" its value is in {unit}, not {typed}: convert it"
        if same and {typed, unit} <= _UNITS
        else ""
    )
    return f" (did you mean {' or '.join(near)}?{said})"


def cut_text(text: str, n: int | None = None) -> str:
    """``text`` whole up to :data:`LONG_WORD` characters, else its first 60 and last 20 and
    its length ``n`` (default ``len(text)``): ``'yyy...yyy' (100000 characters)``."""
    if len(text) <= LONG_WORD:
        return text
    return f"{text[:60]}...{text[-20:]} ({len(text) if n is None else n} characters)"


#: a number followed by a unit: ``45mm``, ``45 mm``, ``2.5"``, ``1e-3 arcsec``
_WITH_UNIT = re.compile(
    r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-z\u00b5\u00b0\"']{1,12})\s*"
)


def unit_hint(key: str, text: str) -> str:
    """For the text ``text`` given to the number key ``key``: when it is a number written with
    a unit, the words that say the unit is in the key's name and what to write (``: the unit
    is in the key's name (_mm): write 45``), else ``""``."""
    m = _WITH_UNIT.fullmatch(text) if len(text) <= 100 else None
    if m is None:
        return ""
    number, unit = m.groups()
    number = number_text(number)  # as TOML writes it: ".5mm" was told "write .5", refused too
    stem, _, own = key.rpartition(".")[2].rpartition("_")
    if stem and own in _UNITS:
        if unit.lower().replace("\u00b5", "u") == own.lower():  # 1e999: no number to write
            return f": the unit is in the key's name (_{own}): write {number or 'a finite number'}"
        return f": the key's unit is {own}, in its name: write the number alone, in {own}"
    return ": write the number alone, without a unit"


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
