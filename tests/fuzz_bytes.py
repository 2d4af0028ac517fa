"""BYTES, a mutation kind of the fuzzer (tests/test_fuzz.py): the raw bytes of a file changed
as editors, other systems and cut copies change them. A UTF-8 signature (BOM), CRLF or lone
CR line ends, a NUL byte, the file in UTF-16 (with and without its signature), a Latin-1 byte
or an overlong or cut UTF-8 sequence in a string, a zero-width space or a right-to-left mark
inside a key or an id, a look-alike of ASCII (a Cyrillic letter in a key; full-width or
Arabic-Indic digits, a superscript minus or the minus sign in a number), a tab, form feed,
vertical tab, no-break space, NEL or line separator for a space, and a file that ends in
the middle of a line or a string, or without its last line end.

``bytes_case`` mutates a study file (a case of ``sim run``); ``data_case`` mutates a GNU Gama
XML file or a Wolf reading table (``studies/data/wolf_table*.csv``), whose check is a
``sim check`` of the study that reads it: exit 0 with the file read as the same input, or exit
2 with one line naming the file. ``SAME``: the mutations that leave a TOML study file the
same document (TOML skips the signature, CRLF ends a line, a last line needs no line end).
"""

from __future__ import annotations

import random
import re

#: the mutations after which a study file is the same TOML document (it must run)
SAME = ("bom", "crlf", "no final line end")


def _spans(text: str, pattern: str) -> list[tuple[int, int]]:
    return [m.span(1) for m in re.finditer(pattern, text, re.M)]


def _insert(text: str, span: tuple[int, int], s: str) -> str:
    k = span[0] + max(1, (span[1] - span[0]) // 2)
    return text[:k] + s + text[k:]


def mutate_bytes(rng: random.Random, text: str, sites: dict) -> tuple[bytes, str]:
    """One mutation of ``text``'s bytes; ``sites``: spans of its ``key``, ``id``, ``num`` and
    ``str`` (a string's content) places. Returns the bytes and the mutation's name."""
    b = text.encode()
    kinds = ["bom", "crlf", "cr", "nul", "utf16", "utf16-le", "utf16-be", "cut", "cut-string"]
    kinds += ["no final line end", "space"] * 2 + ["in-string", "in-key", "lookalike", "number"]
    what = rng.choice(kinds)
    key = rng.choice(["key", "id"]) if sites.get("id") else "key"
    if what == "bom":
        return b"\xef\xbb\xbf" + b, what
    if what in ("crlf", "cr"):
        return b.replace(b"\n", b"\r\n" if what == "crlf" else b"\r"), what
    if what == "nul":
        i = rng.randrange(len(b))
        return b[:i] + b"\0" + b[i:], what
    if what.startswith("utf16"):
        return text.encode(
            {"utf16": "utf-16", "utf16-le": "utf-16-le"}.get(what, "utf-16-be")
        ), what
    if what == "cut" or (what == "cut-string" and not sites.get("str")):
        return b[: rng.randrange(1, len(b))], "cut"
    if what == "cut-string":
        s, e = rng.choice(sites["str"])
        return text[: (s + e) // 2].encode(), what
    if what == "no final line end":
        return text.rstrip("\n").encode(), what
    if what == "space" and " " in text:
        k = rng.choice([m.start() for m in re.finditer(" ", text)])
        ch = rng.choice(["\t", "\f", "\v", "\u00a0", "\u0085", "\u2028"])
        return (text[:k] + ch + text[k + 1 :]).encode(), f"{ch!r} for a space"
    if what == "in-string" and sites.get("str"):
        raw = rng.choice([b"\xe9", b"\xc0\xaf", b"\xe2\x82"])  # Latin-1, overlong, cut
        return _insert(text, rng.choice(sites["str"]), "\0").encode().replace(b"\0", raw), (
            f"byte(s) {raw!r} in a string"
        )
    if what == "lookalike":
        spans = [sp for sp in sites.get(key, []) if re.search("[aceopx]", text[sp[0] : sp[1]])]
        if spans:
            s, e = rng.choice(spans)
            m = re.search("[aceopx]", text[s:e])
            cyr = dict(zip("aceopx", "асеорх"))[m.group()]
            return (
                text[: s + m.start()] + cyr + text[s + m.end() :]
            ).encode(), f"Cyrillic in {key}"
    if what == "number" and sites.get("num"):
        s, e = rng.choice(sites["num"])
        seg = text[s:e]
        new = rng.choice(
            [
                "".join(chr(ord(c) + 0xFEE0) if c.isdigit() else c for c in seg),  # full-width
                "".join(chr(ord(c) + 0x0630) if c.isdigit() else c for c in seg),  # Arabic-Indic
                "\u207b" + seg.lstrip("-"),  # superscript minus
                "\u2212" + seg.lstrip("-"),  # minus sign
            ]
        )
        return (text[:s] + new + text[e:]).encode(), f"number {new!r}"
    if sites.get(key):  # in-key, and the fallbacks of the kinds above
        ch = rng.choice(["\u200b", "\u200f"])
        return _insert(text, rng.choice(sites[key]), ch).encode(), f"{ch!r} in a {key}"
    return b"\xef\xbb\xbf" + b, "bom"


def toml_sites(text: str) -> dict:
    """The places of a study file written by tests/fuzz_values.py (``key = value`` lines)."""
    return {
        "key": _spans(text, r"^\s*([A-Za-z_][\w.]*)\s*=") + _spans(text, r"[{,]\s*([a-z_]+)\s*="),
        "num": _spans(text, r"=\s*(-?\d[\d.eE+-]*)"),
        "str": _spans(text, r'"([^"\n]+)"'),
    }


def bytes_case(rng: random.Random, text: str) -> tuple[bytes, str]:
    """A study file's bytes mutated; the description ends with :data:`SAME`'s name when the
    document is the same."""
    return mutate_bytes(rng, text, toml_sites(text))


def gama_sites(text: str) -> dict:
    return {
        "key": _spans(text, r"\s([a-z-]+)=\""),
        "id": _spans(text, r'(?:id|from|to)="([^"]+)"'),
        "num": _spans(text, r'(?:val|x|y|stdev)="(-?[\d.e]+)"'),
        "str": _spans(text, r"<description>(.+?)</description>"),
    }


def csv_sites(text: str) -> dict:
    lines = text.split("\n")
    at = next(i for i, ln in enumerate(lines) if ln and not ln.startswith("#"))
    off = sum(len(ln) + 1 for ln in lines[:at])
    return {
        "key": [(off + m.start(), off + m.end()) for m in re.finditer(r"\w+", lines[at])],
        "id": _spans(text, r"^(\d{3}),"),
        "num": _spans(text, r",(-?\d+\.\d+)"),
        "str": _spans(text, r',"([^"\n]+)"$'),
    }
