"""Reading one results directory that a run may publish meanwhile: read again when it changed.

A run publishes its results by putting its finished directory in the place of the old one in
one step (:func:`sim.mc.publish.publish`), so the path always names one whole run; but a
reader that opens its files one after another may take some of the old run's and some of the
new one's. ``sim show`` printed the new run's claims under the old run's configuration note
(exit 0), and ``Results.table`` called the directory one that "mixes results of two runs; run
its study again" (its ``run.json`` read before the swap, the table after). :func:`settled`
reads again when the directory is another one after the reading (its inode: every publish
puts a new directory in place), and names it when it changed at every reading. (``sim
report`` and ``make verify`` do the same over a results root: their own ``_settled``.) Not
imported by any study (no code hash).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, TypeVar

from sim.mc.config import ConfigError

__all__ = ["READS", "settled"]

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


def settled(d: str | Path, read: Callable[[], T], key: str) -> T:
    """``read()`` of the results directory ``d``, made again when another directory took its
    place while it read (a run published there), also when it failed (a :class:`ConfigError`
    or an OSError of a reading of two runs' files); after :data:`READS` such readings a
    :class:`ConfigError` naming ``key`` and ``d`` says so."""
    for _ in range(READS):
        before = _identity(Path(d))
        try:
            value = read()
        except (ConfigError, OSError):
            if _identity(Path(d)) == before:
                raise
            continue
        if _identity(Path(d)) == before:
            return value
    raise ConfigError(
        key,
        f"{d} was replaced while it was read, {READS} times (a run publishing its results "
        "there?): read it when that run has ended",
    )
