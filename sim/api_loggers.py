"""The caller's logger levels kept across a run of the Python API (:mod:`sim.api`): a Dask
run silences the chatty loggers of its cluster, which must not outlive the run in a user's
process."""

from __future__ import annotations

import contextlib
import logging

_CHATTY = ("asyncio", "distributed", "tornado")


@contextlib.contextmanager
def loggers_kept():
    """The levels of the caller's loggers of :data:`_CHATTY` (and below) put back after the
    run: an interrupted Dask run silences them for the cluster's closing chatter, which in a
    user's process silenced the user's own ``asyncio`` errors for good. Loggers below them
    that the run made (its cluster's) stay silenced."""
    known = logging.root.manager.loggerDict
    levels = {n: logging.getLogger(n).level for n in _CHATTY}  # NOTSET unless set
    levels.update(
        (n, lg.level)
        for n, lg in list(known.items())
        if n.split(".")[0] in _CHATTY and isinstance(lg, logging.Logger)
    )
    try:
        yield
    finally:
        for n, level in levels.items():
            logging.getLogger(n).setLevel(level)
