"""SWEEP LEVELS, a mutation kind of the study-file fuzzer (tests/test_fuzz.py): a small valid
``[sweep]`` table of one study (two levels of one of its keys, sometimes a second key or
``replicates``) with one mutation at its levels.

TYPE: a level of the wrong TOML type (tests/fuzz_values.py's ``TYPED``), the whole value a
scalar, a string or a table, a range whose ``start``, ``stop``, ``num`` or ``step`` is of the
wrong type or not finite; EMPTY: ``[]``, ``{}``, an empty ``[sweep.<table>]``; DUPLICATED: a
level given twice, as written or as another spelling of one number (``4`` and ``4.0``, ``0.5``
and ``5e-1``), or a range that repeats its start; NO KEY: the key respelt (tests/fuzz_keys.py),
cut to its table, given a leaf no study has, or given twice (quoted and in a table); an ITEM
of a list-valued key by its index (``network.points[0].x_mm``, ``dilution.grids.0``); HUGE:
level counts over the cells' bound (a ``num``, a ``step``, a product of two keys, replicates),
and, with ``huge_work``, a range of up to 10,000 cells against a lowered work limit.

Each case is ``sim check`` of the file: exit 0, or exit 2 in one line; a mutation that cannot
be a sweep (all but TYPE and the huge work) must be refused naming the key as written
(``sweep.<key>``, :func:`sim.mc.message_text.key_text`), a TYPE mutation refused names it too.
"""

from __future__ import annotations

import json
import random

from fuzz_keys import _respelt_part
from fuzz_values import TYPED, Raw, toml_key, toml_value

from sim.mc.config import Field
from sim.mc.message_text import key_text

KINDS = ["type", "empty", "duplicate", "nokey", "item", "huge"]


def _levels(f: Field, v) -> list | None:
    """Two distinct levels of key ``f`` at value ``v`` within its bounds (None: no such)."""

    def inside(x) -> bool:
        return (f.lo is None or x > f.lo or (x == f.lo and not f.lo_open)) and (
            f.hi is None or x <= f.hi
        )

    if f.kind == "bool" and isinstance(v, bool):
        return [v, not v]
    if f.kind in ("int", "float") and isinstance(v, (int, float)) and not isinstance(v, bool):
        steps = [1, -1] if f.kind == "int" else [v * 0.25 or 1.0, -(v * 0.2) or -0.5]
        for d in steps:
            if inside(v + d):
                return [v, v + d]
        return None
    if f.kind == "str" and isinstance(v, str):
        other = [c for c in f.choices or () if c != v]
        return [v, other[0]] if other else None
    if f.kind.startswith("list[") and isinstance(v, list) and len(v) > max(f.min_len, 1):
        return [v, v[:-1]]
    return None


def _dup(rng: random.Random, x):
    """``x`` again, as written or in another spelling of the same number."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return x
    if isinstance(x, int):
        return rng.choice([x, float(x), Raw(f"{x}.0"), Raw(f"{x}e0")])
    return rng.choice([x, Raw(f"{x!r}".replace("e", "E")), Raw(f"{x:.17e}")])


def _lines(sweep: dict, tables: bool) -> list[str]:
    """``[sweep]`` and its entries: quoted dotted keys, or each key in its table."""
    if not tables:
        return ["[sweep]"] + [f"{toml_key(k)} = {toml_value(v)}" for k, v in sweep.items()]
    out, heads = ["[sweep]"], {}
    for k, v in sweep.items():
        head, _, leaf = k.rpartition(".")
        if head:
            heads.setdefault(head, []).append(f"{toml_key(leaf)} = {toml_value(v)}")
        else:
            out.append(f"{toml_key(k)} = {toml_value(v)}")
    for head, body in heads.items():
        out += [f"[sweep.{'.'.join(toml_key(p) for p in head.split('.'))}]", *body]
    return out


def sweep_case(rng: random.Random, flat: dict, schema: dict, huge_work=False, kind=None):
    """``(lines, description, needle, environment, key)``: the ``[sweep]`` table's lines for
    ``flat``'s study file, mutated; the one-line refusal must hold ``needle`` (None: exit 0,
    or a refusal naming ``key``), under the variables ``environment`` sets; ``kind`` one of
    :data:`KINDS` (default: drawn)."""
    keys = [
        k
        for k, f in schema.items()
        if isinstance(f, Field) and f.sweep is None and f.read_when is None and k in flat
        if k not in ("trials", "chunk", "seed") and _levels(f, flat[k])
    ]
    k = rng.choice(keys)
    sweep: dict = {k: _levels(schema[k], flat[k])}
    if rng.random() < 0.3 and len(keys) > 1:  # a second key: four cells
        k2 = rng.choice([x for x in keys if x != k])
        sweep[k2] = _levels(schema[k2], flat[k2])
    if rng.random() < 0.2:
        sweep["replicates"] = 2
    kind = kind or rng.choice(KINDS + ["huge"] * huge_work)
    name, env = f"sweep.{k}", {}
    levels = sweep[k]
    if kind == "type":
        what = rng.choice(["level", "level", "scalar", "range"])
        if what == "level":
            i = rng.randrange(len(levels))
            sweep[k] = levels[:i] + [rng.choice(TYPED)] + levels[i + 1 :]
        elif what == "scalar":
            sweep[k] = rng.choice([levels[0], str(levels[0]), Raw("{a = 1}"), True, Raw("[[]]")])
        else:
            bad = rng.choice([Raw('"1"'), Raw("nan"), Raw("inf"), True, Raw("[1]"), Raw("{}")])
            sweep[k] = {"start": 1, "stop": 2, "num": 2}
            sweep[k][rng.choice(["start", "stop", "num"])] = bad
        desc = f"{k} = {toml_value(sweep[k])[:80]}"
        return _lines(sweep, rng.random() < 0.5), f"type: {desc}", None, env, name
    needle = name
    if kind == "empty":
        what = rng.choice(["[]", "{}", "table"])
        lines = _lines({**sweep, k: [] if what == "[]" else {}}, rng.random() < 0.5)
        if what == "table":  # an empty [sweep.<head>] beside the sweep
            head = k.rpartition(".")[0] or "extra"
            lines = _lines({x: v for x, v in sweep.items() if x != k} or {"replicates": 2}, False)
            lines += [f"[sweep.{head}]"]
            needle = f"sweep.{head}"
        desc = f"empty {what}"
    elif kind == "duplicate":
        what = rng.choice(["level", "range"])
        if what == "range" and schema[k].kind in ("int", "float"):
            a = levels[0]
            sweep[k] = {"start": a, "stop": a, "num": rng.choice([2, 3])}
        else:
            i = rng.randrange(len(levels))
            sweep[k] = levels + [_dup(rng, levels[i])]
        lines, desc = _lines(sweep, rng.random() < 0.5), f"{k} = {toml_value(sweep[k])[:80]}"
    elif kind == "nokey":
        parts = k.split(".")
        what = rng.choice(["respelt", "table", "leaf", "twice"])
        if what == "respelt":
            j = rng.randrange(len(parts))
            parts[j] = _respelt_part(rng, parts[j])[0]
        elif what == "table" and len(parts) > 1:
            parts = parts[:-1]
        elif what == "twice" and len(parts) > 1:  # quoted and in its table
            head = ".".join(toml_key(p) for p in parts[:-1])
            lines = _lines(sweep, False) + [f"[sweep.{head}]", f"{toml_key(parts[-1])} = [1]"]
            return lines, f"nokey: {k} twice", name, env, name
        else:
            parts = parts + [rng.choice(["value", "x_mm", "0", "num"])]
        written = ".".join(parts)
        sweep = {(written if x == k else x): v for x, v in sweep.items()}
        lines = ["[sweep]"] + [
            f"{json.dumps(x, ensure_ascii=False)} = {toml_value(v)}" for x, v in sweep.items()
        ]
        needle, desc = key_text(f"sweep.{written}"), f"{what} {written!r}"
    elif kind == "item":
        lists = [x for x, f in schema.items() if isinstance(f, Field) and f.kind != "str"]
        lists = [
            x for x in lists if schema[x].kind in ("records", "points") or "list" in schema[x].kind
        ]
        x = rng.choice(lists)
        form = rng.choice(["[0]", "[0].x_mm", ".0", ".0.sigma_mm", "[-1]", "[99]"])
        written = x + form
        sweep = {written: [1.0, 2.0], **{y: v for y, v in sweep.items() if y != x}}
        lines = ["[sweep]"] + [
            f"{json.dumps(y, ensure_ascii=False)} = {toml_value(v)}" for y, v in sweep.items()
        ]
        needle, desc = key_text(f"sweep.{written}"), f"item {written}"
    else:  # huge level counts: over the cells' bound, or (huge_work) under it and its work
        what = rng.choice(["num", "step", "product", "replicates"] + ["work"] * huge_work)
        if what == "work":  # within the cells' bound: refused by the work limit it sets
            n = rng.choice([300, 2_000, 10_000])
            sweep = {k: levels, "replicates": n // len(levels)}
            env = {"SIM_MAX_ADJUSTMENTS": "1e6"}
            desc = f"{n} cells against a work limit of 1e6"
            return _lines(sweep, False), f"huge: {desc}", "adjustments", env, "sweep"
        if what == "num":
            sweep[k] = {"start": 0, "stop": 1, "num": rng.choice([10_001, 10**6, 2**63 - 1])}
        elif what == "step":
            sweep[k] = {"start": 0.0, "stop": 1.0, "step": rng.choice([1e-5, 1e-300, 5e-324])}
        elif what == "product":
            sweep[k] = list(range(101)) if schema[k].kind == "int" else [i / 7 for i in range(101)]
            k2 = next((x for x in keys if x != k), None)
            if k2 is None:
                sweep["replicates"] = 100
            else:
                sweep[k2] = [i / 9 for i in range(101)]
            needle = "sweep"
        else:
            sweep["replicates"] = rng.choice([5_001, 10_001, 10**9])
            needle = "sweep"
        lines, desc = _lines(sweep, rng.random() < 0.5), f"{what}: {toml_value(sweep)[:80]}"
    return lines, f"{kind}: {desc}", needle, env, name
