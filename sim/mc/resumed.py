"""What a resumed run keeps of the chunk files its staging directory holds.

"resuming: N finished chunks found" counted the files, also those the run then computed
again: a chunk that is not what its name says (another study's, config's, part's or index's)
or not as the run wrote it (its content digest differs: :mod:`sim.mc.chunk_content`). The
line says how many are kept and how many are computed again, by the check a resume makes of
each chunk (:meth:`sim.mc.runner.ChunkStore._checked`; a sweep cell's chunks by their own
identity and content, the cell's config being made later).
"""

from __future__ import annotations

import re
from pathlib import Path

from sim.mc.runner import ChunkStore

__all__ = ["resumed_words"]


def _kept(store: ChunkStore, p: Path, config: bool) -> bool:
    m = re.fullmatch(r"part-(\d+)/chunk-(\d+)\.parquet", p.relative_to(store.root).as_posix())
    return m is not None and store._checked(p, int(m[1]), int(m[2]), None, None, config) is not None


def resumed_words(store: ChunkStore) -> str:
    """``N finished chunks found`` of the staging directory of ``store`` (its ``trials/``
    and a sweep's ``cells/*/trials/``), or ``K finished chunks kept, M computed again (...)``
    when M of them will not be read back."""
    root = Path(store.root)
    cells = root.parent / "cells"
    stores = [(store, True)] + [
        (ChunkStore(t), False) for t in (sorted(cells.glob("*/trials")) if cells.is_dir() else [])
    ]
    kept = again = 0
    for s, config in stores:
        for p in sorted(Path(s.root).rglob("chunk-*.parquet")) if Path(s.root).is_dir() else []:
            if _kept(s, p, config):
                kept += 1
            else:
                again += 1
    if not again:
        return f"{kept} finished chunks found"
    return (
        f"{kept} finished chunks kept, {again} computed again (chunk files not what their names "
        "say or not as the run wrote them: another run's, or edited)"
    )
