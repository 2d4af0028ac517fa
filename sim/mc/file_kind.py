"""What stands at a path where the suite keeps a file of its own, when it is not a regular
file: a FIFO, a device or a socket put there by hand is never opened (a FIFO nobody writes to
blocks its reader for good), and a message names it as what it is rather than as missing."""

from __future__ import annotations

import os
import stat
from pathlib import Path

__all__ = ["odd_file", "odd_table", "mode_kind"]

#: the tables that make a directory a results directory (a study run's, a sweep's)
TABLES = ("claims.parquet", "sweep.parquet")

_KINDS = (
    (stat.S_ISLNK, "a symbolic link"),  # (an lstat's mode: os.stat follows it)
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISDIR, "a directory"),
)


def mode_kind(mode: int) -> str:
    """What a file of the ``st_mode`` ``mode`` is in a message (``"a FIFO (named pipe)"``,
    ``"a symbolic link"`` of an ``lstat``, ``"a directory"``, ...), for one that is not a
    regular file (:mod:`sim.mc.export_edits` names an export's place in the same words)."""
    return next((what for test, what in _KINDS if test(mode)), "not a regular file")


def odd_file(p: str | Path) -> str | None:
    """What ``p`` is when something other than a regular file stands there (a symbolic link
    followed): ``"a FIFO (named pipe)"``, ``"a character device"``, ``"a directory"``, ...,
    ``"a symbolic link that leads nowhere"``; None for a regular file, nothing at all, or a
    path that cannot be looked at."""
    try:
        mode = os.stat(p).st_mode
    except OSError:  # nothing there, under a file, or no permission to look: not named
        return "a symbolic link that leads nowhere" if os.path.islink(p) else None
    if stat.S_ISREG(mode):
        return None
    return mode_kind(mode)


def odd_table(d: str | Path) -> str | None:
    """One line when the ``claims.parquet`` or ``sweep.parquet`` of the results directory
    ``d`` is something other than a regular file (readers that look for the table with
    ``is_file`` passed the directory over: "no claims.parquet", or a study left out of
    REPORT.md without a word), else None."""
    for name in TABLES:
        if (what := odd_file(Path(d) / name)) is not None:
            return f"{Path(d) / name} is {what}, not a table the suite wrote"
    return None
