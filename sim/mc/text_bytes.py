"""Bytes that should be UTF-8 text, decoded, or named in one line when they are not: a study
file (:func:`sim.mc.config.read_toml`), a transcribed CSV table (``sim.studies.wolf.tables``),
a run record (``run.json``, :func:`sim.mc.storage.record_problem`).

A leading UTF-8 signature (the BOM a Windows editor or Excel's "CSV UTF-8" writes) is no part
of the text and is skipped. A file with NUL bytes is UTF-16 (Windows' "Unicode") or binary; a
UTF-16 signature is named as UTF-16 even without NULs (text of CJK characters only); else the
first byte that is not UTF-8 is named with its line (Latin-1 or Windows-1252, an overlong or
cut multi-byte sequence). The CSV table said only "not a text file (not UTF-8)", no byte or
line, and UTF-16 without its signature was "a binary file".
"""

from __future__ import annotations

import codecs

__all__ = ["NotText", "utf8_text"]


class NotText(ValueError):
    """Why bytes are not UTF-8 text, as a message says it (``not UTF-8 text (...)``)."""


def utf8_text(data: bytes) -> str:
    """``data`` decoded as UTF-8 (a leading UTF-8 signature skipped); :class:`NotText` naming
    the problem when they are not UTF-8 text."""
    data = data.removeprefix(codecs.BOM_UTF8)
    if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        raise NotText("not UTF-8 text (it is UTF-16, as Windows saves 'Unicode': save it as UTF-8)")
    if b"\x00" in data:
        raise NotText("not UTF-8 text (it holds NUL bytes: UTF-16 or binary)")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        line = data[: e.start].count(b"\n") + 1
        raise NotText(
            f"not UTF-8 text (byte 0x{data[e.start]:02x} at line {line}: saved as Latin-1 "
            "or Windows-1252? save it as UTF-8)"
        ) from None
