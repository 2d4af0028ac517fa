"""The study and config a command's options resolve (:func:`load_run`): ``sim run`` and
``sim check`` (:mod:`sim.cli` imports their modules when the command runs) and
``python -m sim.batch``'s checks use it. It loads what reading a study file needs (the
study's keys and checks) and nothing of the run: a study file ``sim check`` refuses (an
unknown key, a bad value) is refused before the runner, the estimate's engine and the report
are imported (they were, by :mod:`sim.cli_run`, which held this function, and
:mod:`sim.execute`: about 0.7 s of CPU before the file was read)."""

from __future__ import annotations

from sim.mc.config import ConfigError, parse_override
from sim.mc.memory_limit import memory_given
from sim.mc.progress import set_quiet
from sim.option_words import two_sets
from sim.studies.picking import load_picking_chunk

__all__ = ["load_run"]


def _keys_set(overrides: list[str]) -> set[str]:
    """The keys of the ``--set`` overrides; a key set twice is refused (one of its values
    would be dropped silently)."""
    keys = set()
    for text in overrides:
        try:
            key = parse_override(text)[0]
        except ConfigError:
            continue  # load_study names the bad override
        if key in keys:
            raise ConfigError(key, "given twice by --set: give one value")
        keys.add(key)
    return keys


def load_run(args):
    """The study and its resolved config, as ``sim run`` (or ``check``) with the parsed
    ``args`` resolves them. ``--trials`` (or ``--set trials=``) without a chunk
    size picks the largest chunk giving at least MIN_CHUNKS chunks; ``--chunk`` sets it
    (:func:`sim.studies.picking.load_picking_chunk`, :func:`sim.load`'s rule too)."""
    set_quiet(getattr(args, "quiet", False))  # the check of a large network shows its steps
    overrides = list(args.set) + ([f"chunk={args.chunk}"] if args.chunk is not None else [])
    given = _keys_set(args.set)
    for opt, key in (("--trials", "trials"), ("--seed", "seed"), ("--chunk", "chunk")):
        if getattr(args, key) is not None and key in given:  # one would be dropped silently
            raise ConfigError(opt, f"given twice, as {opt} and as --set {key}=: give one")
    trials = args.trials is not None or "trials" in given
    picks = trials and args.chunk is None and "chunk" not in given  # --trials's chunk
    try:
        with memory_given(getattr(args, "max_memory_gb", None)):  # a network's size (sim.batch)
            return load_picking_chunk(args.study, picks, overrides, args.trials, args.seed)
    except ConfigError as e:  # --set trials=40,seed=3: two overrides in one, named
        if hint := two_sets(args.set, e.key):
            raise ConfigError(e.key, e.detail + hint) from None
        raise
