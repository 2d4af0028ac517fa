"""A TOML slip in a study file named in the suite's words (:func:`sim.mc.config.read_toml`).

tomllib says where a study file stops being TOML ("Invalid value (at line 3, column 9)") but not
what the user probably meant. The slips a new user makes in a study file are few and plain to
see in the line: a text value without quotes (``study = brown_table1``), a number with a
thousands separator or a decimal comma (``trials = 4,000``, ``format_mm = 245,0``), a number
with its unit (``setting_sigma_um = 1.7um``: the unit is in the key's name), ``True`` for
``true``, ``NaN`` and ``Inf`` for ``nan`` and ``inf``, ``None`` or ``null`` (TOML has none),
``key: value``, a table name or a list without its closing bracket, a string without
its closing quote. :func:`slip_hint` names the slip and the line as it was probably meant;
:func:`quote_hint` names a word processor's typographic quote. No hint is a guess at random:
a line none of these fits gets none.
"""

from __future__ import annotations

import re

__all__ = ["TYPOGRAPHIC", "quote_hint", "slip_hint"]

#: quotes an editor or a web page puts where a plain " or ' was typed (“plate.grid=4”)
TYPOGRAPHIC = "\u201c\u201d\u2018\u2019\u201e\u00ab\u00bb"
#: the units the study schemas put at the end of a key's name (``spacing_mm``)
UNITS = ("mm", "um", "m", "nm", "deg", "rad", "arcsec", "mgon", "gon", "pct", "ppm", "px")
_NUMBER = re.compile(r"[+-]?(?:\d[\d_]*)(?:\.\d[\d_]*)?(?:[eE][+-]?\d+)?")
_KEY_VALUE = re.compile(r"\s*([A-Za-z0-9_.\-\"' ]+?)\s*=\s*(.*)")
_BARE_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_.\-]*")
#: longest line a hint is looked for in (a study file's lines are short; a line of megabytes
#: is no slip, and a regular expression's backtracking over it would take minutes)
LONGEST = 400


def quote_hint(line: str) -> str:
    """`` (the typographic quote “ is no TOML quote: type ")`` for a ``line`` holding one."""
    curly = [c for c in line if c in TYPOGRAPHIC]
    return f' (the typographic quote {curly[0]} is no TOML quote: type ")' if curly else ""


def _unit(key: str) -> str | None:
    """The unit the name of ``key`` (dotted) ends in: ``plate.spacing_mm`` -> ``mm``."""
    end = key.rsplit(".", 1)[-1].rsplit("_", 1)
    return end[1] if len(end) == 2 and end[1] in UNITS else None


def _value_slip(key: str, value: str) -> str:
    """What is wrong with ``value``, the text after ``key =`` up to its end or comment."""
    if not value:
        return f"{key} has no value: write one after the ="
    if m := re.fullmatch(r"([+-]?\d{1,3})((?:[, ]\d{3})+)", value):  # 4,000, 4 000, -4,000
        digits = m.group(1) + re.sub(r"[, ]", "", m.group(2))
        return f"a TOML number has no thousands separator: {key} = {digits}, or {key} = " + (
            m.group(1) + re.sub(r"[, ]", "_", m.group(2))
        )
    if m := re.fullmatch(r"([+-]?\d+),(\d+)", value):  # 245,0
        return f"a TOML number has a decimal point, not a comma: {key} = {m[1]}.{m[2]}"
    if (m := _NUMBER.match(value)) and re.fullmatch(
        r"\s*[A-Za-z\u00b5\u03bc\u00b0%][\w/]*", unit := value[m.end() :]
    ):
        given, number = unit.strip(), m.group()
        if given.lower() in ("e", "e+", "e-"):  # an exponent without digits: no unit
            return ""
        if (mine := _unit(key)) is None:
            return f"a TOML number is the digits alone, without {given!r}"
        if given.replace("\u00b5", "u").replace("\u03bc", "u") == mine:
            return f"a number alone: the unit is in the key's name, {key} = {number}"
        return f"a number alone, in the unit the key's name gives ({mine}), not {given}"
    if value in ("True", "False", "TRUE", "FALSE"):
        return f"TOML writes true and false in lower case: {key} = {value.lower()}"
    if re.fullmatch(r"[+-]?\.\d+", value):
        return f"a TOML number has a digit before its point: {key} = {value.replace('.', '0.')}"
    if re.fullmatch(r"[+-]?0\d+", value):
        return f"a TOML integer has no leading zero: {key} = {int(value)}"
    if _BARE_WORD.fullmatch(value) and value.lower() not in ("true", "false", "inf", "nan"):
        return f'a text value is quoted in TOML: {key} = "{value}"'
    return ""


#: what a user of Python, JSON or NumPy writes for no value, for NaN and for infinity
_NULLS = ("None", "null", "NULL", "Null", "nil")
_SPECIAL = re.compile(r"([+-]?)(nan|inf|infinity)", re.I)


def _word_slip(line: str, col: int) -> str:
    """What is wrong with the bare word at column ``col`` (1-based) of ``line`` when it is
    ``NaN``, ``Inf`` (TOML writes ``nan``, ``inf``) or ``None``, ``null`` (TOML has no null),
    or ""; it was no hint (``x = NaN``) or "a text value is quoted" (``x = None``)."""
    m = re.match(r"[+-]?[A-Za-z_]\w*", line[col - 1 :] if col > 0 else "")
    word = m.group() if m else ""
    k = re.search(r"([\w\-]+|\"[^\"]*\")\s*=\s*$", line[: col - 1])
    key = k.group(1) if k else "x"
    if (special := _SPECIAL.fullmatch(word)) and word not in ("nan", "inf", "+nan", "-nan"):
        fixed = special[1] + ("nan" if special[2].lower() == "nan" else "inf")
        return f"TOML writes not-a-number and infinity in lower case, nan and inf: {key} = {fixed}"
    if word in _NULLS:
        return (
            f"TOML has no null: leave {key} out for no value (its default), or quote a "
            f'text: {key} = "{word}"'
        )
    return ""


def _opened(lines: list[str], before: int, mark: str) -> int | None:
    """The 1-based number of the last line before line ``before`` whose value opens with
    ``mark`` (``[`` a list, ``{`` an inline table), or None."""
    for k in range(min(before, len(lines)) - 1, -1, -1):
        short = len(lines[k]) <= LONGEST
        if short and (m := _KEY_VALUE.fullmatch(lines[k])) and m.group(2).startswith(mark):
            return k + 1
    return None


#: a TOML file's comments and strings, each whole (a one-line string's closing quote a group of
#: its own: absent, it is left open), matched by the regular-expression engine: one pass in C
_LEXED = re.compile(
    r"""\#[^\n]*
    |\"\"\"(?:\\.|[^\\])*?(?:\"\"\"|\\?\Z)
    |'''.*?(?:'''|\Z)
    |(?P<b>"(?:\\.|[^"\\\n])*)(?P<bc>")?
    |(?P<l>'[^'\n]*)(?P<lc>')?""",
    re.S | re.X,
)


def _left_open(text: str, quote: str) -> int | None:
    """The 1-based number of the first line of ``text`` that opens a one-line string of
    ``quote`` (``"`` or ``'``) and does not close it, outside comments and multi-line
    strings, or None. The count of ``'`` per line blamed a line before the slip for the
    apostrophe of a text in double quotes (``name = "Brown's plate"``). Its tokens are
    matched by :data:`_LEXED`, not character by character in Python: a study file of 16 MiB
    (the limit) took 10 s of CPU here, three times tomllib's own parse."""
    group, closer = ("b", "bc") if quote == '"' else ("l", "lc")
    for m in _LEXED.finditer(text):
        if m.group(group) is not None and m.group(closer) is None:
            return text.count("\n", 0, m.start()) + 1
    return None


def slip_hint(text: str, message: str, n: int, col: int) -> str:
    """`` (<the slip>: <the line as probably meant>)`` for tomllib's ``message`` on the study
    file ``text`` at line ``n``, column ``col`` (1-based; 0 when tomllib said "at end of
    document"), or ``""`` when the line shows none of the slips this module knows."""
    lines = text.split("\n")  # as tomllib counts lines
    if not n:  # at the end of the document: the last line that holds anything
        n = next((k + 1 for k in range(len(lines) - 1, -1, -1) if lines[k].strip()), 0)
        col = len(lines[n - 1]) + 1 if n else 0
        where = f"line {n}: " if n else ""
    else:
        where = ""
    line = lines[n - 1] if 0 < n <= len(lines) else ""
    if len(line) > LONGEST:
        return ""
    code = line.split("#", 1)[0].rstrip() if '"' not in line and "'" not in line else line
    words = ""
    kv = _KEY_VALUE.fullmatch(code)
    if message.startswith("Invalid value") and (words := _word_slip(line, col)):
        pass  # NaN, Inf, None: in a list or an inline table too
    elif message.startswith(("Invalid value", "Expected newline or end of document")) and kv:
        words = _value_slip(kv.group(1).strip(), kv.group(2).strip())
    elif message.startswith("Expected ']' at the end of a table") and "[" in line:
        words = f"a table's name is closed by ]: {code.strip()}]"
    elif message.startswith("Expected ']]' at the end of an array") and "[[" in line:
        words = f"an array of tables' name is closed by ]]: {code.strip().rstrip(']')}]]"
    elif message.startswith("Expected '=' after a key") and (key := line[: col - 1].strip()):
        rest = line[col - 1 :].lstrip(":").strip()
        if " " in key or not rest or "=" in rest:  # (a key with a space: "a b = 1")
            return ""
        words = f"TOML joins a key and its value with =: {key} = {rest}"
    elif message.startswith(("Unclosed array", "Unclosed inline table")):
        mark, close = ("[", "]") if "array" in message else ("{", "}")
        if (k := _opened(lines, n if where == "" else n + 1, mark)) is not None:
            return f" (the {'list' if mark == '[' else 'inline table'} opened at line {k} is not closed by {close})"
    elif message.startswith("Illegal character '\\n'") and line[: col - 1].count('"') % 2:
        words = 'the text opened on this line is not closed by "'
    elif message.startswith('Expected "\'"'):  # a literal string not closed: at the document's end
        k = _left_open(text, "'")
        return "" if k is None else f" (the text opened at line {k} is not closed by ')"
    return f" ({where}{words})" if words else ""
