"""Reading one results directory that a run may publish meanwhile: read again when it changed.

A run publishes its results by putting its finished directory in the place of the old one in
one step (:func:`sim.mc.publish.publish`), so the path always names one whole run; but a
reader that opens its files one after another may take some of the old run's and some of the
new one's. ``sim show`` printed the new run's claims under the old run's configuration note
(exit 0), and ``Results.table`` called the directory one that "mixes results of two runs; run
its study again" (its ``run.json`` read before the swap, the table after). :func:`settled`
reads again when the directory is another one after the reading (its inode: every publish
puts a new directory in place), and names it when it changed at every reading; ``sim report``
reads a results root by the same rule (:func:`reread`: its directories). (``make verify``
keeps its own loop: it compares tables' content too, and its outcome is a comparison.)
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, TypeVar

from sim.mc.config import ConfigError

__all__ = ["READS", "Spun", "reread", "settled"]

T = TypeVar("T")

#: how many times :func:`settled` reads a directory at most
READS = 3


def _identity(d: Path) -> tuple[int, int] | None:
    """The directory ``d`` is (device, inode), or None when it is not there."""
    try:
        st = os.stat(d)
    except (OSError, ValueError):
        return None
    return st.st_dev, st.st_ino


def reread(read: Callable[[], T], state: Callable[[], object], last_stands: bool = False) -> T:
    """``read()``, made again when ``state()`` (what a publish changes: a directory's inode,
    a results root's directories) differs after it, also when it failed (a
    :class:`ConfigError` or an OSError of a reading of two runs' files), at most :data:`READS`
    times. Then the last outcome stands (``last_stands``: ``sim report``) or :class:`Spun` is
    raised."""
    for k in range(READS):
        before = state()
        try:
            value = read()
        except (ConfigError, OSError):
            if state() == before or (last_stands and k + 1 == READS):
                raise
            continue
        if state() == before or (last_stands and k + 1 == READS):
            return value
    raise Spun


class Spun(Exception):
    """What was read changed at every one of :data:`READS` readings."""


def settled(d: str | Path, read: Callable[[], T], key: str) -> T:
    """``read()`` of the results directory ``d``, made again when another directory took its
    place while it read (a run published there; :func:`reread`); after :data:`READS` such
    readings a :class:`ConfigError` naming ``key`` and ``d`` says so."""
    try:
        return reread(read, lambda: _identity(Path(d)))
    except Spun:
        raise ConfigError(
            key,
            f"{d} was replaced while it was read, {READS} times (a run publishing its results "
            "there?): read it when that run has ended",
        ) from None
