"""Doors sweep 48h: the chunk store (``trials/``) and a sweep's and a batch's output touched
by hand, each touch followed by the readers, a resume and a re-run; one case per class found,
each failed on the code before its fix.

* A chunk of an unfinished run edited by hand in its staging directory, its identity kept
  (``sim.chunk`` in its metadata: study, config hash, part, index, seed): a value of its rows
  or of its kept arrays changed, its rows reordered, a column added. A resume read it as the
  run's: a network run of 4,000 trials whose first five chunks' sums were tripled reported
  4,200 converged and another false-alarm rate, exit 0. A chunk file's identity now holds the
  digest of its content (:mod:`sim.mc.chunk_content`), and a chunk whose content is not that
  digest's is computed again, as a chunk of another seed is.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from sim.mc.packed import pack, unpack
from sim.mc.runner import ChunkStore, RunContext, run_chunks


def _fn(rng, n):
    x = rng.normal(size=n)
    return {
        "rows.x": x,
        "rows.ok": x > 0,
        "rows.status": (x > 1).astype(np.int8),
        "sum": np.array([x.sum()]),
    }


def _store(tmp_path):
    return ChunkStore(tmp_path / "trials", {"study": "toy", "config": {"a": 1}})


def _rewrite(p, edit):
    """Rewrite the chunk file ``p`` through ``edit(table, arrays)``, its metadata kept."""
    t = pq.read_table(p)
    meta = dict(t.schema.metadata)
    t, arrays = edit(t, unpack(meta[b"sim.arrays"]))
    meta[b"sim.arrays"] = pack(arrays)
    pq.write_table(t.replace_schema_metadata(meta), p)


def test_a_staged_chunk_edited_by_hand_is_computed_again(tmp_path):
    """Class: silent nonsense on resume. Before, a chunk whose rows or kept arrays were edited
    with its identity metadata kept was loaded as the run's (the sums tripled: more converged
    trials than trials); now its content digest refuses it and the chunk is computed again."""
    clean = run_chunks(_fn, 40, 9, 10, quiet=True, keep_rows=True)
    run_chunks(_fn, 40, 9, 10, ctx=RunContext(quiet=True, store=_store(tmp_path)))
    d = tmp_path / "trials" / "part-0"
    # a faithful store round trip is read back: a resume recomputes nothing
    calls = []

    def counting(rng, n):
        calls.append(n)
        return _fn(rng, n)

    run_chunks(counting, 40, 9, 10, ctx=RunContext(quiet=True, store=_store(tmp_path)))
    assert calls == []
    edits = {
        0: lambda t, a: (t, {**a, "sum": a["sum"] * 3}),  # a kept array
        1: lambda t, a: (t.set_column(2, "x", pc.multiply(t.column("x"), 3.0)), a),  # a row
        2: lambda t, a: (t.take(list(range(t.num_rows))[::-1]), a),  # rows reordered
        3: lambda t, a: (t.append_column("junk", pa.array([1.0] * t.num_rows)), a),  # a column
    }
    for k, edit in edits.items():
        _rewrite(d / f"chunk-{k:06d}.parquet", edit)
    again = run_chunks(
        counting, 40, 9, 10, keep_rows=True, ctx=RunContext(quiet=True, store=_store(tmp_path))
    )
    assert calls == [10, 10, 10, 10]  # every edited chunk was refused and computed again
    assert set(again) == set(clean)
    for key in clean:
        assert np.array_equal(again[key], clean[key]), key
