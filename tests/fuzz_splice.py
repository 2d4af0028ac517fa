"""SPLICE, a mutation kind of the fuzzer (tests/test_fuzz.py): a bad input made by crossing
valid ones, each part well-formed where it came from.

A study file (:func:`splice_case`): a table of another study pasted in (Brown's ``[plate]``
into salsig's file, a network's ``[datum]`` into gridplate's; keys both studies have keep this
file's values), a ``[sweep]`` of another study's key, a list of records written as the inline
table of its first record (``points = { name = "A", ... }``) or a table as an array of tables
(``[[plate]]``), a network record given a field of another list's records (a point with
``kind``, a generated observation with ``role``). Each brings a key this study does not read
in that place: it must be refused, one line naming it (the description ends with the text the
line must hold); a pasted table whose keys are all this study's is run as any other file.

A GNU Gama file (:func:`gama_splice`): an element of the file moved under another parent (a
``<point>`` into an ``<obs>``, an observation into ``<points-observations>`` or another
observation, a ``<cov-mat>`` before the observations it follows, a ``<point>``, ``<vec>`` or
observation after its ``<cov-mat>``), an attribute of one element put on an element whose
vocabulary lacks it, a second ``<network>``: refused naming the file and the element (the
needle returned); ``<parameters>`` or ``<description>`` moved after ``<points-observations>``
is the same document (``gama-local`` reads them in any order), read as the file is (needle
None)."""

from __future__ import annotations

import random
import re

from fuzz_values import NAMES, base, toml_key, toml_tables, toml_value

from sim.studies.network.gama_vocab import VOCAB
from sim.studies.network.validate import _OBS

#: the fields of each list of records of the network kind (sim/studies/network/definition.py)
FIELDS = {
    "network.points": {"name", "x_mm", "y_mm", "x_m", "y_m", "role", "sigma_mm"},
    "network.grids": {"prefix", "nx", "ny", "spacing_mm", "spacing_m", "origin_mm", "origin_m"}
    | {"role", "sigma_mm"},
    "network.random": {"prefix", "n", "half_extent_mm", "half_extent_m", "center_mm"}
    | {"center_m", "role", "sigma_mm"},
    "network.observations": _OBS - {"nearest"},
    "network.generate": _OBS - {"at", "set"},
}
_TOP = ("study", "trials", "chunk", "seed")


def _study(name: str) -> str:
    return "network" if name.startswith("network") else name


def _records(flat: dict) -> list[str]:
    return [k for k, v in flat.items() if isinstance(v, list) and v and isinstance(v[0], dict)]


def splice_case(rng: random.Random, name: str, flat: dict, schema) -> tuple[str, str]:
    """``(document, description)``: ``flat`` (``name``'s tiny file) crossed with another
    study's; the description ends ``: must name TEXT`` when the file must be refused so."""
    other = rng.choice([n for n in NAMES if _study(n) != _study(name)])
    theirs = base(other)
    what = rng.choice(["table", "sweep", "inline", "aot", "field"])
    recs = [k for k in _records(flat) if k in FIELDS]
    if what == "field" and len(recs) >= 2:
        a, b = rng.sample(recs, 2)
        extra = sorted({f for r in flat[b] for f in r} - FIELDS[a])
        if extra:
            f, i = rng.choice(extra), rng.randrange(len(flat[a]))
            value = next(r[f] for r in flat[b] if f in r)
            flat = {**flat, a: [dict(r) for r in flat[a]]}
            flat[a][i][f] = value
            return _doc(flat), f"{b}'s field {f} in {a}[{i}]: must name {a}[{i}].{f}"
    if what == "inline" and _records(flat):
        k = rng.choice(_records(flat))
        one = "{ " + ", ".join(f"{toml_key(f)} = {toml_value(v)}" for f, v in flat[k][0].items())
        doc = toml_tables({x: v for x, v in flat.items() if x != k})
        head, _, leaf = k.rpartition(".")
        return _put(doc, head, f"{leaf} = {one} }}"), f"{k} one inline record: must name {k}"
    heads = sorted({k.rpartition(".")[0] for k in flat if "." in k})
    if what == "aot" and heads:
        head = rng.choice(heads)
        doc = [f"[[{head}]]" if ln == f"[{head}]" else ln for ln in toml_tables(flat)]
        return "\n".join(doc) + "\n", f"[[{head}]] for [{head}]: must name {head}"
    keys = [k for k in theirs if k not in _TOP and k.split(".")[0] != "sweep"]
    if what == "sweep":
        k = rng.choice(keys)
        sweep = {f"sweep.{k}": [theirs[k]]}
        foreign = k not in schema
        tail = f": must name sweep.{k}" if foreign else ""
        return _doc({**flat, **sweep}), f"[sweep] {k} of {other}{tail}"
    head = rng.choice(sorted({k.rpartition(".")[0] for k in keys if "." in k}))
    pasted = {k: v for k, v in theirs.items() if k.rpartition(".")[0] == head and k not in flat}
    foreign = [k for k in pasted if k not in schema]
    tail = f": must name one of {' '.join(foreign)}" if foreign else ""
    return _doc({**flat, **pasted}), f"[{head}] of {other}{tail}"


def _doc(flat: dict) -> str:
    return "\n".join(toml_tables(flat)) + "\n"


def _put(lines: list[str], head: str, line: str) -> str:
    """``lines`` with ``line`` written in table ``head`` (``""``: the top level)."""
    if not head:
        return "\n".join([line, *lines]) + "\n"
    if f"[{head}]" not in lines:
        lines = [*lines, f"[{head}]"]
    i = lines.index(f"[{head}]")
    return "\n".join([*lines[: i + 1], line, *lines[i + 1 :]]) + "\n"


_ELEMENT = re.compile(r"<(point|obs|direction|distance|angle|parameters|description)\b[^>]*?/>")
_BEFORE_COV = re.compile(
    r"(<(point|vec|direction|distance|angle)\b[^>]*?/>)(\s*)(<cov-mat\b[^>]*>[^<]*</cov-mat>)"
)
_OBS_BLOCK = re.compile(r"<obs\b[^>]*>.*?</obs>", re.S)


def gama_splice(rng: random.Random, text: str) -> tuple[str, str, str | None]:
    """``(document, description, needle)``: a valid ``gama-local`` file ``text`` with one of
    its parts moved; ``needle``: the text the one-line refusal must hold (None: the same
    document, to be read as ``text`` is)."""
    els = _ELEMENT.findall(text)
    what = rng.choice(["into_obs", "out_of_obs", "into_obs_el", "cov_first", "after_cov"])
    what = rng.choice([what, "attr", "two"]) if rng.random() < 0.4 else what
    what = rng.choice([what, "same"]) if rng.random() < 0.3 else what
    whole = [m.group(0) for m in _ELEMENT.finditer(text)]
    obs = _OBS_BLOCK.findall(text)
    if what == "into_obs" and "point" in els and obs:  # a <point> inside an <obs>
        pt = rng.choice([w for w in whole if w.startswith("<point")])
        o = rng.choice(obs)
        cut = o.index(">") + 1
        return text.replace(o, o[:cut] + pt + o[cut:], 1), "a <point> in an <obs>", "<point>"
    sights = [w for w in whole if w.split()[0][1:] in ("direction", "distance", "angle")]
    if what in ("out_of_obs", "into_obs_el") and sights:
        s = rng.choice(sights)
        tag = s.split()[0][1:]
        if what == "out_of_obs":  # an observation directly in <points-observations>
            doc = text.replace("</points-observations>", s + "</points-observations>", 1)
            return doc, f"a <{tag}> in <points-observations>", f"<{tag}>"
        o = rng.choice(obs)  # inside another observation of an <obs>
        inner = re.search(r"<(direction|distance|angle)\b[^>]*?/>", o)
        if inner:
            nest = inner.group(0)[:-2] + ">" + s + f"</{inner.group(1)}>"
            return text.replace(inner.group(0), nest, 1), f"a <{tag}> in an observation", f"<{tag}>"
    if what == "cov_first" and obs:  # a diagonal <cov-mat> before the observations it follows
        o = rng.choice(obs)
        n = len(re.findall(r"<(direction|distance|angle)\b", o))
        cut = o.index(">") + 1
        cm = f'<cov-mat dim="{n}" band="0">' + " 1" * n + "</cov-mat>"
        return text.replace(o, o[:cut] + cm + o[cut:], 1), "a <cov-mat> first", "<cov-mat>"
    after = list(_BEFORE_COV.finditer(text))
    if what == "after_cov" and after:  # the element before a <cov-mat> moved after it
        m = rng.choice(after)
        doc = text[: m.start()] + m.group(4) + m.group(3) + m.group(1) + text[m.end() :]
        return doc, f"a <{m.group(2)}> after its <cov-mat>", "<cov-mat>"
    if what == "attr" and len(whole) >= 2:  # an attribute of one element on another
        src, dst = rng.sample(whole, 2)
        t_dst = dst.split()[0][1:]
        attrs = [a for a in re.findall(r'\s([\w-]+)="', src) if a not in VOCAB.get(t_dst, ())]
        attrs = [a for a in attrs if f' {a}="' not in dst]
        if attrs:
            a = rng.choice(attrs)
            v = re.search(rf'\s{a}="([^"]*)"', src).group(1)
            new = dst[:-2].rstrip() + f' {a}="{v}" />'
            return text.replace(dst, new, 1), f"{a} on <{t_dst}>", f"'{a}'"
    if what == "two":  # a second <network>
        doc = text.replace("</gama-local>", "<network></network></gama-local>", 1)
        return doc, "two <network>s", "<network>"
    # the same document: <parameters> or <description> after <points-observations>
    for tag in ("parameters", "description"):
        m = re.search(rf"<{tag}\b.*?(/>|</{tag}>)", text, re.S)
        if m and rng.random() < 0.7:
            doc = text.replace(m.group(0), "", 1).replace("</network>", m.group(0) + "</network>")
            return doc, f"<{tag}> last, the same document", None
    return text, "unchanged, the same document", None
