"""The size of a GNU Gama ``gama-local`` file for the network's work and memory estimate
(:mod:`sim.mc.network_size`): its points, its observations by kind and its orientation sets,
counted in one pass of expat over the file's elements (no tree is built, no entity expanded).
The study's reader (``sim.studies.network.gama_read``) checks the file; this only counts what
it will read: each ``<point>`` of ``<points-observations>`` that it keeps, once by its id (one
that an observation or ``<coordinates>`` names, or fixed in xy with coordinates: the reader
leaves out the others, as ``gama-local`` does; a file listing 150,000 such points beside a
3-point network was counted as 300,008 unknowns on the sparse path), a ``<distance>``,
``<direction>`` or ``<angle>`` one row, a ``<vec>`` two (its ``dx`` and ``dy``), a point of
``<coordinates>`` two (its x and y), an ``<obs>`` with a direction one orientation unknown.
The estimate had guessed them from the file's size (80 bytes an observation, 4 observations
a point): a 10,000-point network's export was counted as 22,000 points and 50,000 unknowns
for its 30,006. A file this cannot count (unreadable, not XML, an entity declared, over
:data:`MAX_COUNT_BYTES`) gives None, and the estimate falls back to its size. A file in an
encoding Python's expat does not know (``gama-local``'s own ``cp-1250`` and ``cp-1251``, spelt
so, or a name it reads as ISO-8859-1) is counted byte by byte as ISO-8859-1: the names are
those bytes, told apart as there (such a 10,000-point file fell back to its size, 56,102 rows
and 2.1e6 factor nonzeros for its 88,803 and 3.6e6: the memory estimate 40 % short)."""

from __future__ import annotations

import functools
import hashlib
import os
import stat
from typing import NamedTuple
from xml.parsers import expat

__all__ = ["GamaCounts", "gama_counts", "MAX_COUNT_BYTES"]

#: the largest file counted (bytes): beyond the reader's own limit, which refuses it anyway
MAX_COUNT_BYTES = 256 * 1024**2
#: the elements of an ``<obs>`` that are one observation (row) each
_ROWS = ("distance", "direction", "angle")
#: the attributes of such an element that name a point (an angle's ``bs``/``fs``, their aliases;
#: its own ``from``, which an ``<obs>`` without one needs: a point only ever named there was not
#: counted, 3 points of a file of 3 as 2)
_SIGHTS = ("from", "to", "bs", "fs", "rs")


class GamaCounts(NamedTuple):
    """``points`` (distinct ids of the points the reader keeps), ``rows`` (observations by kind: distance, direction, angle,
    dx, dy, and the observed coordinates as ``coordinates``), ``orientations`` (sets)."""

    points: int
    rows: dict
    orientations: int


class _Stop(Exception):
    """An entity declaration: not counted (the reader refuses it, naming it)."""


def gama_counts(path: str | os.PathLike) -> GamaCounts | None:
    """The counts of the ``gama-local`` file at ``path``, or None where it cannot be counted
    (parsed once per content of the file, its sha256: keyed on its size and modification
    time, an edit that kept both, through the Python API within one process, kept the old
    counts in the work estimate; hashing is a small part of parsing)."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    if not stat.S_ISREG(st.st_mode) or st.st_size > MAX_COUNT_BYTES:
        return None
    h = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            while block := fh.read(1 << 20):
                h.update(block)
    except (OSError, ValueError):
        return None
    return _counted(os.path.abspath(path), h.hexdigest())


@functools.lru_cache(maxsize=4)
def _counted(path: str, sha256: str) -> GamaCounts | None:
    ids: set = set()
    kept: set = set()  # fixed in xy with coordinates: the reader keeps them, observed or not
    seen: set = set()  # named by an observation or <coordinates>
    rows = dict.fromkeys(("distance", "direction", "angle", "dx", "dy", "coordinates"), 0)
    stack: list[str] = []
    sets = [0, False]  # orientation sets, and whether the open <obs> has a direction

    def start(name, attrs):
        tag = name.rsplit(":", 1)[-1]
        parent = stack[-1] if stack else ""
        stack.append(tag)
        if tag == "point" and parent == "points-observations":
            pid = _id(attrs.get("id"))
            ids.add(pid)
            fixed = "xy" in str(attrs.get("fix", "")).lower()
            if fixed and str(attrs.get("x", "")).strip() and str(attrs.get("y", "")).strip():
                kept.add(pid)
        elif tag == "point" and parent == "coordinates":
            rows["coordinates"] += 2
            seen.add(_id(attrs.get("id")))
        elif tag == "vec":
            rows["dx"] += 1
            rows["dy"] += 1
            seen.update(_id(attrs.get(k)) for k in ("from", "to"))
        elif tag in _ROWS and parent == "obs":
            rows[tag] += 1
            seen.update(_id(attrs.get(k)) for k in _SIGHTS)
            if tag == "direction" and not sets[1]:
                sets[0] += 1
                sets[1] = True
        elif tag == "obs":
            sets[1] = False
            seen.add(_id(attrs.get("from")))

    def end(name):
        stack.pop()

    def entity(*_):
        raise _Stop

    for encoding in (None, "iso-8859-1"):  # the second: an encoding expat does not know
        for held in (ids, kept, seen, stack):
            held.clear()
        rows.update(dict.fromkeys(rows, 0))
        sets[:] = [0, False]
        p = expat.ParserCreate(encoding)
        p.StartElementHandler, p.EndElementHandler = start, end
        p.EntityDeclHandler = entity
        try:
            with open(path, "rb") as fh:
                p.ParseFile(fh)
        except LookupError:
            continue
        except (_Stop, expat.ExpatError, OSError, ValueError, RecursionError):
            return None
        return GamaCounts(len(ids & (seen | kept)), rows, sets[0])
    return None


def _id(v) -> str:
    """An id as the reader takes it: trimmed, each run of white space one space."""
    return " ".join(str(v or "").split())
