"""Stop signals held while a run publishes its results (not in :mod:`sim.stops`, which every
study's code hash holds: this is the command's, not a study's)."""

from __future__ import annotations

import signal
from contextlib import contextmanager

from sim.stops import in_main_thread

__all__ = ["held_stops"]


@contextmanager
def held_stops():
    """While open, a stop signal (SIGINT, SIGTERM, SIGHUP) whose handler is a Python function
    (Ctrl-C's, the commands', a caller's own) is recorded, not handled; it is handled on
    closing, by the handler that was there. Around publishing a run: the swap of the results
    directory and its clean-up are a few renames, and an interrupt between two of them left
    the new results published but the command saying "run the same command again to finish
    the missing chunks" (exit 130), with the old results in a hidden directory. Also around
    the drivers' last writes after their runs ended (``sim.batch``'s ``--timings``, ``make
    verify``'s record and the removal of its temporary scratch directory). In another
    thread than the main one nothing is held (a signal is handled in the main thread)."""
    signals = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP) if in_main_thread() else ()
    old = {s: h for s in signals if callable(h := signal.getsignal(s))}
    got: list[int] = []
    for s in old:
        signal.signal(s, lambda signum, frame: got.append(signum))
    try:
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, h)
    for s in dict.fromkeys(got):  # handled now, as it would have been (raises KeyboardInterrupt)
        signal.raise_signal(s)
