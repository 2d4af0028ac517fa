"""One line for an exception raised inside a study's run (sim.execute): the study part where it
was raised and, where the message says which, the config key to change; for a MemoryError the
memory limit in force (``ulimit -v``/``-d``) and the keys that set the run's memory
(sim.mc.estimate). No model: the words of the failure, for every study."""

from __future__ import annotations

import os

from sim.mc.config import StudyError
from sim.mc.estimate import keys_advice
from sim.room import limits_set

__all__ = ["numeric_failure", "hint", "memory_hint"]


def numeric_failure(e: BaseException, study, cfg: dict, keys: tuple = ()) -> StudyError:
    """One line for an exception raised inside a study's run: the study part (the innermost
    frame in study code) and, where the message says which, the config key to change (for
    memory, the estimate's ``keys`` and the ``ulimit`` in force: :func:`memory_hint`)."""
    import traceback

    frames = [
        f
        for f in traceback.extract_tb(e.__traceback__)
        if "/sim/" in f.filename.replace(os.sep, "/")
    ]
    plumbing = ("runner.py", "cli.py", "storage.py", "sweep.py", "claims.py")
    study_code = [f for f in frames if "/sim/studies/" in f.filename.replace(os.sep, "/")]
    model = [f for f in frames if not f.filename.replace(os.sep, "/").endswith(plumbing)]
    part = None
    for f in (study_code or model)[-1:]:
        mod = f.filename.replace(os.sep, "/").rsplit("/sim/", 1)[1][:-3].replace("/", ".")
        part = f"sim.{mod}.{f.name}"
    msg = (str(e).strip().splitlines() or [""])[0][:300]
    advice = hint(msg, type(e).__name__, study.schema, keys)
    where = f" in {part}" if part else ""
    return StudyError(f"{cfg['study']}: the run failed{where}: {type(e).__name__}: {msg}{advice}")


_HINTS = (  # message words -> config keys (the first that the study has is named)
    (("iteration", "converge"), ("solver.max_iter", "solver.tol_mm")),
    (("overflow",), ("errors.setting_sigma_um", "plate.format_mm")),
    (("svd", "singular", "degenerate", "collinear"), ("plate.grid", "plate.points", "marks.grid")),
)


def hint(msg: str, kind: str, schema, keys: tuple = ()) -> str:
    """The advice that ends a failure's line: the first key of ``schema`` its words name
    (:data:`_HINTS`), or for memory :func:`memory_hint`; ``""`` where nothing fits."""
    low = (msg + " " + kind).lower()
    for words, named in _HINTS:
        if any(w in low for w in words):
            have = [k for k in named if k in schema]
            if have:
                return f" (check {have[0]})"
    return memory_hint(keys) if "memory" in low else ""


def memory_hint(keys: tuple) -> str:
    """What to change after a MemoryError mid-run: the limit in force and the keys that set
    the run's memory. It said "reduce trials, chunk or the sizes in the study file" for
    brown_dilution's region (``region.points``) failing under ``ulimit -v 1250000``."""
    limits = limits_set()
    return (
        f" ({limits}: raise {'them' if ', ' in limits else 'it'}, or reduce {keys_advice(keys)})"
        if limits
        else (f" (reduce {keys_advice(keys)})")
    )
