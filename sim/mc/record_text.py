"""Why a directory's ``run.json`` is no run record of the suite, in words for the one-line
refusal of an output directory that holds files (``--out``): it said "holds files but no sim
run record (run.json)" of a directory whose ``run.json`` was there but damaged (saved by an
editor with a UTF-8 signature or in another encoding, cut short, edited into other JSON),
which sent the user looking for a file that exists; and how to finish an unfinished run of
another config, in words that can be followed (:func:`finish_words`)."""

from __future__ import annotations

import codecs
import json
from pathlib import Path

from sim.mc.storage import RECORD
from sim.mc.text_bytes import NotText, utf8_text

__all__ = ["record_problem", "finish_words", "digest_file_key"]


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


def digest_file_key(key: str) -> str | None:
    """The key of the file whose sha256 the config key ``key`` records (filled in on load from
    its bytes: ``network.gama_sha256`` of ``network.gama_xml``, Wolf's ``table1.sha256`` of
    ``table1.file``), or None when ``key`` records none."""
    if key == "network.gama_sha256":
        return "network.gama_xml"
    head, _, leaf = key.rpartition(".")
    return f"{head}.file" if head and leaf == "sha256" else None


def finish_words(old, new: dict) -> str:
    """How to finish an unfinished run whose config ``old`` differs from this run's ``new``:
    run again with its values; where the sha256 of a file it read differs, with that file put
    back as it was ("run again with its values" was no advice there: the digest is filled in on
    load, and given by hand it must be the file's own, so it was refused again)."""
    if not isinstance(old, dict):
        return "run again with its values to finish it, or "
    keys = sorted(k for k in {*old, *new} if old.get(k) != new.get(k))
    digests = [k for k in keys if digest_file_key(k)]
    files = [str(old.get(digest_file_key(k)) or digest_file_key(k)) for k in digests]
    if not files:
        return "run again with its values to finish it, or "
    what = " and ".join(dict.fromkeys(files))
    if len(digests) == len(keys):
        return f"{what} changed since it started: put back its contents of then to finish it, or "
    return f"run again with its values and {what} as it was then to finish it, or "
