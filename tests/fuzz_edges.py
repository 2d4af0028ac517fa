"""EDGE values, a mutation kind of the study-file fuzzer (tests/test_fuzz.py): a number that
keeps its key's type moved to the edge of the key's bounds or one step beyond, or to an edge
of floating point.

A bound itself (``lo``, ``hi``), one ulp inside and one ulp beyond it (``math.nextafter``; an
integer key: one beyond), ``-0.0``, the smallest subnormal and normal doubles, ``1 - eps`` and
``1 + eps``, the largest double; for an integer key ``2**53 + 1``, ``2**63 - 1``, and floats
written for it: ``1e2``, ``4.0``, ``9007199254740993.0`` (a float that holds no such integer).
A list key gets one element so moved; a network's record (a point, a grid, an observation) one
number field. A value beyond the key's bounds must be refused naming the key (the description
ends ``beyond its bounds``, and :func:`sim.mc.message_text.key_text` of the key comes before
it); every case keeps the fuzzer's contract (exit 0 with finite results, or one line).
"""

from __future__ import annotations

import math
import random
import sys

from fuzz_values import Raw

TINY, NORMAL, BIG = 5e-324, sys.float_info.min, sys.float_info.max
EPS = sys.float_info.epsilon
#: edges of floating point, for every number key
FLOATS = [-0.0, TINY, -TINY, NORMAL, 1 - EPS / 2, 1 + EPS, BIG, -BIG, 0.1 + 0.2]
#: edges of an integer key: 2**53 + 1 (no double holds it), 64-bit ends, floats written for it
INTS = [2**53, 2**53 + 1, 2**63 - 1, -(2**63), 0, -1]
INT_TEXTS = [Raw("1e2"), Raw("4.0"), Raw("9007199254740993.0"), Raw("2e0"), Raw("-0.0")]


def _bound_edges(f, as_int: bool) -> list[tuple[object, bool | None]]:
    """``(value, within the bounds)`` at the field's bounds: on them, a step in, a step out."""
    out: list[tuple[object, bool | None]] = []
    for b, down in ((f.lo, True), (f.hi, False)):
        if b is None or not math.isfinite(b):
            continue
        on = not (down and f.lo_open)
        if as_int:
            b = int(math.ceil(b) if down else math.floor(b))
            out += [(b, on or b != f.lo), (b - 1 if down else b + 1, False)]
            out += [(b + 1 if down else b - 1, True)]
        else:
            out += [(float(b), on)]
            out += [(math.nextafter(b, -math.inf if down else math.inf), False)]
            out += [(math.nextafter(b, math.inf if down else -math.inf), True)]
    return out


def _within(f, v) -> bool | None:
    if not isinstance(v, (int, float)) or isinstance(v, Raw) or math.isnan(v):
        return None
    if f.lo is not None and (v < f.lo or (f.lo_open and v == f.lo)):
        return False
    if f.hi is not None and v > f.hi:
        return False
    return True


def edge_of(rng: random.Random, f, old) -> tuple[object, bool | None]:
    """A value at an edge for the field ``f`` (its default ``old``), and whether it is within
    the field's bounds (None: it depends on more than the bounds, a float for an integer)."""
    as_int = f.kind in ("int", "list[int]")
    if rng.random() < 0.6 and (bounded := _bound_edges(f, as_int)):
        return rng.choice(bounded)
    if as_int:
        v = rng.choice(INTS + INT_TEXTS)
        return v, (None if isinstance(v, Raw) else _within(f, v))
    v = rng.choice(FLOATS)
    return v, _within(f, v)


def edge_case(rng: random.Random, flat: dict, schema) -> tuple[str, object, bool | None]:
    """``(key, value, within)``: ``flat`` (changed in place) with one number at an edge; the
    key is the schema key (a list's or a record's too), ``within`` as :func:`edge_of`."""
    nums = [
        k
        for k, f in schema.items()
        if f.kind in ("int", "float", "list[int]", "list[float]") and k in flat
    ]
    records = [
        k
        for k, f in schema.items()
        if f.kind == "records" and isinstance(flat.get(k), list) and flat[k]
    ]
    if records and rng.random() < 0.5:  # a network's record: bounds are the study's check
        k = rng.choice(records)
        i = rng.randrange(len(flat[k]))
        rec = dict(flat[k][i])
        fields = [n for n, x in rec.items() if isinstance(x, (int, float, list))]
        if fields:
            n = rng.choice(fields)
            x = rec[n]
            if isinstance(x, list) and x:
                j = rng.randrange(len(x))
                rec[n] = x[:j] + [rng.choice(FLOATS)] + x[j + 1 :]
            elif isinstance(x, int) and not isinstance(x, bool):
                rec[n] = rng.choice(INTS + INT_TEXTS)
            else:
                rec[n] = rng.choice(FLOATS)
            flat[k] = flat[k][:i] + [rec] + flat[k][i + 1 :]
            return f"{k}[{i}].{n}", rec[n], None
    k = rng.choice(nums)
    f = schema[k]
    old = flat[k]
    v, within = edge_of(rng, f, old)
    if isinstance(old, list) and old:
        j = rng.randrange(len(old))
        flat[k] = old[:j] + [v] + old[j + 1 :]
    else:
        flat[k] = v
    return k, v, within
