"""Whether a directory a killed process left is still in use: the test shared by the sweeps
of such directories (a killed ``run(out=None)``'s, :mod:`sim.api_tmp`; a killed ``make
verify``'s, :mod:`sim.report.verify.scratch`). Not imported by any study (no code hash)."""

from __future__ import annotations

import fcntl
import os
from pathlib import Path

from sim.mc.storage import LOCK

__all__ = ["lock_held"]


def lock_held(d: Path) -> bool:
    """True when a ``.lock`` file under ``d`` is held (a run still writes there) or cannot
    be tried."""
    for top, dirs, files in os.walk(d):
        dirs[:] = [n for n in dirs if not os.path.islink(os.path.join(top, n))]
        if LOCK in files:
            try:
                fd = os.open(os.path.join(top, LOCK), os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
            except OSError:
                return True
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                return True
            finally:
                os.close(fd)  # releases the lock just taken
    return False
