"""How many chunks a run needs: a jackknife interval is taken over the chunks of a run's
``trials`` in chunks of ``chunk`` (:func:`sim.mc.runner.jackknife`), and a config that gives
too few is refused at load. Plain numbers, no NumPy: the command line's help and a study's
schema read them before any trial is drawn (:mod:`sim.mc.runner` holds the runner itself)."""

from __future__ import annotations

from typing import Mapping

from sim.mc.config import ConfigError

__all__ = ["MIN_CHUNKS", "require_chunks"]

#: the fewest chunks a jackknife interval is computed from: with C chunks the interval's
#: standard error has C - 1 degrees of freedom, and below about 20 it is itself too uncertain
#: to decide a claim on (the issue-25 run of 2 chunks gave a proportion's interval [0.07, 0.07])
MIN_CHUNKS = 20


def require_chunks(cfg: Mapping, need: int = MIN_CHUNKS, use: str = "jackknife intervals") -> None:
    """Refuse, at load time, a config whose ``trials`` in chunks of ``chunk`` give fewer than
    ``need`` chunks (:class:`sim.mc.config.ConfigError`, one line naming ``chunk``, or
    ``trials`` when no chunk size can give enough). A study whose results call
    :func:`sim.mc.runner.jackknife` on the chunks of its ``trials``/``chunk`` run calls it from its schema's
    ``check`` (brown_table1, brown_dilution, network): without it a run of too few chunks
    computed every trial and then failed in :func:`jackknife`. ``need >= 2``."""
    trials, chunk = cfg["trials"], cfg["chunk"]
    have = -(-trials // chunk)
    if have >= need:
        return
    if trials < need:  # chunk = 1 gives `trials` chunks: only more trials help
        # both numbers: "at least 20 trials (one per chunk)" followed with the chunk kept
        # (a chunk of 2 given) was refused again, "make chunk at most 1"
        fix = f"give at least {need} trials in chunks of 1, or {need * chunk:,} in chunks of {chunk:,}"
        fix = fix if chunk > 1 else f"give at least {need} trials"  # not "20 ..., or 20 ..."
    else:  # the largest chunk c with ceil(trials / c) >= need
        fix = f"make chunk at most {-(-trials // (need - 1)) - 1}"
    raise ConfigError(
        "trials" if trials < need else "chunk",
        f"{trials:,} trials in chunks of {chunk:,} give {have} chunk{'s' * (have != 1)}; "
        f"this study's {use} are taken over chunks and need at least {need}: {fix}",
    )
