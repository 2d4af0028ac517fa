"""The encodings GNU Gama's ``gama-local`` decodes, and the characters it reads from a file's
bytes: expat's own encodings (UTF-8, UTF-16, ISO-8859-1, US-ASCII, any case) and those of its
own handler (``encoding_unknown_handler.cpp``: ``cp-1250``, ``windows-1250``, ``cp-1251``,
``windows-1251``, ``iso-8859-2``, names compared exactly, by its own tables); any other name it
reads as ISO-8859-1. :func:`gama_text` gives the file as ``gama-local`` reads it, or raises
:class:`EncodingProblem` where that is not what the file means. :func:`undecodable` names the first bytes that are not of the encoding the parser reads the
file in (UTF-8 when it declares none). Used by :mod:`sim.studies.network.gama_read`."""

from __future__ import annotations

import codecs
import re

from sim.studies.network.gama_vocab import said

__all__ = ["gama_text", "EncodingProblem", "bom_note", "utf8_note", "undecodable"]

#: the encodings gama-local decodes: expat's own (any case) and its handler's (names compared
#: exactly), by Python's codec and the bytes its table maps otherwise (cp1250: 0x80 to U+0080,
#: not the euro sign, its undefined bytes to themselves; cp1251: 0x98 to U+FFFD); any other
#: name it reads as ISO-8859-1 (``encoding_unknown_handler.cpp``: the identity table)
#: (not "UTF-16LE" nor "UTF-16BE": the expat gama-local 2.03 bundles lacks a comma in its table
#: of names, ``"UTF-16BE" "UTF-16LE"``, one name "UTF-16BEUTF-16LE"; it reads them as any other)
_EXPAT_ENC = ("utf-8", "utf-16", "iso-8859-1", "us-ascii")
_GAMA_ENC = {
    "cp-1250": "cp1250",
    "windows-1250": "cp1250",
    "cp-1251": "cp1251",
    "windows-1251": "cp1251",
    "iso-8859-2": "iso8859_2",
}
_OWN = {
    "cp1250": {b: chr(b) for b in (0x80, 0x81, 0x83, 0x88, 0x90, 0x98)},
    "cp1251": {0x98: "\ufffd"},
}
_BOM8 = b"\xef\xbb\xbf"
#: the XML declaration's encoding (a ``<?xml-stylesheet encoding=...?>`` declares nothing)
_DECL = re.compile(rb"^(?:\xef\xbb\xbf)?<\?xml[ \t\r\n][^>]*?\bencoding\s*=\s*[\"']([^\"']*)[\"']")


_DECL16 = re.compile(r"^\ufeff?<\?xml[ \t\r\n][^>]*?\bencoding\s*=\s*[\"']([^\"']*)[\"']")


def _utf16_name(data: bytes) -> str | None:
    """The encoding a UTF-16 file's XML declaration names (None: no UTF-16 file, or none)."""
    head = data[:2048]
    if head[:2] == b"\xff\xfe" or head[:4] == b"<\0?\0":
        m = _DECL16.match(head.decode("utf-16-le", "replace"))
    elif head[:2] == b"\xfe\xff" or head[:4] == b"\0<\0?":
        m = _DECL16.match(head.decode("utf-16-be", "replace"))
    else:
        return None
    return m.group(1) if m else None


def bom_note(data: bytes) -> str:
    """What the report says of a file that begins with a UTF-8 byte-order mark: read as
    UTF-8 here, where ``gama-local`` 2.03 stops on it (a segmentation fault in its expat)."""
    if not data.startswith(_BOM8):
        return ""
    return (
        "; the file begins with a UTF-8 byte-order mark, read as UTF-8 here: gama-local 2.03 "
        "stops on it (a segmentation fault), remove the mark to run the file there"
    )


def utf8_note(data: bytes) -> str:
    """What the report says of a file that declares a single-byte encoding (``ISO-8859-1``,
    ``cp-1250``, ...) over bytes beyond ASCII that are UTF-8 as well: a program that writes
    UTF-8 under another declaration. They are read as declared, as ``gama-local`` reads them
    (the same network, its point names other characters: ``\u010c\u00e1p`` read as ``\u00c4\u0152\u00c3\u00a1p``);
    a Latin-1 text is almost never valid UTF-8, so the note says what the writer likely meant."""
    m = _DECL.match(data[:1024])
    if not m or data.startswith(_BOM8):
        return ""
    enc = m.group(1).decode("ascii", "replace")
    if enc.lower() in _EXPAT_ENC and enc.lower() != "iso-8859-1":
        return ""
    if data.isascii() or not _utf8(data):
        return ""
    return (
        f"; the file declares {said(enc)} and its bytes beyond ASCII are read so, as gama-local "
        "reads them, but they are UTF-8 too (point names in UTF-8 read as other characters): "
        'if the file is UTF-8, declare encoding="UTF-8"'
    )


class EncodingProblem(ValueError):
    """The file's bytes read as other characters in gama-local than here (the message says why)."""


def _table(codec: str) -> dict[int, str]:
    own = _OWN.get(codec, {})  # gama-local's table of the bytes beyond ASCII
    return {b: own[b] if b in own else bytes([b]).decode(codec) for b in range(128, 256)}


def _latin1(enc: str) -> bool:
    """``enc`` is a Python name of ISO-8859-1 (``latin_1``, ``L1``), as gama-local reads it."""
    try:
        return codecs.lookup(enc).name == "iso8859-1"
    except (LookupError, ValueError):
        return False


def gama_text(data: bytes) -> bytes | str:
    """The file as ``gama-local`` reads its characters, for the XML parser: the bytes where
    the parser decodes them as gama-local's (no declaration, expat's own encodings), else
    the text decoded as gama-local decodes it: its own encodings (``cp-1250``, ...) by its
    tables, any other name (``x-foo``, ``latin_1``) as ISO-8859-1, alike for a file of ASCII
    bytes. Raises :class:`EncodingProblem` where that is not what the file means: a name of
    another encoding (``koi8-r``, ``ISO-8859-2`` in capitals, ``UTF8``, ``CP1250``: Python's
    codec would read other characters than gama-local, and the writer meant those) over bytes
    beyond ASCII, a UTF-8 byte-order mark before another declared encoding (the mark and the
    declaration disagree: ``É`` of the UTF-8 the mark says is ``Ã‰`` in ISO-8859-1), or a
    UTF-16 file declared ``UTF-16LE`` or ``UTF-16BE``, names gama-local 2.03 does not know
    (it refuses the file; over ASCII bytes it reads them, as any other name), or a UTF-16 file
    declaring another encoding (``iso-8859-2``: gama-local refuses it as "not well-formed" or
    "encoding specified in XML declaration is incorrect", and so did this reader, unexplained)."""
    if (name := _utf16_name(data)) and name.lower() in ("utf-16le", "utf-16be"):
        raise EncodingProblem(
            f"<?xml encoding={said(name)}?>: gama-local 2.03 does not know this name (its "
            'expat knows "UTF-16") and refuses the file as not well-formed: declare UTF-16'
        )
    if name and name.lower() != "utf-16":  # a UTF-16 file declaring iso-8859-2: "not well-formed"
        raise EncodingProblem(
            f"a UTF-16 file (its bytes) declaring <?xml encoding={said(name)}?>: gama-local "
            "refuses it (the declaration and the bytes disagree): declare UTF-16, or save the "
            f"file in {said(name)}"
        )
    m = _DECL.match(data[:1024])
    if not m:
        return data
    enc = m.group(1).decode("ascii", "replace")
    bom = data.startswith(_BOM8)
    body = data[len(_BOM8) :] if bom else data
    if bom and enc.lower() != "utf-8" and not body.isascii():
        raise EncodingProblem(
            f"a UTF-8 byte-order mark before <?xml encoding={said(enc)}?>: gama-local reads "
            "the bytes beyond ASCII by the declaration, not as UTF-8 (an \u00c9 as \u00c3 and "
            "another character): remove the mark or declare UTF-8"
        )
    if enc.lower() in _EXPAT_ENC:
        return data
    if body.isascii():  # no byte beyond ASCII: every name reads alike (gama-local's too)
        return body.decode("ascii")
    if enc in _GAMA_ENC:
        return body.decode("latin-1").translate(_table(_GAMA_ENC[enc]))
    if _latin1(enc):
        return body.decode("latin-1")
    raise EncodingProblem(
        f"<?xml encoding={said(enc)}?>: gama-local does not know this encoding and reads the "
        "bytes beyond ASCII as ISO-8859-1, other characters than here: declare UTF-8 "
        f"(or one of {', '.join(('UTF-16', 'ISO-8859-1', 'US-ASCII', *_GAMA_ENC))})"
    )


_LINE_END = re.compile(rb"\r\n|\r|\n")


def undecodable(data: bytes) -> tuple[int, str] | None:
    """``(line, why)`` of the first bytes of ``data`` that are not of the encoding the XML
    parser reads it in: UTF-8 where it declares none or ``UTF-8``, ASCII where it declares
    ``US-ASCII`` (None: no such bytes, or another encoding). The parser stops there with "not
    well-formed (invalid token)", which does not say why: a file from another program, in
    ISO-8859-2 or windows-1250 (Czech point names) and without a declaration, is the likely
    case (``gama-local`` 2.03 reads such bytes as they are, other characters than written)."""
    head = data[:4]
    if head[:2] in (b"\xff\xfe", b"\xfe\xff") or head in (b"<\0?\0", b"\0<\0?"):
        return None  # UTF-16: its own checks
    m = _DECL.match(data[:1024])
    enc = m.group(1).decode("ascii", "replace") if m else None
    if enc is not None and enc.lower() not in ("utf-8", "us-ascii"):
        return None
    codec = "ascii" if enc is not None and enc.lower() == "us-ascii" else "utf-8"
    try:
        data.decode(codec)
        return None
    except UnicodeDecodeError as e:
        start = e.start
    line = len(_LINE_END.findall(data, 0, start)) + 1
    bad = repr(data[start : start + 4])
    if enc is None:
        decl = "declares no encoding, so it is read as UTF-8 (XML's default)"
    else:
        decl = f"declares {said(enc)}"
    what = "beyond ASCII" if codec == "ascii" else "that are not UTF-8"
    why = f"line {line}: bytes {what} ({bad}...) in a file that {decl}"
    if codec == "ascii" and _utf8(data):
        return line, f'{why}: they read as UTF-8, declare encoding="UTF-8"'
    return line, (
        f"{why}: it was written in another encoding: declare that one in its first line, such "
        'as <?xml version="1.0" encoding="iso-8859-2"?> or "windows-1250" (names gama-local '
        "knows, spelt so), or save the file as UTF-8"
    )


def _utf8(data: bytes) -> bool:
    try:
        data.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return True
