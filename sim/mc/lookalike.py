"""Characters that look like ASCII but are not, named in messages (doors24c).

A key typed with a Cyrillic ``а`` (``triаls``), a number with a full-width digit (``５``) or a
minus sign (``−1.0``), a point name in decomposed form (``E`` + U+0301 beside a precomposed
``É``): the one-line message quoted text that looks exactly like what the user meant, so it
could not be told what was wrong. :func:`note` names the first such character of a text by
its code point and Unicode name; :func:`skeleton` is the text with every lookalike read as
the character it looks like (two point names of one skeleton print the same in every table,
figure and exported file); :func:`differs` names what tells two such names apart.
"""

from __future__ import annotations

import re
import unicodedata

__all__ = ["note", "skeleton", "looks", "differs", "char_name", "alike", "toml_char_hint"]

#: Cyrillic and Greek letters drawn as a Latin letter, and the letter they look like
#: (doors25a: and the Armenian, Cherokee and Latin letters drawn as one, Greek small ones)
_GLYPHS = str.maketrans(
    "АВЕЅІЈКМНОРСТУХаеѕіјорсхуԁһԛԝӀΑΒΕΖΗΙΚΜΝΟΡΤΥΧοϲӏԌԜԚօսհոզႽᎪᏴᏟᎠᎬᎻᏦᎷᎾᏢᏚᎢᏙᏔᏃᏞᏒǀαιϳνρυ",
    "ABESIJKMHOPCTYXaesijopcxydhqwIABEZHIKMNOPTYXoclGWQouhnqSABCDEHKMOPSTVWZLRlaijvpu",
)
#: signs drawn as an ASCII one that NFKC does not fold
_SIGNS = str.maketrans({"\u2212": "-", "\u2010": "-", "\u2011": "-", "\ufe63": "-"})
_WORD = re.compile(r"\w+")


#: the control characters Unicode gives no name (a form feed was "U+000C unnamed")
_CONTROLS = {
    "\t": "CHARACTER TABULATION",
    "\x0b": "LINE TABULATION",
    "\x0c": "FORM FEED",
    "\x1b": "ESCAPE",
    "\x85": "NEXT LINE",
}


def char_name(c: str) -> str:
    """``U+0430 CYRILLIC SMALL LETTER A``."""
    return f"U+{ord(c):04X} {unicodedata.name(c, _CONTROLS.get(c, 'unnamed'))}"


def skeleton(text: str) -> str:
    """``text`` as it looks: NFKC-folded (full-width forms, ligatures, composed accents), with
    the Cyrillic and Greek letters that look Latin and the Unicode minus read as ASCII."""
    return unicodedata.normalize("NFKC", text).translate(_GLYPHS).translate(_SIGNS)


def looks(text: str) -> str:
    """``text`` as a reader sees it, in lower case: its :func:`skeleton` without white space and
    characters that do not print (``"Tri\u200bals "`` looks like ``trials``)."""
    return "".join(c for c in skeleton(text) if c.isprintable() and not c.isspace()).lower()


def _lookalike(c: str, word: str) -> bool:
    if c.isascii():
        return False
    if c.translate(_SIGNS) != c:
        return True
    if unicodedata.category(c).startswith("M"):  # a combining mark of a decomposed word
        return unicodedata.normalize("NFC", word) != word
    folded = unicodedata.normalize("NFKC", c)
    if folded != c and folded.isascii() and folded.strip():
        return True  # a full-width digit or letter, a ligature
    # a Cyrillic or Greek letter among Latin ones (a wholly Cyrillic word is no mistake)
    return c.translate(_GLYPHS) != c and any(x.isascii() and x.isalpha() for x in word)


def note(text: str) -> str:
    """`` (note: 'а' is U+0430 CYRILLIC SMALL LETTER A, not ASCII)`` for the first character of
    ``text`` that looks like an ASCII one but is not; ``""`` when there is none."""
    hit = next((c for m in _WORD.finditer(text) for c in m[0] if _lookalike(c, m[0])), None)
    hit = hit or next((c for c in text if c.translate(_SIGNS) != c), None)  # "−1.0"'s minus
    if hit is None or char_name(hit) in text:  # none, or named already
        return ""
    return f" (note: {hit!r} is {char_name(hit)}, not ASCII)"


def differs(a: str, b: str) -> str:
    """What tells ``a`` from ``b`` (of one :func:`skeleton`): the code points of the part where
    they differ, ``U+0410 against U+0041``."""
    i = 0
    while i < min(len(a), len(b)) and a[i] == b[i]:
        i += 1
    j = 0
    while j < min(len(a), len(b)) - i and a[-1 - j] == b[-1 - j]:
        j += 1
    codes = [
        " ".join(f"U+{ord(c):04X}" for c in s[i : len(s) - j][:8]) or "nothing" for s in (a, b)
    ]
    return f"{codes[0]} against {codes[1]}"


def alike(name: str, names) -> str:
    """`` (... declares 'X ', which looks the same: U+0020 against nothing)`` for a name of
    ``names`` that prints like ``name`` but is not it (a trailing space, a lookalike letter);
    ``""`` when there is none (doors25a: a claim id renamed so was 'not declared', unexplained)."""
    key = skeleton(name).strip()
    hit = next((n for n in names if n != name and skeleton(n).strip() == key), None)
    return (
        "" if hit is None else f" (declared is {hit!r}, which looks the same: {differs(hit, name)})"
    )


def toml_char_hint(line: str, col: int) -> str:
    """What the character at ``col`` (1-based) of a malformed TOML ``line`` is, when nothing
    shows it: a line ended by a lone CR (classic Mac OS), or a character that is not ASCII --
    invisible (a second byte-order mark, a zero-width or no-break space) or drawn as ASCII (a
    Cyrillic letter in a key): "at line 6, column 4" of ``triаls = 5`` pointed at nothing
    the user could see; nor did "Invalid value" at a form feed or a vertical tab."""
    c = line[col - 1 : col]
    if c == "\r" and line[col : col + 1] != "":  # tomllib's line ends at "\n" only
        return " (a lone CR ends the line, as classic Mac OS saved text: save it with LF ends)"
    if c and (not c.isascii() or not c.isprintable()):  # a form feed or a vertical tab too:
        return f" (the character there is {c!r}, {char_name(c)})"  # "Invalid value" named none
    return ""
