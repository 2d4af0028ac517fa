"""The content digest of a Monte-Carlo chunk file (:class:`sim.mc.runner.ChunkStore`).

A chunk file's identity (``sim.chunk`` in its metadata: study, config hash, part, index,
trials, seed stream) says what it stands for; its digest says that its content is the one the
run wrote: the sha256 of its kept arrays (``sim.arrays``, packed) and of the shape of its
per-trial rows (:func:`sim.mc.table_shape.shape`: every column's name, kind and values in
their order). A chunk of an unfinished run edited by hand in the staging directory (a
number of its rows or arrays changed, its rows reordered, a column added, with its identity
kept) was resumed as the run's: a network run of 4,000 trials reported 4,200 converged.
The digest is the same for a faithful rewrite of the rows (another row-group size, another
integer width), as the tables' shapes are.
"""

from __future__ import annotations

import hashlib
import json

import pyarrow as pa

from sim.mc.table_shape import shape

__all__ = ["content_digest"]


def content_digest(rows: pa.Table, arrays: bytes) -> str:
    """16 hex digits of the sha256 of a chunk's packed ``arrays`` and the shape of its
    ``rows`` (the table as written, its metadata left out)."""
    h = hashlib.sha256(arrays)
    h.update(json.dumps(shape(rows.replace_schema_metadata(None)), sort_keys=True).encode())
    return h.hexdigest()[:16]
