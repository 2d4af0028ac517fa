"""The mark of a report that a batch set out to rebuild and did not: ``<results>/.report-due``.

``python -m sim.batch --report`` rebuilds ``REPORT.md`` after its runs published results; killed
outright while ``sim report`` ran (``kill -9``, the out-of-memory killer: no handler runs, and
its ``sim report`` child is stopped with it) it left the old ``REPORT.md`` beside the new
results without a word, then or later. The batch sets the mark before it starts ``sim report``
(:func:`mark_due`); ``sim report`` clears it once ``REPORT.md`` is written (:func:`clear_due`),
so the mark outlives only a report that did not end; ``make verify`` and the next batch name
it (:func:`due_words`). A hidden file of the suite's: no study's results, never reported.
Not imported by any study (no code hash).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

__all__ = ["DUE", "mark_due", "clear_due", "due_words"]

#: the mark's name in the results directory
DUE = ".report-due"


def mark_due(results: Path) -> None:
    """Set the mark in ``results`` (its text: this process's pid); a results directory that
    cannot hold it goes without (the report's own failure is said where it happens). Written
    only as a regular file of that name, never through a link (it wrote the pid over the file
    a ``.report-due`` symbolic or hard link named) nor into a FIFO (opening it for writing
    waited for a reader: the batch hung after its runs)."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK
    try:
        fd = os.open(Path(results) / DUE, flags, 0o644)
    except OSError:  # a link (ELOOP), a FIFO nobody reads (ENXIO), a directory, read-only
        return
    try:
        st = os.fstat(fd)
        if stat.S_ISREG(st.st_mode) and st.st_nlink == 1:  # (a hard link: a user's file too)
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()}\n".encode("ascii"))
    except OSError:
        pass
    finally:
        os.close(fd)


def clear_due(results: Path) -> None:
    """Clear the mark in ``results`` (``REPORT.md`` was just written); a link or a directory of
    that name is not the suite's and is left."""
    p = Path(results) / DUE
    try:
        if p.is_file() and not p.is_symlink():
            p.unlink()
    except OSError:
        pass


def due_words(results: Path) -> str | None:
    """What the mark in ``results`` says, or None (no mark, or not the suite's)."""
    p = Path(results) / DUE
    try:
        if not p.is_file() or p.is_symlink():
            return None
    except OSError:
        return None
    return (
        f"{Path(results) / 'REPORT.md'} was not rebuilt after a batch's runs published results "
        "(its sim report did not finish: killed, interrupted or refused); "
        f"sim report --results {results} rebuilds it"
    )
