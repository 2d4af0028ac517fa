"""The random streams of a Monte-Carlo run: chunk ``k`` of stream ``part`` draws from
``numpy.random.SeedSequence(seed, spawn_key=(part, k))`` -- the same stream that
``SeedSequence(seed).spawn(part + 1)[part].spawn(k + 1)[k]`` gives -- so a result does not
depend on how many workers run the chunks, in which order, or on which machine."""

from __future__ import annotations

import numpy as np

__all__ = ["chunk_rng", "call_chunk"]


def chunk_rng(seed: int, part: int, k: int) -> np.random.Generator:
    """The generator of chunk ``k`` of stream ``part``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(part, k)))


def call_chunk(fn, seed: int, part: int, k: int, n: int) -> dict:
    """Chunk ``k`` of stream ``part``: ``fn(rng, n)`` on its own generator, as arrays."""
    out = fn(chunk_rng(seed, part, k), n)
    return {key: np.asarray(v) for key, v in out.items()}
