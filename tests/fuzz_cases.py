"""The fuzzer's cases (tests/test_fuzz.py): case ``i`` of seed ``FUZZ_SEED`` is one study's
tiny file (tests/fuzz_values.py) with one mutation of a kind drawn by the seed: VALUE, two
values, a ``--set``, STRUCTURE, a ``[sweep]``, an option, a key in the wrong place
(``relocate``), TYPE, KEY spelling (tests/fuzz_keys.py), EDGE values (tests/fuzz_edges.py), SHAPE
(tests/fuzz_shapes.py), BYTES of the file (tests/fuzz_bytes.py), SPLICE of two studies' files
(tests/fuzz_splice.py)."""

from __future__ import annotations

import json
import os
import random

from fuzz_bytes import bytes_case
from fuzz_edges import edge_case
from fuzz_keys import respell
from fuzz_shapes import shape_case
from fuzz_splice import splice_case
from fuzz_values import (
    NAMES,
    NAN,
    ROOT,
    TYPED,
    Raw,
    base,
    mutate_value,
    toml_tables,
    toml_value,
)

from sim.studies import load_study

SEED = int(os.environ.get("FUZZ_SEED", "13"))


def relocate(rng: random.Random, flat: dict, schema: list[str]) -> tuple[bytes, str]:
    """A well-formed key in the wrong place: moved into another table or to the top level,
    its table given as an array of tables or declared twice, the key itself a table array."""
    k = rng.choice([s for s in schema if "." in s and s in flat] or list(flat))
    head, _, leaf = k.rpartition(".")
    heads = sorted({s.rpartition(".")[0] for s in flat if "." in s} - {head})
    what = rng.choice(["moved", "top", "aot_table", "dup_table", "aot_key"])
    if what == "moved" and heads:
        to = rng.choice(heads)
        return "\n".join(toml_tables(flat, {k: to})).encode() + b"\n", f"{k} moved to [{to}]"
    if what in ("moved", "top"):
        return "\n".join(toml_tables(flat, {k: ""})).encode() + b"\n", f"{k} moved to the top"
    lines = toml_tables(flat)
    if what == "aot_key":
        lines = toml_tables({x: v for x, v in flat.items() if x != k})
        lines += [f"[[{k}]]", f"{leaf} = {toml_value(flat[k])}"]
    elif head and what == "aot_table":
        lines = [f"[[{head}]]" if ln == f"[{head}]" else ln for ln in lines]
    elif head:  # the table declared twice (malformed TOML)
        lines += [f"[{head}]", f"{leaf} = {toml_value(flat[k])}"]
    return "\n".join(lines).encode() + b"\n", f"{what} {k}"


def make_case(i: int):
    """``(name, flat config, sweep or None, extra argv, description, raw text or None)``."""
    rng = random.Random(SEED * 100_003 + i)
    name = NAMES[i % len(NAMES)]
    flat = base(name)
    fields = load_study(ROOT / "studies" / f"{name}.toml")[0].schema
    schema = list(fields)
    extra: list[str] = []
    sweep = None
    raw = None
    kind = rng.choice(
        ["value"] * 5
        + ["two"] * 2
        + ["set", "structure", "sweep", "option", "relocate"]
        + ["type"] * int(os.environ.get("FUZZ_TYPE_WEIGHT", "2"))
        + ["key"] * int(os.environ.get("FUZZ_KEY_WEIGHT", "2"))
        + ["edge"] * int(os.environ.get("FUZZ_EDGE_WEIGHT", "2"))
        + ["shape"] * int(os.environ.get("FUZZ_SHAPE_WEIGHT", "1"))
        + ["bytes"] * int(os.environ.get("FUZZ_BYTES_WEIGHT", "2"))
        + ["splice"] * int(os.environ.get("FUZZ_SPLICE_WEIGHT", "2"))
    )
    if kind in ("value", "two"):
        keys = rng.sample(schema, 2 if kind == "two" else 1)
        for k in keys:
            flat[k] = mutate_value(rng, flat.get(k, 1.0))
        desc = ", ".join(f"{k}={toml_value(flat[k])[:60]}" for k in keys)
    elif kind == "set":
        k = rng.choice(schema)
        text = rng.choice(
            [
                toml_value(mutate_value(rng, flat.get(k, 1.0))),
                "[1, 2",
                "{a = 1}",
                "nan",
                "",
                "'π'",
                "0x10",
                "1e999",
                "[[]]",
            ]
        )
        extra += ["--set", f"{k}={text}"]
        desc = f"--set {k}={text[:60]}"
    elif kind == "structure":
        what = rng.choice(
            [
                "unknown",
                "study",
                "nostudy",
                "garbage",
                "empty",
                "unicode_key",
                "table_for_value",
                "huge_list",
            ]
        )
        desc = what
        if what == "unknown":
            flat["bogus.key"] = 1
        elif what == "study":
            flat["study"] = rng.choice(["nope", 3, "", "brown_table1 ", "π"])
        elif what == "nostudy":
            flat.pop("study")
        elif what == "garbage":
            raw = bytes(rng.randrange(256) for _ in range(200))
        elif what == "empty":
            raw = b""
        elif what == "unicode_key":
            flat["plate.grïd"] = 5
        elif what == "table_for_value":
            flat[rng.choice(schema)] = {"a": 1}
        else:
            flat[rng.choice(schema)] = [1.0] * 100_000
    elif kind == "type":  # a value of the wrong TOML type, or a list with one such element
        k = rng.choice(schema)
        old, lit = flat.get(k), rng.choice(TYPED)
        if isinstance(old, list) and old and rng.random() < 0.5:
            i = rng.randrange(len(old))
            flat[k] = old[:i] + [lit] + old[i + 1 :]
        elif isinstance(old, (int, float)) and rng.random() < 0.3:
            flat[k] = Raw(json.dumps(str(old)))  # the right number as a string
        else:
            flat[k] = lit
        desc = f"{k}={toml_value(flat[k])[:60]}"
    elif kind == "edge":  # the description ends with the key a refusal must name, if beyond
        k, v, within = edge_case(rng, flat, fields)
        desc = f"{k} = {toml_value(v)[:60]}" + " beyond its bounds" * (within is False)
    elif kind == "shape":  # the description ends "the same document" or the table named
        text, desc = shape_case(rng, flat)
        raw = text.encode()
    elif kind == "bytes":  # the description ends with the mutation (fuzz_bytes.SAME: runs)
        raw, desc = bytes_case(rng, "\n".join(toml_tables(flat)) + "\n")
    elif kind == "splice":  # the description ends ": must name ..." when it must be refused
        text, desc = splice_case(rng, name, flat, fields)
        raw = text.encode()
    elif kind == "relocate":
        raw, desc = relocate(rng, flat, schema)
    elif kind == "key":  # the last word of desc: the key the refusal must name
        text, desc, opts = respell(rng, flat, toml_value, toml_tables)
        raw, extra = text.encode(), extra + opts
    elif kind == "sweep":
        k = rng.choice(schema)
        rngv = rng.choice(
            [
                {"start": 1.0, "stop": NAN, "num": 2},
                {"start": "a", "stop": 2, "num": 2},
                {"start": 1.0, "stop": 2.0, "step": 1e-12},
                {"start": 1, "stop": 2, "num": 5_000_000},
                {"start": 1, "stop": 2, "num": 2},
                {"start": 0.5, "stop": 1.5, "step": 0.5},
                [flat.get(k, 1), mutate_value(rng, flat.get(k, 1))],
                [],
                {"start": 1},
            ]
        )
        sweep = {k: rngv}
        if rng.random() < 0.3:
            sweep["replicates"] = rng.choice([0, 2, 3_000_000, "x"])
        desc = f"[sweep] {k} = {toml_value(rngv)[:80]}"
    else:
        opt = rng.choice(
            [
                ["--trials", rng.choice(["0", "-1", "2.5", "abc", "1000000000", "1"])],
                ["--seed", rng.choice(["-1", str(2**70), "x", "0"])],
                ["--workers", rng.choice(["0", "-3", "1000000", "two"])],
                ["--scheduler", rng.choice(["foo", "tcp://", "tcp://h:99999", ""])],
                ["--max-memory-gb", rng.choice(["0", "nan", "-1", "1e-9"])],
                ["--out", rng.choice(["", "/", ".", "{file}", "π☃/ü", "x" * 300])],
            ]
        )
        extra += opt
        desc = " ".join(opt)[:80]
    return name, flat, sweep, extra, f"{name}: {kind}: {desc}", raw
