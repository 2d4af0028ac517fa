"""The memory of the runs ``python -m sim.batch --jobs J`` holds side by side.

Each run's estimate (:func:`sim.mc.estimate.estimate`, its bytes times its ``--workers``) is
checked alone against the memory limit before any run starts (the run's ``--max-memory-gb``,
else ``SIM_MAX_MEMORY_GB``, else 8 GiB), so J large runs side by side could need J times the
limit: three network studies of 5 GiB each under ``--jobs 3`` passed the batch's checks one
by one and then held 15 GiB together, on a machine the limit was set for. The batch now starts
a run only while its estimate and those of the runs going fit in the limit together; a run
that does not fit beside them waits for runs to end (one line says so), and a run alone
always starts (its own check bounded it). Runs that fit side by side still go ``J`` at a
time; nothing is refused that fits one at a time, and ``--stale-only``'s current studies,
which do not run, hold nothing.
"""

from __future__ import annotations

import math
import sys
import threading

from sim.mc.estimate import _gib
from sim.mc.memory_limit import DEFAULT_MAX_MEMORY_GB, limit_value

__all__ = ["MemoryGate", "batch_memory_gb"]


def batch_memory_gb(given: float | None) -> float:
    """The memory limit of the batch's runs in GiB: their ``--max-memory-gb`` (``given``),
    else ``SIM_MAX_MEMORY_GB``, else :data:`DEFAULT_MAX_MEMORY_GB` (as each run reads it)."""
    return limit_value(given, "SIM_MAX_MEMORY_GB", DEFAULT_MAX_MEMORY_GB, "--max-memory-gb")


class MemoryGate:
    """Admits runs while their estimated bytes (``needs``: ``{file: bytes}``; a file not in it
    needs none) together stay within the memory limit (``given``: the runs'
    ``--max-memory-gb``, :func:`batch_memory_gb`); one run is always admitted when none is
    going. :meth:`around` runs one when it fits; :meth:`enter` waits for room, :meth:`leave`
    gives a run's bytes back."""

    def __init__(self, needs: dict | None = None, given: float | None = None, say=None) -> None:
        self.needs = needs or {}
        self.limit = batch_memory_gb(given) * 2**30 if self.needs else math.inf
        self.held = 0.0  # the estimated bytes of the runs going
        self.cond = threading.Condition()
        self.say = say or (lambda line: print(line, file=sys.stderr, flush=True))

    def around(self, f, stop: threading.Event, run, stopped):
        """``run(f)`` once ``f``'s estimate fits beside the runs going, its bytes held while it
        runs; ``stopped()`` when ``stop`` was set while it waited."""
        need = self.needs.get(f, 0.0)
        if not self.enter(getattr(f, "name", str(f)), need, stop):
            return stopped()
        try:
            return run(f)
        finally:
            self.leave(need)

    def enter(self, name: str, need: float, stop: threading.Event) -> bool:
        """Wait until ``need`` bytes fit beside the runs going (or none is going), then hold
        them; False (nothing held) when ``stop`` is set meanwhile (an interrupt)."""
        need = max(float(need), 0.0)
        with self.cond:
            said = False
            while self.held > 0 and self.held + need > self.limit and not stop.is_set():
                if not said:
                    self.say(
                        f"sim.batch: note: {name} waits for a run to end: its estimate of "
                        f"{_gib(need)} and the {_gib(self.held)} of the runs going exceed the "
                        f"{self.limit / 2**30:g} GiB memory limit together (--max-memory-gb or "
                        "SIM_MAX_MEMORY_GB)"
                    )
                    said = True
                self.cond.wait(0.25)  # (a stop is seen within a quarter second)
            if stop.is_set():
                return False
            self.held += need
            return True

    def leave(self, need: float) -> None:
        """Give back the ``need`` bytes a run held and wake the runs that wait."""
        with self.cond:
            self.held = max(self.held - max(float(need), 0.0), 0.0)
            self.cond.notify_all()
