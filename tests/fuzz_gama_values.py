"""VALUES of a GNU Gama XML file, a mutation kind of the fuzzer (tests/test_fuzz.py): one
attribute's value replaced, the document otherwise as written.

The BYTES (tests/fuzz_bytes.py) and SPLICE (tests/fuzz_splice.py) kinds change a file's
encoding, characters and structure; neither puts another value into an attribute: a number
that is none (``nan``, ``inf``, ``1e400``, ``abc``, nothing, ``1,5``, ``0x10``), one at an edge
(``0``, ``-0``, a subnormal, ``1e308``, 400 digits), a padded one, or a point's name for
another point of the file (an observation whose fore-sight is its station, a point given
twice). ``sim check`` of the study that reads the file must exit 0 or refuse it in one line
naming the file; a numeric attribute given a value that is no finite number is refused (an
empty value aside: ``gama-local`` reads ``z=""`` or ``stdev=""`` as not given, and so does
the suite: :data:`sim.studies.network.gama_vocab.EMPTY_IS_ABSENT`; and the XML declaration's
``version``, whatever it says, as expat reads it for ``gama-local``)."""

from __future__ import annotations

import math
import random
import re

#: the values put into an attribute (a name of the file's points added for names)
VALUES = ["nan", "NaN", "inf", "-inf", "1e400", "abc", "", "  ", "1e", "+", "1,5", "0x10"]
VALUES += ["2.0.0", "1_0", "\uff11", "0", "-0", "-0.0", "-1", "1e308", "-1e308", "1e-320"]
VALUES += ["5e-324", " 5 ", "1" * 400, "10000000000000000000000"]
_ATTR = re.compile(r'(\s)([A-Za-z][\w-]*)="([^"]*)"')
_NAMES = re.compile(r'\b(?:id|from|to|bs|fs)="([^"]*)"')
_NAMED = ("id", "from", "to", "bs", "fs")


def _number(s: str) -> float | None:
    try:
        return float(s)
    except ValueError:
        return None


def gama_value(rng: random.Random, text: str) -> tuple[str, str, bool]:
    """``(document, description, must be refused)``: ``text`` with one attribute's value
    replaced; refused when a numeric attribute (its value in ``text`` a number) gets a value
    Python reads as no finite number."""
    m = rng.choice(list(_ATTR.finditer(text)))
    name, old = m.group(2), m.group(3)
    names = sorted(set(_NAMES.findall(text)))
    pool = VALUES + ([rng.choice(names)] * 4 if name in _NAMED and names else [])
    new = rng.choice(pool)
    doc = text[: m.start(3)] + new + text[m.end(3) :]
    x = _number(new)
    prolog = text[text.rfind("<", 0, m.start()) + 1] == "?"  # <?xml version="1.0"?>
    refuse = _number(old) is not None and name not in _NAMED and not prolog
    refuse = refuse and new != "" and (x is None or not math.isfinite(x))
    return doc, f'{name}="{old}" -> "{new[:24]}"', refuse
