"""Monte-Carlo runner: trials in chunks, one spawned random stream per chunk.

Chunk ``k`` of stream ``part`` draws from
``numpy.random.SeedSequence(seed, spawn_key=(part, k))`` -- the same stream that
``SeedSequence(seed).spawn(part + 1)[part].spawn(k + 1)[k]`` gives -- so a result does not
depend on how many chunks run at once or on which machine; only ``seed``, ``part`` and the
chunk size fix it.
"""
from __future__ import annotations

from typing import Callable, Mapping

import numpy as np

from .progress import Progress

__all__ = ["chunk_rng", "run_chunks"]


def chunk_rng(seed: int, part: int, k: int) -> np.random.Generator:
    """The generator of chunk ``k`` of stream ``part``."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(part, k)))


def run_chunks(fn: Callable[[np.random.Generator, int], Mapping[str, np.ndarray]], trials: int,
               seed: int, chunk: int, part: int = 0, label: str = "", quiet: bool = False
               ) -> dict[str, np.ndarray]:
    """Run ``fn(rng, n)`` over chunks of at most ``chunk`` trials and concatenate.

    ``fn`` returns a dict of arrays whose leading axis is the ``n`` trials of the chunk.
    """
    if trials < 1:
        raise ValueError("trials must be >= 1")
    sizes = [min(chunk, trials - s) for s in range(0, trials, chunk)]
    parts: dict[str, list[np.ndarray]] = {}
    with Progress(trials, label, quiet=quiet) as bar:
        for k, n in enumerate(sizes):
            out = fn(chunk_rng(seed, part, k), n)
            for key, v in out.items():
                parts.setdefault(key, []).append(np.asarray(v))
            bar.update(n)
    return {k: np.concatenate(v, axis=0) for k, v in parts.items()}
