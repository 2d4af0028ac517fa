"""Which tables of a results directory changed after the run that wrote them: their sha256 is
not the one its ``run.json`` records (``table_sha256``). ``make verify`` says so before the
deviations such an edit makes, and ``--stale-only`` (``make reproduce``) re-runs such results,
as it re-draws a figure replaced by hand, rather than calling them current."""

from __future__ import annotations

import re
from pathlib import Path

from sim.mc.publish import file_sha256
from sim.mc.storage import read_record

__all__ = ["edited_tables"]

#: the name of a table of a results directory's top level, as ``table_sha256`` records it
_TABLE = re.compile(r"[^/\\\x00]+\.parquet")


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
