"""KEY spelling, a mutation kind of the study-file fuzzer (tests/test_fuzz.py): one key of a
valid study file spelt as no key of its study is, or given twice through two spellings.

A key (or one part of a dotted key, or ``study``) in another case; one ASCII letter replaced
by a Cyrillic or Greek letter drawn the same; white space or a character that does not print
at its end, its start or inside (a space, a tab, a no-break space, a zero-width space or
joiner, a soft hyphen, a byte-order mark), in a quoted key; ``_`` written ``-``, doubled or
dropped; the key given twice (``"plate.grid" = 5`` beside ``[plate] grid = 5``, or
``trials = 4`` beside ``"trials" = 4``); a ``--set`` of a key so spelt. A study reads its keys
by their exact spelling, so each such file must be refused: exit 2, one line that names the
key as written (:func:`sim.mc.message_text.key_text`, the suite's one way of showing a key);
exit 0 would be a key read in place of another or dropped without a word.
"""

from __future__ import annotations

import json
import random

from sim.mc.message_text import key_text

#: a Cyrillic or Greek letter drawn as the ASCII one
LOOKALIKE = {"a": "а", "c": "с", "e": "е", "i": "і", "o": "о", "p": "р", "x": "х", "y": "у"}
#: white space and characters that do not print, put into a quoted key
INVISIBLE = [" ", "\t", "\u00a0", "\u200b", "\u200d", "\u00ad", "\ufeff", "\u3000"]


def _quoted(part: str) -> str:
    """``part`` as one TOML key: bare when it can be, else a basic string."""
    bare = part and all(c.isascii() and (c.isalnum() or c in "_-") for c in part)
    return part if bare else json.dumps(part, ensure_ascii=False)


def _respelt_part(rng: random.Random, part: str) -> tuple[str, str]:
    """``part`` spelt as another key, and how."""
    how = rng.choice(["case", "lookalike", "invisible", "separator"])
    if how == "lookalike" and any(c in LOOKALIKE for c in part):
        i = rng.choice([j for j, c in enumerate(part) if c in LOOKALIKE])
        return part[:i] + LOOKALIKE[part[i]] + part[i + 1 :], how
    if how == "separator" and "_" in part:
        i = rng.choice([j for j, c in enumerate(part) if c == "_"])
        return part[:i] + rng.choice(["-", "__", ""]) + part[i + 1 :], how
    if how in ("invisible", "separator", "lookalike"):
        c = rng.choice(INVISIBLE)
        i = rng.choice([0, len(part), rng.randrange(len(part) + 1)])
        return part[:i] + c + part[i:], "invisible"
    spelt = rng.choice([part.upper(), part.title(), part[0].swapcase() + part[1:]])
    if spelt == part:  # "_" or digits only
        spelt = part + "X"
    return spelt, "case"


def respell(rng: random.Random, flat: dict, toml_value, toml_tables) -> tuple[str, str, list]:
    """``(document, description, --set options)``: ``flat`` (a valid study file's keys) with
    one key spelt as no key is; the description ends with that key as the one line must
    name it (``key_text``), or with the key given twice."""
    k = rng.choice([x for x in flat if x != "study"] + ["study"] * (rng.random() < 0.1))
    lines = [f"{x} = {toml_value(v)}" for x, v in flat.items()]  # dotted keys, as toml_doc
    head, _, leaf = k.rpartition(".")
    where = rng.random()
    if where < 0.15 and k != "study":  # twice through two spellings: "plate.grid" = 5 at the
        twice = f"{json.dumps(k)} = {toml_value(flat[k])}"  # top, [plate] grid = 5 below
        body = toml_tables(flat) if head else lines  # (trials = 4 and "trials" = 4)
        return "\n".join([*body[:1], twice, *body[1:]]) + "\n", f"twice {key_text(k)}", []
    parts = k.split(".")
    j = rng.randrange(len(parts))
    spelt, how = _respelt_part(rng, parts[j])
    new = ".".join(parts[:j] + [spelt] + parts[j + 1 :])
    if where < 0.35 and k != "study" and new.strip() != k:  # on the command line (its key is
        return "\n".join(lines) + "\n", f"--set-{how} {key_text(new)}", ["--set", f"{new}=1"]
    line = ".".join(map(_quoted, parts[:j] + [spelt] + parts[j + 1 :]))  # read stripped)
    doc = [f"{line} = {toml_value(flat[k])}" if x == k else ln for x, ln in zip(flat, lines)]
    return "\n".join(doc) + "\n", f"{how} {key_text(new)}", []


#: a small network whose every key a case may respell: tables, record fields, constraint keys
NETWORK = {
    "study": "network",
    "trials": 40,
    "chunk": 2,
    "network": {
        "name": "spelt",
        "points": [
            {"name": "A", "x_mm": 0.0, "y_mm": 0.0},
            {"name": "B", "x_mm": 400.0, "y_mm": 0.0},
            {"name": "C", "x_mm": 400.0, "y_mm": 300.0, "role": "free"},
            {"name": "P", "x_mm": 150.0, "y_mm": 120.0},
        ],
        "grids": [{"prefix": "G", "nx": 2, "ny": 2, "spacing_mm": 50.0}],
        "generate": [
            {"kind": "distance", "from": ["A", "B", "C"], "to": "*", "sigma_mm": 0.002},
            {"kind": "direction", "from": "C", "to": "*", "sigma_arcsec": 2.0},
        ],
    },
    "datum": {"kind": "constraints", "constraints": [{"A.x": 1.0}, {"A.y": 1.0}, {"B.y": 1.0}]},
    "output": {"inner_over": ["G*"]},
}


def _inline(v, toml_value) -> str:
    if isinstance(v, dict):
        return (
            "{ "
            + ", ".join(f"{_quoted(k)} = {_inline(x, toml_value)}" for k, x in v.items())
            + " }"
        )
    if isinstance(v, list):
        return "[" + ", ".join(_inline(x, toml_value) for x in v) + "]"
    return toml_value(v)


def network_case(rng: random.Random, toml_value) -> tuple[str, str, list[str]]:
    """``(document, description, needles)``: :data:`NETWORK` with one key spelt as no key is
    (a table's name, a field of a record, a point's name in a constraint's key); the line
    must hold one of ``needles`` (the part so spelt, as a key or a ``repr`` shows it)."""
    doc = json.loads(json.dumps(NETWORK))
    table = rng.choice(["network", "datum", "output", "points", "grids", "generate", "constraints"])
    if table in ("network", "datum", "output"):
        old = rng.choice([table, *doc[table]])
        spelt, how = _respelt_part(rng, old)
        if old == table:
            doc[spelt] = doc.pop(table)
        else:
            doc[table] = {spelt if k == old else k: v for k, v in doc[table].items()}
    else:
        recs = doc["datum"]["constraints"] if table == "constraints" else doc["network"][table]
        i = rng.randrange(len(recs))
        old = rng.choice(list(recs[i]))
        spelt, how = _respelt_part(rng, old)
        recs[i] = {spelt if k == old else k: v for k, v in recs[i].items()}
    lines = [
        f"{_quoted(k)} = {_inline(v, toml_value)}"
        for k, v in doc.items()
        if not isinstance(v, dict)
    ]
    for head, body in ((k, v) for k, v in doc.items() if isinstance(v, dict)):
        lines += [
            f"[{_quoted(head)}]",
            *(f"{_quoted(k)} = {_inline(v, toml_value)}" for k, v in body.items()),
        ]
    needles = [key_text(spelt).strip('"'), repr(spelt)[1:-1], spelt]
    return "\n".join(lines) + "\n", f"network {table}: {how} {old} -> {spelt!r}", needles
