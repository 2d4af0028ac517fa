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
* A sweep's ``run.json`` deleted and a value of its ``sweep.parquet`` edited by hand (a left
  item of H46/L47: "a sweep's top directory without run.json is read without checks"):
  ``sim show`` (and ``--markdown``) printed the edited value as the sweep's and ``sim
  report`` wrote it into the sweep's README.md, exit 0, where a study's directory without its
  record is refused (doors47k). Both now refuse in one line naming the ``run.json``
  (:func:`sim.report.read.check_sweep_record`), as ``Results.table("sweep")`` did.
* A chunk file of a finished run replaced by hand (a user's file saved over it, a link or a
  FIFO put in its place) was replaced by the next run into the same ``--out`` without a word,
  where a table so replaced is named in a note (``changed after the run that wrote it ...:
  replaced by this run's``); the note names such a chunk too
  (:func:`sim.mc.table_edits.edited_chunks`).
* ``python -m sim.batch --timings F`` where ``F`` is a large file of the user's (a disk
  image, a log named by mistake): the check that an existing ``F`` is an earlier timings file
  read it whole into memory (a sparse 3 GiB file under ``ulimit -v`` 2.5 GB: a ``MemoryError``
  traceback, exit 1); a file over 1 MiB is now refused as no timings file without reading it
  (:data:`sim.batch_checks.TIMINGS_BYTES`).
* A file manager's or a notebook's litter inside ``trials/`` (``.DS_Store``,
  ``.ipynb_checkpoints/``), which the chunk dataset's reader skips as pyarrow does, made
  ``Results.table("trials")`` refuse the run's chunks as "added by hand"; it is skipped by the
  check too, while any other file there is still refused.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest

import sim
from sim import batch
from sim.cli import main
from sim.mc.packed import pack, unpack
from sim.mc.runner import ChunkStore, RunContext, run_chunks
from tests.conftest import TRIANGLE_NETWORK
from tests.oneline import SIM_ERROR, one_line


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


def test_a_sweep_whose_run_record_was_deleted_is_refused(tmp_path, capsys):
    """Class: silent nonsense. Before, a sweep's directory without its ``run.json`` beside an
    edited ``sweep.parquet`` was shown, and its README.md rewritten by ``sim report``, with the
    edited value, exit 0; now ``sim show`` and ``sim report`` name the missing record, and the
    README.md is left as the run wrote it."""
    st = tmp_path / "sw.toml"
    st.write_text(TRIANGLE_NETWORK + "[sweep]\ntrials = [40, 60]\n")
    d = tmp_path / "res" / "sw"
    assert main(["run", str(st), "--out", str(d), "--quiet", "--no-figures"]) == 0
    capsys.readouterr()
    t = pq.read_table(d / "sweep.parquet")
    i = t.column_names.index("network.coverage95.mean")
    edited = t.set_column(i, t.column_names[i], pa.array([0.123456, 0.123456]))
    pq.write_table(edited.replace_schema_metadata(t.schema.metadata), d / "sweep.parquet")
    (d / "run.json").unlink()
    readme = (d / "README.md").read_text()
    rec = str(d / "run.json")
    for markdown in ([], ["--markdown"]):
        line = one_line(capsys, main(["show", str(d), *markdown]), rec, "is missing")
        assert line.startswith(SIM_ERROR)
    one_line(capsys, main(["report", "--results", str(d.parent)]), rec, "is missing")
    assert (d / "README.md").read_text() == readme and "0.123" not in readme
    assert not (d.parent / "REPORT.md").exists()


def test_a_chunk_replaced_by_hand_is_named_when_a_rerun_replaces_it(tmp_path, capsys):
    """Class: data loss without a word. Before, a user's file saved over a chunk of a finished
    run was replaced by the re-run silently; now the re-run's note names it."""
    st = tmp_path / "tri.toml"
    st.write_text(TRIANGLE_NETWORK)
    out = tmp_path / "out"
    cmd = ["run", str(st), "--out", str(out), "--quiet", "--no-figures"]
    assert main(cmd) == 0
    chunk = out / "trials" / "part-0" / "chunk-000004.parquet"
    chunk.write_text("my notes, saved over a chunk")
    capsys.readouterr()
    assert main(cmd) == 0
    err = capsys.readouterr().err
    assert "trials/part-0/chunk-000004.parquet" in err and "replaced by this run's" in err, err
    assert err.count("\n") == 1 and pq.read_table(chunk).num_rows == 2


def test_a_large_file_named_as_timings_is_not_read(tmp_path, capsys, monkeypatch):
    """Class: traceback (MemoryError) or a machine out of memory. Before, an existing
    ``--timings`` file was read whole to see whether it is an earlier timings file; now one
    over the limit is refused, one line, without reading a byte of it."""
    big = tmp_path / "disk.img"
    with open(big, "wb") as f:
        f.truncate(1 << 31)  # sparse: 2 GiB that take no disk
    read = []
    real = Path.read_bytes
    monkeypatch.setattr(Path, "read_bytes", lambda p: read.append(p) or real(p))
    st = tmp_path / "tri.toml"
    st.write_text(TRIANGLE_NETWORK)
    rc = batch.main([str(st), "--results", str(tmp_path / "res"), "--timings", str(big)])
    one_line(capsys, rc, str(big), "is not a timings file of sim.batch")
    assert big not in read and big.stat().st_size == 1 << 31
    assert not (tmp_path / "res").exists()  # refused before any run


def test_litter_in_the_chunk_store_does_not_hide_the_chunks(tmp_path, capsys):
    """Class: a refusal of good data. Before, a ``.DS_Store`` that Finder left in
    ``trials/part-0`` made ``Results.table("trials")`` refuse the run's chunks; now it reads
    them, and a file of the user's there that the reader would read is still named."""
    st = tmp_path / "tri.toml"
    st.write_text(TRIANGLE_NETWORK)
    out = tmp_path / "out"
    assert main(["run", str(st), "--out", str(out), "--quiet", "--no-figures"]) == 0
    (out / "trials" / "part-0" / ".DS_Store").write_bytes(b"\0\0\0\1Bud1")
    (out / "trials" / ".ipynb_checkpoints").mkdir()
    (out / "trials" / ".ipynb_checkpoints" / "x.parquet").write_bytes(b"PAR1")
    assert sim.Results(out, "network").table("trials").num_rows == 40
    (out / "trials" / "part-0" / "notes.parquet").write_bytes(b"PAR1")
    with pytest.raises(sim.ConfigError, match="notes.parquet is not one of the run's chunk"):
        sim.Results(out, "network").table("trials")
