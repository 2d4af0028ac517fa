"""Results that a publish replaced but a kill left in the staging directory.

:func:`sim.mc.publish.publish` swaps the finished staging directory ``.<out>.partial`` with
``<out>`` in one step, then moves the old results (now in the staging directory) aside and
removes them. A run killed (or interrupted) between the two left the replaced results in
``.<out>.partial``, where the next run took them for an unfinished run of another config and
refused to start without ``--overwrite`` (advising to "run again with its values", which would
have brought the old results back over the new ones). The new results name the run record of
the results they replaced by its sha256 (``run.json`` ``replaced``): a staging directory
holding exactly that record is removed before the next run starts, once every file of the
user's in it is also in ``<out>`` (copied there before the swap); else the run is refused in
one line naming the file. A staging directory whose lock a run holds is never taken for them:
that run's sealed record is byte for byte the replaced one when it re-runs their config with
the same code (a second ``sim run`` of the same command removed the staging directory of a
run about to publish, ran the study alongside it, and the first ended "cannot be read as the
run's record").
"""

from __future__ import annotations

from pathlib import Path

from sim.mc.config import ConfigError
from sim.mc.dead_dirs import lock_held
from sim.mc.publish import _foreign, _present, _remove_record_last, file_sha256
from sim.mc.storage import RECORD, read_record

__all__ = ["replaced_results", "clear_replaced"]


def replaced_results(stage: Path, out: Path) -> bool:
    """Whether ``stage`` holds the results that the run published in ``out`` replaced: its
    run record is the one ``out``'s run record names as replaced, and no run holds its lock
    (module docstring)."""
    if stage.is_symlink() or not stage.is_dir() or out.is_symlink():
        return False
    rec = read_record(out)
    want = rec.get("replaced") if rec else None
    if not isinstance(want, str) or read_record(stage) is None:
        return False
    try:
        return file_sha256(stage / RECORD) == want and not lock_held(stage)
    except OSError:
        return False


def clear_replaced(stage: Path, out: Path, shown: str) -> None:
    """Remove the replaced results left in ``stage`` (:func:`replaced_results`; nothing
    otherwise), silently (as publishing would have); refused (:class:`ConfigError`, one line) when a
    file of the user's there is not in ``out``, or when they cannot be removed."""
    if not replaced_results(stage, out):
        return
    left = f"{stage} holds the results that the last run into {shown} replaced (it was stopped "
    try:
        lost = [f for f in _foreign(stage) if not _present(out / f)]
    except ConfigError:  # its record does not list the files its run wrote
        lost = [RECORD]
    if lost:
        raise ConfigError(
            "--out",
            f"{left}before removing them), with {stage / lost[0]}, which is not in {shown}: "
            "move what you need out of it, remove it and run again",
        )
    _remove_record_last(stage)
    if stage.exists() or stage.is_symlink():
        raise ConfigError(
            "--out", f"{left}before removing them), and they cannot be removed: remove {stage}"
        )
