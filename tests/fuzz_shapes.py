"""SHAPE, a mutation kind of the study-file fuzzer (tests/test_fuzz.py): a valid study file
written in another TOML shape, the same document or a table given twice.

The same document: a table written inline (``plate = { grid = 5, ... }``), a list of records
as an array of tables (``[[network.points]]``), a table's keys dotted under another table's
header's neighbour (``[plate]`` then ``comparator.alpha_mm = ...`` at the top). Such a case
must run as the file does (exit 0: the description ends ``the same document``).

A table given twice: by dotted keys and then by a header (``plate.grid = 5`` then ``[plate]``),
inline and then by dotted keys or a header, or the study's name as a table or an array of
tables (``study = { name = "..." }``, ``[[study]]``). Such a case must be refused naming the
table (the description ends with it)."""

from __future__ import annotations

import random

from fuzz_values import toml_key, toml_tables, toml_value

SAME = "the same document"


def _tables(flat: dict) -> dict[str, dict]:
    """``flat``'s keys by table (``""``: the top level), each with its leaves."""
    out: dict[str, dict] = {}
    for k, v in flat.items():
        head, _, leaf = k.rpartition(".")
        out.setdefault(head, {})[leaf] = v
    return out


def _inline(body: dict) -> str:
    return "{ " + ", ".join(f"{k} = {toml_value(v)}" for k, v in body.items()) + " }"


def shape_case(rng: random.Random, flat: dict) -> tuple[str, str]:
    """``(document, description)``: ``flat`` (a valid study file's keys) in another shape."""
    tables = _tables(flat)
    heads = [h for h in tables if h]
    top = [f"{k} = {toml_value(v)}" for k, v in tables.get("", {}).items()]
    what = rng.choice(["inline", "aot", "dotted_then_header", "inline_then_more", "study"])
    head = rng.choice(heads)
    body = tables[head]
    others = [ln for h in heads if h != head for ln in _lines(h, tables[h])]
    if what == "inline" and "." not in head:  # plate = { ... } at the top
        return "\n".join([*top, f"{head} = {_inline(body)}", *others]) + "\n", f"inline {SAME}"
    records = [(k, v) for k, v in flat.items() if _records(v)]
    if what == "aot" and records:  # [[network.points]] for points = [ {...}, ... ]
        k, v = rng.choice(records)
        lines = toml_tables({x: w for x, w in flat.items() if x != k})
        for rec in v:
            lines += [f"[[{k}]]", *(f"{toml_key(f)} = {toml_value(x)}" for f, x in rec.items())]
        return "\n".join(lines) + "\n", f"aot {k} {SAME}"
    if what == "study":
        form = rng.choice(
            ['study = { name = "x" }', "[[study]]", "[study]", 'study = ["x"]', "study = []"]
        )
        rest = [ln for ln in toml_tables(flat) if not ln.startswith("study =")]
        return "\n".join([form, *rest]) + "\n", "study shape study"
    (leaf, v), *more = body.items()
    if what == "inline_then_more" and "." not in head:  # plate = { grid = 5 } then more of it
        later = [f"{head}.{k} = {toml_value(x)}" for k, x in more] or [f"[{head}]"]
        doc = [*top, f"{head} = {_inline({leaf: v})}", *later, *others]
        return "\n".join(doc) + "\n", f"inline then more {head}"
    # plate.grid = 5 at the top, then [plate] with its other keys (or empty)
    doc = [*top, f"{head}.{leaf} = {toml_value(v)}", *others, f"[{head}]"]
    doc += [f"{k} = {toml_value(x)}" for k, x in more]
    return "\n".join(doc) + "\n", f"dotted then header {head}"


def _lines(head: str, body: dict) -> list[str]:
    return [f"{head}.{k} = {toml_value(v)}" for k, v in body.items()]


def _records(v) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) and x for x in v)
