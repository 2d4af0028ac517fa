"""A sweep's checks outside its cells' runs (:mod:`sim.execute` runs them): its estimate
against the limits (:func:`sweep_limits`, the cells the study refuses left out), the cells the
study refuses named once (:func:`check_sweep`), and which failure of a cell is the machine's,
not the cell's (:func:`not_the_cells`)."""

from __future__ import annotations

from concurrent.futures import BrokenExecutor
from typing import Any, Mapping

from sim.mc.config import ConfigError
from sim.mc.estimate import estimate
from sim.mc.sweep import refused_cells, refused_note
from sim.room import check_room
from sim.standard_error import say
from sim.threads import interrupted, shadowed

__all__ = ["sweep_limits", "check_sweep", "not_the_cells"]


def sweep_limits(
    study,
    cfg: dict,
    sweep: Mapping[str, Any],
    max_memory_gb: float | None = None,
    max_adjustments: float | None = None,
    workers: int = 1,
):
    """The run's estimate (:func:`sim.mc.estimate.estimate`), checked against the limits
    (``sim run``, ``sim check``, ``python -m sim.batch``). A sweep is estimated without the
    cells the study refuses (recorded infeasible, never run): a 150 x 150 plate outside the
    format, refused in its cell, made a sweep of it and a 5 x 5 plate "need 0.744 GiB" and
    refused it, and ``sim check`` said "120 trials in 3 sweep cells" of a sweep that runs one. A cell refused for the limit itself is named
    (:func:`sim.mc.sweep.refused_cells`). What the load of ``cfg`` mapped is counted once
    (:func:`sim.room.loaded`)."""
    refused = refused_cells(study, cfg, sweep) if sweep else ({}, 0)
    _CHECKED[:] = [(study, cfg, sweep, refused)] if sweep else []  # for check_sweep, once
    est = estimate(cfg, sweep, skip=refused[0])
    check_room(est, max_memory_gb, max_adjustments, workers, cfg)  # and ulimit -v's
    return est


#: the cells :func:`sweep_limits` validated, ``[(study, cfg, sweep, (refused, checked))]``,
#: taken by the :func:`check_sweep` of the same objects that follows it (the cells of a
#: 2,500-point network take 0.7 s each to validate: not twice)
_CHECKED: list = []


def not_the_cells(e: BaseException) -> bool:
    """Whether a sweep cell's failure is the machine's, not its configuration's: a write cut
    short (a full disk, ``ulimit -f``), memory, a worker killed, an interrupt inside a library,
    a user's module shadowing one. Such a cell was recorded infeasible ("failed: [Errno 28]
    No space left on device") and the sweep published with exit 0; it now stops the run as
    it stops a single study's (one line; the finished chunks are kept for the same command).
    So does an input file of the study (a GNU Gama file, a Wolf table) changed since the study
    was loaded (its ``...sha256`` key): recorded as the cell's failure, the sweep published
    with exit 0 results that a clean run of its config does not give."""
    return (
        isinstance(e, (OSError, MemoryError, BrokenExecutor))
        or interrupted(e)
        or shadowed(e) is not None
        or (isinstance(e, ConfigError) and str(e.key or "").endswith("sha256"))
    )


def check_sweep(study, cfg: dict, sweep: Mapping[str, Any], quiet: bool = False) -> None:
    """Before anything runs (``sim run``, ``sim check``, the API, ``sim.batch``): a sweep in
    which the study refuses every cell is refused (:class:`ConfigError` naming the swept key
    and its values); the cells it refuses of a sweep that has others are named once on
    standard error (:func:`sim.mc.sweep.refused_note`; they are recorded, not run), unless
    ``quiet`` (``sweep.parquet`` records them with the reason)."""
    if not sweep:
        return
    done = [r for s, c, w, r in _CHECKED if s is study and c is cfg and w is sweep]
    _CHECKED.clear()
    note = refused_note(sweep, *(done[0] if done else refused_cells(study, cfg, sweep)))
    if note and not quiet:
        say(f"sim: {note}")
