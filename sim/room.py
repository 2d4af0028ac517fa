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

The load of a network builds it and factorises its normals (the run's memory, which the
estimate counts) before the run builds it again, and what the load mapped stays mapped (the
heap freed but not handed back, numba): counted again on top of it after the load, the estimate
refused a 50,176-point grid (1.39 GiB estimated; 0.47 GiB mapped before the load, 1.07 GiB
after it, 1.87 GiB at its peak, which the run did not pass) under ``ulimit -v 2000000`` after
30 s of building, though with the check off it ran to the end there. :func:`loaded` records
what a study's load mapped under its config, and the check of that config counts it once: the
room is what the limit leaves beside what the process mapped before the load, and what it maps
beyond the load's own (a caller's arrays) is counted (:func:`short_room`). The check before the
build (:func:`sim.studies.network.validate.fits_estimate`) is the same comparison, made first.
"""

from __future__ import annotations

import hashlib
import json
import os
import resource
import threading
from collections.abc import Callable, Mapping

from sim.mc.config import ConfigError
from sim.mc.estimate import Estimate, check_limits

__all__ = ["check_room", "held_by_load", "limits_set", "loaded", "mapped_bytes", "short_room"]


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


#: what the loads of study files mapped, by config (:func:`loaded`): {statm field: (mapped
#: before the load, what the load added)}; the last :data:`_KEPT` configs loaded
_LOADS: dict[str, dict[int, tuple[int, int]]] = {}
_KEPT = 32
_LOCK = threading.Lock()  # loads in threads at once: one dropped the oldest as another put in


def _config_key(cfg: Mapping) -> str | None:
    """A config's sha256, as its record in :data:`_LOADS` is found (a copy finds it); None
    for one no JSON holds (nothing is recorded under it)."""
    try:
        text = json.dumps(cfg, sort_keys=True, default=repr, ensure_ascii=False)
    except (TypeError, ValueError, RecursionError):
        return None
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()


def loaded(load: Callable[[], tuple]) -> tuple:
    """``load()`` (a study file's load: ``(study, cfg)``), with what the process mapped
    before it and what the load added recorded under ``cfg``, for :func:`check_room`."""
    before = {field: mapped_bytes(field) for _, field, _ in _LIMITS}
    study, cfg = load()
    rec = {}
    for field, b in before.items():
        if b is not None and (a := mapped_bytes(field)) is not None:
            rec[field] = (b, max(a - b, 0))
    if (key := _config_key(cfg)) is None:
        return study, cfg
    with _LOCK:
        _LOADS.pop(key, None)
        _LOADS[key] = rec
        while len(_LOADS) > _KEPT:
            del _LOADS[next(iter(_LOADS))]
    return study, cfg


def held_by_load(cfg: Mapping | None) -> dict[int, tuple[int, int]]:
    """What the load of ``cfg`` mapped (:func:`loaded`), ``{}`` if it was not recorded."""
    key = None if cfg is None else _config_key(cfg)
    return {} if key is None else _LOADS.get(key, {})


def limits_set() -> str:
    """The limits of memory this process runs under, as words (``ulimit -v is 1250000 kB``),
    or ``""``: what a MemoryError in the middle of a run names."""
    caps = ((words, resource.getrlimit(limit)[0]) for limit, _, words in _LIMITS)
    return ", ".join(f"{w} is {c // 1024} kB" for w, c in caps if c != resource.RLIM_INFINITY)


def short_room(need: float, held: Mapping[int, tuple[int, int]] | None = None) -> str:
    """Where ``need`` bytes more exceed what ``ulimit -v`` or ``ulimit -d`` leaves this
    process: ``"ulimit -v (1300000 kB) leaves this process about 0.6 GiB beside the 0.64 GiB
    it maps already"``, else ``""``. ``held``: what the study's load mapped (:func:`loaded`),
    ``{field: (before, added)}``; of what the process maps beyond ``before``, up to ``added``
    (and ``need``) is the run's own memory, which the estimate counts: not counted twice."""
    for limit, field, words in _LIMITS:
        cap = resource.getrlimit(limit)[0]
        used = mapped_bytes(field)
        if cap == resource.RLIM_INFINITY or used is None:
            continue
        before, added = (held or {}).get(field, (used, 0))
        reused = min(max(used - before, 0), added, need)
        if not need > cap - used + reused:
            continue
        again = f", of which the run reuses the {reused / 2**30:.3g} GiB its load mapped"
        return (
            f"{words} ({cap // 1024} kB) leaves this process about "
            f"{max(cap - used, 0) / 2**30:.3g} GiB beside the {used / 2**30:.3g} GiB it maps "
            f"already{again if reused > 0 else ''}"
        )
    return ""


def check_room(
    est: Estimate,
    max_memory_gb: float | None = None,
    max_adjustments: float | None = None,
    workers: int = 1,
    cfg: Mapping | None = None,
) -> None:
    """:func:`sim.mc.estimate.check_limits`, then ConfigError when the estimate of one
    process (``est.bytes``) exceeds what ``ulimit -v`` or ``ulimit -d`` leaves it, what the
    load of ``cfg`` mapped counted once (:func:`loaded`, :func:`short_room`)."""
    check_limits(est, max_memory_gb, max_adjustments, workers)
    if short := short_room(est.bytes, held_by_load(cfg)):
        each = " a worker" if workers > 1 else ""
        cell = f" (the sweep's cell of {est.cell})" if est.cell else ""
        words = short.split(" (", 1)[0]
        raise ConfigError(
            None,
            f"{est.study}: the run needs about {est.bytes / 2**30:.3g} GiB of memory{each}{cell}, "
            f"and {short}: raise {words}, or reduce {est.memory_advice()}",
        )
