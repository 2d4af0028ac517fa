"""Why a directory's ``run.json`` is no run record of the suite, in words for the one-line
refusal of an output directory that holds files (``--out``): it said "holds files but no sim
run record (run.json)" of a directory whose ``run.json`` was there but damaged (saved by an
editor with a UTF-8 signature or in another encoding, cut short, edited into other JSON),
which sent the user looking for a file that exists."""

from __future__ import annotations

import codecs
import json
from pathlib import Path

from sim.mc.storage import RECORD
from sim.mc.text_bytes import NotText, utf8_text

__all__ = ["record_problem"]


def record_problem(d: str | Path) -> str:
    """``no sim run record (run.json)`` when ``d`` has none, else what its ``run.json`` is
    instead of a record (for a directory :func:`sim.mc.storage.read_record` did not take)."""
    p = Path(d) / RECORD
    try:
        data = p.read_bytes() if p.is_file() else None
    except OSError as e:
        return f"a run.json that cannot be read ({e.strerror or e})"
    if data is None:
        return "no sim run record (run.json)"
    what = "it is no JSON object with a config and a code hash"
    if data.startswith(codecs.BOM_UTF8):
        what = "it starts with a UTF-8 signature, which sim never writes: another program saved it"
    else:
        try:
            json.loads(utf8_text(data))
        except NotText as e:
            what = f"it is {e}"
        except (ValueError, RecursionError) as e:
            what = f"it is not JSON: {str(e)[:80] or type(e).__name__}"
    return f"a run.json that is no sim run record ({what})"
