"""The address space a run may still map, against its memory estimate.

``--max-memory-gb`` (default 8 GiB) bounds a run's estimate; a limit of address space
(``ulimit -v``, ``RLIMIT_AS``) below the estimate was not looked at: a run of
``brown_table1`` on a 100 x 100 plate (about 0.9 GiB) under ``ulimit -v 1400000`` computed
every chunk, then failed on "MemoryError: Unable to allocate 183. MiB", naming no limit (a
large run: hours of work first); so under a limit of data (``ulimit -d``). :func:`check_room` refuses such a run before it starts, one
line naming the limit, where the estimate exceeds what the limit leaves beside what the
process maps already (its libraries: about 700 MB). It refuses only what cannot fit: the
libraries loaded later (numba's) and the allocator's slack are not counted. Each worker is
a process of its own under the same limit, so one worker's share is compared. The refusal
names the keys to reduce (and a sweep's largest cell) as the memory limit's does: it sent the
user to "sim check", which refused the same run in the same words.
"""

from __future__ import annotations

import os
import resource

from sim.mc.config import ConfigError
from sim.mc.estimate import Estimate, _either, check_limits

__all__ = ["check_room", "limits_set", "mapped_bytes", "short_room"]


def mapped_bytes(field: int = 0) -> int | None:
    """What this process maps now, in bytes: its address space (``VmSize``, field 0 of
    ``/proc/self/statm``) or its data (field 5, what ``ulimit -d`` counts); None where it
    cannot be read."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[field]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return None


#: the limits a run's memory is compared with: (limit, field of statm, its shell words)
_LIMITS = ((resource.RLIMIT_AS, 0, "ulimit -v"), (resource.RLIMIT_DATA, 5, "ulimit -d"))


def limits_set() -> str:
    """The limits of memory this process runs under, as words (``ulimit -v is 1250000 kB``),
    or ``""``: what a MemoryError in the middle of a run names."""
    caps = ((words, resource.getrlimit(limit)[0]) for limit, _, words in _LIMITS)
    return ", ".join(f"{w} is {c // 1024} kB" for w, c in caps if c != resource.RLIM_INFINITY)


def short_room(need: float) -> str:
    """Where ``need`` bytes more exceed what ``ulimit -v`` or ``ulimit -d`` leaves this
    process: ``"ulimit -v (1300000 kB) leaves this process about 0.6 GiB beside the 0.64 GiB
    it maps already"``, else ``""``."""
    for limit, field, words in _LIMITS:
        cap = resource.getrlimit(limit)[0]
        used = mapped_bytes(field)
        if cap == resource.RLIM_INFINITY or used is None or not need > cap - used:
            continue
        return (
            f"{words} ({cap // 1024} kB) leaves this process about "
            f"{max(cap - used, 0) / 2**30:.3g} GiB beside the {used / 2**30:.3g} GiB it maps "
            "already"
        )
    return ""


def check_room(
    est: Estimate,
    max_memory_gb: float | None = None,
    max_adjustments: float | None = None,
    workers: int = 1,
) -> None:
    """:func:`sim.mc.estimate.check_limits`, then ConfigError when the estimate of one
    process (``est.bytes``) exceeds what ``ulimit -v`` or ``ulimit -d`` leaves it."""
    check_limits(est, max_memory_gb, max_adjustments, workers)
    if short := short_room(est.bytes):
        each = " a worker" if workers > 1 else ""
        cell = f" (the sweep's cell of {est.cell})" if est.cell else ""
        words = short.split(" (", 1)[0]
        raise ConfigError(
            None,
            f"{est.study}: the run needs about {est.bytes / 2**30:.3g} GiB of memory{each}{cell}, "
            f"and {short}: raise {words}, or reduce {_either(est.memory_keys)}",
        )
