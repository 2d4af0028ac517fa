"""Which key a study file gives twice, for the "malformed TOML" refusal
(:func:`sim.mc.config.read_toml`): tomllib says ``Cannot overwrite a value (at line 3, column
11)`` for ``trials = 5`` then ``trials = 6``, naming no key, and ``Cannot declare ('plate',)
twice`` (a Python tuple) for a table given twice. The line is now ``trials is given twice (at
line 3, column 11)``; when the two differ in kind, which they are (``plate is given twice (a
value, then a table)``).
A file whose last line, with no line break after it, gives the key again is told
"(at end of document)" by tomllib, no line: named too (``trials is given twice (at line 4,
the end of the file)``), no longer left as tomllib's words.

The statement at fault is found by TOML itself: it begins at the last line start at or before
the error's line whose text before it reads as TOML (a statement that spans lines, an array
or a multi-line string, leaves the text before its later lines unread); its key is read by
TOML from the text before its ``=`` (or its ``[header]``), and the table it is in by reading
the text before it with a probe key added.
"""

from __future__ import annotations

import ast
import re
import tomllib
from typing import Any

from sim.mc.message_text import key_text

__all__ = ["twice_text"]

_AT = re.compile(r"(.*) \(at line (\d+), column (\d+)\)", re.S)
#: the words of a file whose last statement, with no line break after it, is at fault
_END = re.compile(r"(.*) \(at end of document\)", re.S)
_NAMED = re.compile(r"Cannot (?:declare|redefine namespace|mutate immutable namespace) (\(.*?\))")
#: a key no study file holds: where it lands is the table a statement is in
_PROBE = "sim probe 5f0c"
#: lines looked back for a statement's start, characters read in all, and the largest file
#: so read (a longer multi-line value, a larger file: tomllib's words, not a minute of parsing)
_BACK, _BUDGET, _LARGEST = 400, 1_000_000, 256_000


def twice_text(text: str, message: str) -> str | None:
    """``message`` (tomllib's, for ``text``) with the key given twice named, or None when it
    is no such message or the key cannot be told."""
    at, end = _AT.fullmatch(message), _END.fullmatch(message)
    if at:
        reason, line, where = at.group(1), int(at.group(2)), f" (at line {at[2]}, column {at[3]})"
    elif end:  # the last statement, no line break after it: tomllib gives no line
        line = text.count("\n") + 1
        reason, where = end.group(1), f" (at line {line}, the end of the file)"
    else:
        return None
    if len(text) > _LARGEST or not reason.startswith(("Cannot ", "Duplicate inline table key")):
        return None
    try:
        return _named(text, reason, line, where)
    except (tomllib.TOMLDecodeError, ValueError, SyntaxError, RecursionError, IndexError):
        return None


def _named(text: str, reason: str, line: int, where: str) -> str | None:
    lines = text.split("\n")  # as tomllib counts lines
    starts = [0]
    for ln in lines:
        starts.append(starts[-1] + len(ln) + 1)
    before, budget = None, _BUDGET
    for i in range(line - 1, max(-1, line - 1 - _BACK), -1):
        budget -= starts[i]
        if budget < 0:
            return None
        try:
            before = tomllib.loads(text[: starts[i]])
            break
        except tomllib.TOMLDecodeError:
            continue
    if before is None:
        return None
    stmt = lines[i].strip()
    if stmt.startswith("["):  # a header: its key is absolute
        doc = tomllib.loads(lines[i].rstrip("\r"))  # a CRLF file
        path, second = _path(doc), "an array of tables" if stmt.startswith("[[") else "a table"
    else:
        rel = _key_of(lines[i])
        if rel is None:
            return None
        head = _where(tomllib.loads(text[: starts[i]] + f'\n"{_PROBE}" = 0\n'))
        if head is None:
            return None
        if m := re.fullmatch(r"Duplicate inline table key ('.*')", reason):
            stem = ast.literal_eval(m.group(1))
            at = starts[line - 1] + int(where.split("column ")[-1].rstrip(")")) - 1
            try:
                inner = _inline_key(text[starts[i] : at], _key_end(lines[i]))
            except (tomllib.TOMLDecodeError, IndexError):  # not told: the words below
                inner = None
            if inner is None:  # the inline table named, its key by its last part
                inline = key_text(".".join(head + rel))
                return f"{key_text(stem)} is given twice in the inline table of {inline}{where}"
            return f"{_dotted(head + rel, inner)} is given twice in an inline table{where}"
        path, second = head + rel, "a value"
    named = _NAMED.match(reason)
    if named and stmt[:1] != "[":  # {x = {a = 1}, x = 2}: x named from its inline table
        key = list(ast.literal_eval(named.group(1)))
        if (inline := _inline_prefix(text, lines[i], starts, (i, line), where, key)) is not None:
            shown = _dotted(head + rel, [*inline, key[0]])
            return f"{shown} is given twice in an inline table{where}"
    target = list(ast.literal_eval(named.group(1))) if named else _first_taken(before, path)
    if target is None:
        return None
    if target != path:
        second = "a table"  # dotted keys or a header below the key given before
    first = _kind(before, target)
    while first is None and len(target) > 1 and named:  # [a.b.c] below an inline array a.b:
        target = target[:-1]  # a.b given again, as a table
        first, second = _kind(before, target), "a table"
    if first is None:  # a key inside the statement's own inline table: tomllib's words
        return None
    tables = ("a table", "an array of tables")
    differ = first != second and (first in tables or second in tables)  # not two values
    both = f" ({first}, then {second})" if differ else ""
    return f"{_shown(before, target)} is given twice{both}{where}"


def _key_end(line: str) -> int | None:
    """Where the ``=`` after the key of the statement beginning ``line`` stands."""
    for m in re.finditer("=", line):
        try:
            tomllib.loads(line[: m.start()] + "= 0")
            return m.start()
        except tomllib.TOMLDecodeError:
            continue
    return None


def _inline_key(src: str, eq: int | None) -> list | None:
    """The key given twice in an inline value, as parts below the statement's key (a part
    ``[k]``: the array's item ``k``), read from ``src``, the statement up to tomllib's error
    (just after the second value of that key), its ``=`` at ``eq``; None when it cannot be
    told. tomllib names the key by its last part only: ``plate = {x = {a = 1, a = 2}}`` was
    "a is given twice in the inline table of plate"."""
    if eq is None:
        return None
    stack: list[list] = []  # [table parts, key from, last key] or ["[]", item index]
    path: list = []  # the parts down to the innermost frame
    i, n = eq + 1, len(src)
    while i < n:
        c = src[i]
        if c in "\"'":  # a string (a quoted key too): skipped whole
            q = c * 3 if src.startswith(c * 3, i) else c
            j = i + len(q)
            while j < n and not src.startswith(q, j):
                j += 2 if c == '"' and src[j] == "\\" else 1
            i = j + len(q)
            continue
        top = stack[-1] if stack else None
        if c == "#":
            j = src.find("\n", i)  # a comment between an array's lines
            i = n if j < 0 else j
            continue
        if c == "=" and top and top[0] != "[]":
            top[2] = _path(tomllib.loads(src[top[1] : i] + "= 0"))
        elif c in "{[":
            name = (top[2] if top[0] != "[]" else [f"[{top[1]}]"]) if top else []
            path.append(name)
            stack.append(["[]", 0] if c == "[" else [name, i + 1, None])
        elif c in "}]" and stack:
            stack.pop()
            path.pop()
        elif c == "," and top:
            if top[0] == "[]":
                top[1] += 1
            else:
                top[1] = i + 1
        i += 1
    if not stack or stack[-1][0] == "[]" or not stack[-1][2]:
        return None
    return [p for part in path for p in part] + stack[-1][2]


def _inline_prefix(text, stmt: str, starts, lines: tuple, where: str, key: list) -> list | None:
    """The inline table (parts below the statement's key, an array's item as ``[k]``) in
    which ``key``, tomllib's error of the statement at line ``lines[0]`` (the error at line
    ``lines[1]``), was given; None when it cannot be told (not an inline table's key)."""
    col = where.split("column ")[-1].rstrip(")") if "column " in where else None
    # (at end of document): the error is at the text's end (int() raised: tomllib's words)
    at = len(text) if col is None else starts[lines[1] - 1] + int(col) - 1
    try:
        inner = _inline_key(text[starts[lines[0]] : at], _key_end(stmt))
    except (tomllib.TOMLDecodeError, IndexError):
        return None
    if inner is None or len(inner) < len(key) or inner[len(inner) - len(key) :] != key:
        return None
    return inner[: len(inner) - len(key)]


def _shown(doc: Any, path: list[str]) -> str:
    """``path`` named with the item of each array of tables it passes (its last, where the
    keys go: ``network.grids[1].spacing_mm``, not ``network.grids.spacing_mm``)."""
    out: list = []
    for j, k in enumerate(path):
        doc = _last(doc)
        nxt = doc.get(k) if isinstance(doc, dict) else None
        out.append(k)
        if j < len(path) - 1 and isinstance(nxt, list) and nxt and isinstance(nxt[-1], dict):
            out.append(f"[{len(nxt) - 1}]")
        doc = nxt
    return _dotted([out[0]], out[1:])


def _dotted(head: list[str], inner: list) -> str:
    """``network.grids[0].origin_mm``: the key's parts, an array's item after its key."""
    out = key_text(".".join(head))
    for p in inner:
        out += p if p.startswith("[") else f".{key_text(p)}"
    return out


def _path(doc: Any) -> list[str]:
    """The key path of a document of one statement (``{"a": {"b": {}}}``: ``[a, b]``)."""
    out = []
    while isinstance(doc, dict) and len(doc) == 1:
        (k, doc), *_ = doc.items()
        out.append(k)
        if isinstance(doc, list) and doc:
            doc = doc[-1]
    return out


def _key_of(line: str) -> list[str] | None:
    """The key path of the key/value statement that begins ``line``, read by TOML: the text
    before the first ``=`` that ends a key (a quoted key may hold ``=``)."""
    for m in re.finditer("=", line):
        try:
            return _path(tomllib.loads(line[: m.start()] + "= 0"))
        except tomllib.TOMLDecodeError:
            continue
    return None


def _where(doc: Any, path: tuple = ()) -> list[str] | None:
    """The table path at which :data:`_PROBE` lies in ``doc`` (an array of tables: its last)."""
    if isinstance(doc, list):
        return _where(doc[-1], path) if doc and isinstance(doc[-1], dict) else None
    if not isinstance(doc, dict):
        return None
    if _PROBE in doc:
        return list(path)
    for k, v in reversed(doc.items()):  # the table opened last was added last
        found = _where(v, (*path, k))
        if found is not None:
            return found
    return None


def _first_taken(doc: Any, path: list[str]) -> list[str] | None:
    """The shortest part of ``path`` that ``doc`` already holds as no table (a value, an
    array), else ``path`` itself when ``doc`` holds it."""
    for j, k in enumerate(path):
        doc = _last(doc)
        if not isinstance(doc, dict) or k not in doc:
            return None
        doc = doc[k]
        if j < len(path) - 1 and not isinstance(_last(doc), dict):
            return path[: j + 1]
    return path


def _last(doc: Any) -> Any:
    """``doc``, or the last table of an array of tables (where its keys go)."""
    return doc[-1] if isinstance(doc, list) and doc and isinstance(doc[-1], dict) else doc


def _kind(doc: Any, path: list[str]) -> str | None:
    """What ``doc`` holds at ``path``: a table, an array (of tables) or a value."""
    for k in path:
        doc = _last(doc)
        if not isinstance(doc, dict) or k not in doc:
            return None
        doc = doc[k]
    if isinstance(doc, dict):
        return "a table"
    if isinstance(doc, list):
        return "an array of tables" if doc and all(isinstance(x, dict) for x in doc) else "an array"
    return "a value"
