"""What a results directory that is not there is, when a run of it did not finish: its staging
directory ``.<name>.partial`` (:func:`sim.mc.outputs.stage_dir`) is there, locked by the run
writing it now or left by a run that was stopped (killed, interrupted, or failed with finished
chunks). ``sim show DIR``, ``sim.Results`` and ``sim report`` said only "does not exist" (or
"no study results") of the output of a run killed before it published, never that the same
command finishes it."""

from __future__ import annotations

import os
from pathlib import Path

from sim.mc.dead_dirs import lock_held
from sim.mc.outputs import STAGE_SUFFIX, stage_dir
from sim.mc.storage import read_record

__all__ = ["unfinished", "unfinished_in"]


def unfinished(d: Path) -> str | None:
    """Words on the run of the absent results directory ``d`` that did not finish (its staging
    directory is there), or None (``d`` is there, or no run of it left anything)."""
    d = Path(d)
    if os.path.lexists(d) or not d.name:
        return None
    stage = stage_dir(d)
    try:  # a name of 247 to 255 bytes: its staging directory's is over the system's limit
        if stage.is_symlink() or not stage.is_dir():
            return None
    except OSError:  # (ENAMETOOLONG: sim show said the staging name, the API raised OSError)
        return None
    if lock_held(stage):
        return f"a run is writing it now (in {stage}); it is there when that run ends"
    failed = (read_record(stage) or {}).get("failed")
    if isinstance(failed, str):  # (a failure of the run itself: the same command fails again)
        return f"its run failed ({' '.join(failed.split())[:200]}); {stage} keeps its chunks"
    return f"its run did not finish ({stage} holds it): the same command again finishes it"


def unfinished_in(results: Path) -> str | None:
    """Words on the first unfinished run in the directory ``results`` (``sim report`` found
    no results there), or None."""
    try:
        stages = sorted(p for p in Path(results).iterdir() if p.name.endswith(STAGE_SUFFIX))
    except OSError:
        return None
    for stage in stages:
        name = stage.name[1 : -len(STAGE_SUFFIX)]  # ".partial", "..partial": no run's (with_name
        if name in ("", ".", "..") or not stage.name.startswith("."):  # raised ValueError)
            continue
        if (words := unfinished(stage.with_name(name))) is not None:
            return f"{stage.with_name(name)}: {words}"
    return None
