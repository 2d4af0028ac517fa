"""What ``gama-local``'s own parser (expat, without namespace processing:
``lib/gnu_gama/xml/gkfparser.cpp``) sees in a file before the reader parses it: an entity its
DOCTYPE declares (refused: a ``gama-local`` file needs none) and the names of elements and
attributes as written, prefixes included. Each returns what to refuse, or None; the reader
(:mod:`sim.studies.network.gama_read`) names the file."""

from __future__ import annotations

from xml.parsers import expat

from sim.studies.network.gama_frames import NE
from sim.studies.network.gama_vocab import NS, said

__all__ = ["entity_declared", "default_declared", "raw_name_problem"]


class _Prolog(Exception):
    """The first element: the prolog, where every declaration stands, is over."""


def entity_declared(data: bytes | str) -> str | None:
    """The name of the first entity the file's DOCTYPE declares (None: none). A gama-local file
    needs none, and entities are how a file of a few kilobytes expands to gigabytes in the
    parser ("billion laughs"; expat stops an amplification over 100, one just below it held
    the reader at 50 times the file's size, doors31x) or names a local file or a URL (an
    external entity: never read nor fetched here). Only the prolog is parsed: the scan stops
    at the first element; a parse error is left to the reader, which names it."""
    p = expat.ParserCreate()
    found: list[str] = []

    def entity(name, is_param, *_):
        found.append(("%" if is_param else "&") + name + ";")
        raise _Prolog

    def element(*_):
        raise _Prolog

    p.EntityDeclHandler = entity
    p.StartElementHandler = element
    try:
        p.Parse(data, True)
    except (_Prolog, expat.ExpatError, ValueError, LookupError):
        pass
    return found[0] if found else None


#: attribute defaults a DOCTYPE may declare because they change nothing gama-local or this
#: suite reads: (element, attribute) -> the value gama-local assumes when the attribute is
#: absent (``gkfparser.cpp``: ``xmlns`` must be its namespace, refused otherwise; ``axes-xy``
#: and ``angles`` of ``<network>`` default to ``ne`` and ``left-handed``), None: any value
#: (``version`` of ``<gama-local>``, ignored there and here)
ASSUMED = {
    ("gama-local", "xmlns"): NS,
    ("gama-local", "version"): None,
    ("network", "axes-xy"): NE[0],
    ("network", "angles"): NE[1],
}


def _assumed(element: str, attribute: str, value: str) -> bool:
    """Whether a default ``value`` of ``attribute`` on ``element`` is what gama-local assumes
    without it (:data:`ASSUMED`)."""
    if (element, attribute) not in ASSUMED:
        return False
    want = ASSUMED[element, attribute]
    return want is None or value == want


def default_declared(data: bytes | str) -> tuple[str, str, str] | None:
    """``(element, attribute, value)`` of the first attribute default the file's DOCTYPE
    declares (``<!ATTLIST distance stdev CDATA "5">``, ``#FIXED`` too) that gives an element
    a value it does not write, None: none. The parser (here and in ``gama-local``) gives every
    element without the attribute that value: a stdev or an ``adj`` no element shows, which a
    refusal then named on an element that does not hold it ("point 'A' is both fixed and
    adjusted" of a ``<point fix="xy">``). A default that changes nothing is read: one every
    such element writes itself, or the value gama-local assumes without it (:data:`ASSUMED`:
    ``<!ATTLIST gama-local xmlns CDATA #FIXED "...gama-local">`` was refused too). The scan
    stops at the first element when the DOCTYPE declares no default; a parse error is left to
    the reader."""
    p = expat.ParserCreate()
    p.specified_attributes = True  # the attributes as written: a default is not reported
    declared: dict[str, dict[str, str]] = {}
    found: list[tuple[str, str, str]] = []

    def attlist(elname, attname, _type, default, _required):
        # the first declaration of an attribute binds (XML 1.0, 3.3), a later one is ignored:
        # an assumed default then another was refused naming the other, which no parser gives
        if default is not None and attname not in declared.get(elname, {}):
            declared.setdefault(elname, {})[attname] = (
                None if _assumed(elname, attname, default) else default
            )

    def element(name, attrs):
        if not any(v is not None for d in declared.values() for v in d.values()):
            raise _Prolog
        for att, v in declared.get(name, {}).items():
            if v is not None and att not in attrs:
                found.append((name, att, v))
                raise _Prolog

    p.AttlistDeclHandler = attlist
    p.StartElementHandler = element
    try:
        p.Parse(data, True)
    except (_Prolog, expat.ExpatError, ValueError, LookupError):
        pass
    return found[0] if found else None


class _Raw(Exception):
    """The first name gama-local reads otherwise than a namespace-aware parser."""


def raw_name_problem(data: bytes | str) -> str | None:
    """What ``gama-local`` refuses in the file's names as written, or None. Its parser (expat
    without namespace processing, ``gkfparser.cpp``) reads each name as it stands, where
    ElementTree drops a prefix: ``<g:gama-local xmlns:g="...">`` is an unknown element there
    (the same network here), an attribute of ``<gama-local>`` other than ``xmlns`` and
    ``version`` (``xmlns:g``, ``xsi:schemaLocation``) is refused, and so is ``xmlns`` or any
    prefixed attribute (``o:note``) of every other element, which reads its own attributes
    only. A parse error is left to the reader, which names it."""
    p = expat.ParserCreate()  # no namespace processing: names as gama-local sees them
    p.ordered_attributes = True
    depth = [0]

    def start(name, attrs):
        if ":" in name:
            raise _Raw(
                f"<{name}>: an element name with a namespace prefix (gama-local reads no "
                f"prefix: write <{name.split(':', 1)[1]}>)"
            )
        names = attrs[0::2]
        for a in names:
            if depth[0] == 0 and a not in ("xmlns", "version"):
                raise _Raw(f"<{name}> attribute {said(a)}: gama-local takes only xmlns and version")
            if depth[0] and (a == "xmlns" or ":" in a):
                raise _Raw(
                    f"<{name}> attribute {said(a)}: gama-local refuses a namespace declaration "
                    "or a prefixed attribute here (only <gama-local> takes xmlns)"
                )
        depth[0] += 1

    p.StartElementHandler = start
    try:
        p.Parse(data, True)
    except _Raw as why:
        return str(why)
    except (expat.ExpatError, ValueError, LookupError):
        pass
    return None
