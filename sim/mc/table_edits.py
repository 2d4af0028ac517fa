"""Which tables of a results directory changed after the run that wrote them: their sha256 is
not the one its ``run.json`` records (``table_sha256``). ``make verify`` says so before the
deviations such an edit makes, and ``--stale-only`` (``make reproduce``) re-runs such results,
as it re-draws a figure replaced by hand, rather than calling them current. A sweep's record
holds its cells' tables' sha256 too: a cell's table copied from another cell (same shape,
other numbers) was read as its own by ``sim show`` and ``Results.table`` of the cell
(:func:`edited_cell`)."""

from __future__ import annotations

import os
import re
from pathlib import Path

from sim.mc.publish import file_sha256
from sim.mc.storage import read_record

__all__ = ["edited_tables", "edited_chunks", "edited_cell"]

#: the name of a table of a results directory's top level, as ``table_sha256`` records it
_TABLE = re.compile(r"(?:cells/cell\d{4,}_r\d+/)?[^/\\\x00]+\.parquet")
#: the name of a chunk file of a results directory, as ``chunk_sha256`` records it
_CHUNK = re.compile(r"trials/part-\d+/chunk-\d+\.parquet")


def edited_tables(d: Path) -> list[str]:
    """The names of the tables of the results ``d`` whose sha256 is not the one its run
    record holds (or that are gone, or not regular files); none when the record holds no
    table sha256 (an older version's)."""
    rec = read_record(d) or {}
    sums = rec.get("table_sha256")
    if not isinstance(sums, dict):
        return []
    changed = []
    for name, digest in sorted(sums.items()):
        # a table's name as seal() records it, read only as a regular file: a name of a
        # run.json edited by hand was read as it stood ("x\0y": a ValueError traceback; a
        # FIFO: a hang; "../..": a file outside the results)
        if not isinstance(name, str) or not _TABLE.fullmatch(name):
            continue  # not a name seal() writes
        p = Path(d) / name
        try:
            if not p.is_file() or p.is_symlink() or file_sha256(p) != digest:
                changed.append(name)
        except OSError:
            changed.append(name)
    return changed


def edited_chunks(d: Path) -> list[str]:
    """The chunk files of the results ``d`` that are there but are not the ones its run wrote
    (their sha256 is not the one its record's ``chunk_sha256`` holds, or they are no regular
    file: a user's file saved over one, a link or a FIFO put in its place), which a re-run into
    ``d`` replaces: it said so of a table (:func:`edited_tables`), not of a chunk."""
    sums = (read_record(d) or {}).get("chunk_sha256")
    changed = []
    for name, digest in sorted(sums.items()) if isinstance(sums, dict) else []:
        if not isinstance(name, str) or not _CHUNK.fullmatch(name):
            continue  # not a name seal() writes
        p = Path(d) / name
        try:
            if os.path.lexists(p) and (
                not p.is_file() or p.is_symlink() or file_sha256(p) != digest
            ):
                changed.append(name)
        except OSError:
            changed.append(name)
    return changed


def edited_cell(d: Path, names: list[str] | None = None) -> str | None:
    """Why a table of ``d``, a sweep's cell (``<sweep>/cells/<label>/``, no record of its
    own), is not the one its cell's run wrote (its sha256 is not the one the sweep's run
    record holds for it: copied from another cell, or edited by hand), in one line, or None
    (the same; ``d`` no cell; a sweep of a version that recorded no cell's sha256).
    ``names``: only these tables (``["claims.parquet"]``). A table that is not there is left
    to its reader."""
    d = Path(d)
    up = d.resolve().parent
    if up.name != "cells" or os.path.lexists(d / "run.json"):
        return None
    rec = read_record(up.parent) or {}
    sums = rec.get("table_sha256")
    if not isinstance(sums, dict):
        return None
    prefix = f"cells/{d.resolve().name}/"
    for name, digest in sorted(sums.items()):
        if not isinstance(name, str) or not name.startswith(prefix) or not _TABLE.fullmatch(name):
            continue
        p = d / name[len(prefix) :]
        if (names is not None and p.name not in names) or not os.path.lexists(p):
            continue
        try:
            same = p.is_file() and not p.is_symlink() and file_sha256(p) == digest
        except OSError:
            same = False
        if not same:
            return (
                f"{p} is not the table its cell's run wrote (its sha256 is not the one "
                f"{up.parent / 'run.json'} records for {prefix[:-1]}: copied from another cell "
                "or edited by hand?); run the sweep again"
            )
    return None


def missing_cell(d: Path) -> str | None:
    """Why ``d``, a sweep's directory, lacks a cell its run wrote: a ``cells/<label>/`` whose
    tables its run record lists is gone (``sim show`` printed the cell's row of
    ``sweep.parquet`` as if it were there), in one line, or None."""
    sums = (read_record(Path(d)) or {}).get("table_sha256")
    if not (Path(d) / "sweep.parquet").is_file() or not isinstance(sums, dict):
        return None
    cells = {n.split("/")[1] for n in sums if isinstance(n, str) and n.startswith("cells/")}
    for label in sorted(c for c in cells if c and not os.path.lexists(Path(d) / "cells" / c)):
        return (
            f"{Path(d) / 'cells' / label} is missing: its sweep's run wrote it (removed by "
            "hand?); run the sweep again"
        )
    return None
