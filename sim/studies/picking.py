"""A study file loaded for a command, with the chunk ``trials`` picks: ``sim run --trials N``
(and ``sim check``, the batch's checks, :func:`sim.load` with ``trials=N``), one rule for all.

``sim.cli_load.load_run`` and ``sim.api``'s loader wrote the rule twice (one of them negated): a
change to one would have given ``sim.load`` another config, another config hash and other
results than ``sim run`` with the same numbers. No study imports this module (the rule is
the command's, as :func:`sim.studies.ported.foreign_key`'s wording): it is no part of any
study's code hash.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from sim.mc.chunk_count import MIN_CHUNKS
from sim.mc.config import ConfigError
from sim.room import loaded
from sim.studies import load_study
from sim.studies.ported import foreign_key

__all__ = ["load_picking_chunk"]


def load_picking_chunk(
    path: str | Path,
    picks: bool,
    overrides: list[str] | tuple = (),
    trials: int | None = None,
    seed: int | None = None,
    values: Mapping[str, Any] | None = None,
):
    """:func:`sim.studies.load_study` of ``path`` (``overrides``, ``trials``, ``seed``,
    ``values`` as it takes them), a key of another study named as its
    (:func:`sim.studies.ported.foreign_key`). ``picks``: trials were given and the chunk was
    not; the chunk is then the largest that gives at least :data:`MIN_CHUNKS` chunks, the
    file's own chunk kept when it is smaller, and picked also when the file's chunk is too
    large for the trials asked for (which alone would be refused). What the load mapped (a
    network's: built and factorised) is recorded under the config (:func:`sim.room.loaded`):
    the room check before the run counts it once."""
    return loaded(lambda: _load(path, picks, overrides, trials, seed, values))


def _load(path, picks: bool, overrides, trials, seed, values):
    """:func:`load_picking_chunk`'s load."""

    def load(chunk: int | None = None):
        vals = dict(values or {}) if chunk is None else {**(values or {}), "chunk": chunk}
        return load_study(path, overrides, trials, seed, vals)

    try:
        study, cfg = load()
    except ConfigError as e:
        if e.key != "chunk" or not picks:
            raise foreign_key(e, path) from None  # a key of another study: whose
        _, cfg = load(1)  # the file's chunk is too large for the trials asked for
        return load(max(1, cfg["trials"] // MIN_CHUNKS))
    if picks and "chunk" in cfg and cfg["chunk"] > (chunk := max(1, cfg["trials"] // MIN_CHUNKS)):
        return load(chunk)
    return study, cfg
