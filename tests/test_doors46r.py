"""A hostile reading of session 45's merges (brief R46); each test failed on the code before
its fix.

* ``sim.run_chunks`` (A44's checks of what a chunk function returns,
  :class:`sim.api_chunks.Checked`) took a key's first axis as the chunk's trials ``n`` or 1
  (a per-chunk statistic) in each chunk alone: a function giving ``n`` rows in one chunk and
  one in another passed every chunk, and the concatenation returned 4 values for 6 trials in
  two chunks of 3, without a word (the silent "more values than trials" A44 closed, in its
  other direction). The totals tell it now (:func:`sim.api_chunks.check_counts`).
* F44's refusal of a directory that holds a running run (:func:`sim.mc.swap.
  refuse_if_running_under`) walked every file under an ``--out`` that has files and no run
  record before refusing it, which that run is in any case: ``--out /usr`` looked at 122,000
  entries, ``--out ~`` of a home of millions for minutes, and walked into file systems
  mounted inside. It looks at :data:`sim.mc.swap.LOOK_AT` entries and no mount now.
* X44's test of gama-local's absolute terms (:mod:`sim.studies.network.gama_terms`) wrapped
  an angle to half a turn by subtracting a turn at a time, as gama-local does: a direction's
  ``val="1e15"`` (gon) or an ``<obs orientation="1e15">`` (radians), finite floats the reader
  takes, ran ``sim check`` and every run of the file for ever. The IEEE remainder now.
* W45's and P44's checks of agnard_block's design sit before its memory refusal of a chunk,
  after the datum's check, which adjusts the whole block once for each control layout: a
  block of 34,447 ground points (``block.base_mm = 10``, ``block.scale = 510165``, one strip
  of 50 models) was refused "a chunk of 50 blocks needs 232.3 GB" after 47 s of CPU (3 min
  44 s on the loaded machine) of those adjustments. The refusal, which needs only the block's
  table of observations, comes first now.
* ``sim.write_table`` (A44's checks of its columns) refused a column's value that UTF-8
  cannot hold (a lone surrogate, as ``os.fsdecode`` makes of bytes that are not UTF-8) but not
  such a column name: ``UnicodeEncodeError`` from Arrow, a traceback.
* M44's cache of parsed GNU Gama files (:mod:`sim.studies.network.gama_cache`) dropped its
  oldest entry by iterating the dict another thread was putting one into: network studies
  loaded in threads at once (``sim.load`` in a thread pool) ended in "RuntimeError:
  dictionary changed size during iteration". Its neighbours of the same form (the loads'
  record in :mod:`sim.room`, the last sparse pre-analysis) take it under a lock, or hold it.
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import sim
from sim.mc import swap
from sim.mc.config import ConfigError


def _mixed(rng, n, calls=[0]):  # noqa: B006 - the chunks' count, across calls
    calls[0] += 1
    return {"x": rng.standard_normal(n if calls[0] % 2 else 1)}


def test_run_chunks_refuses_a_key_per_trial_in_one_chunk_and_per_chunk_in_another():
    """Class: a chunk function whose array is of ``n`` rows in one chunk and of 1 in another
    (each chunk alone as allowed). Before: 4 values for 6 trials returned, exit 0."""
    with pytest.raises(ConfigError) as e:
        sim.run_chunks(_mixed, 6, 1, 3, quiet=True)
    assert e.value.key == "fn"
    assert "'x'" in str(e.value) and "4 values for 6 trials in 2 chunks" in str(e.value)


def test_run_chunks_keeps_per_trial_and_per_chunk_keys_with_a_last_chunk_of_one():
    """The counts of a consistent function pass, a last chunk of one trial included (its
    ``n`` and 1 agree), per-trial and per-chunk keys side by side."""

    def fn(rng, n):
        return {"x": rng.standard_normal((n, 2)), "s": np.array([float(n)])}

    out = sim.run_chunks(fn, 7, 1, 3, quiet=True)
    assert out["x"].shape == (7, 2)
    assert out["s"].tolist() == [3.0, 3.0, 1.0]


def test_a_directory_without_a_record_is_not_walked_whole_for_a_running_run(tmp_path, monkeypatch):
    """Class: ``--out`` a large tree of the user's (``~``, ``/usr``), refused as holding files
    but no run record. Before: every directory under it walked first (here all 61)."""
    for k in range(60):
        (tmp_path / f"d{k:02d}").mkdir()
        (tmp_path / f"d{k:02d}" / "f").write_text("x")
    tops: list[str] = []
    scandir = os.scandir

    def counted(top):
        tops.append(str(top))
        return scandir(top)

    monkeypatch.setattr(swap, "LOOK_AT", 10)
    monkeypatch.setattr(os, "scandir", counted)
    swap.refuse_if_running_under(tmp_path, str(tmp_path))
    assert 1 <= len(tops) <= 11


def test_a_held_lock_within_the_walk_is_still_named(tmp_path):
    """The refusal naming the run inside still holds within the walk's entries."""
    stage = tmp_path / "sub" / ".run.partial"
    lock = swap.StageLock(stage).acquire()
    try:
        with pytest.raises(ConfigError) as e:
            swap.refuse_if_running_under(tmp_path, "OUT")
        assert "OUT holds sub/.run.partial" in str(e.value) and f"pid {os.getpid()}" in str(e.value)
    finally:
        lock.release()


TWO_SETS = Path(__file__).parent / "data" / "gama" / "two_sets.xml"


def test_a_direction_of_a_huge_value_in_a_gama_file_is_judged_not_wrapped_for_ever(tmp_path):
    """Class: a GNU Gama file with a direction ``val`` of 1e15 gon and an ``<obs>``
    orientation of 1e15 radians (finite, read). Before: ``sim check`` never ended (killed by
    this test's timeout); now it is refused in one line, naming it."""
    text = TWO_SETS.read_text()
    a = '<direction to="B" val="6.345103486110713" stdev="9.25925925925926" />'
    assert text.count(a) == 1 and text.count('<obs from="B">') == 1
    text = text.replace(a, a.replace("6.345103486110713", "1e15"))
    text = text.replace('<obs from="B">', '<obs from="B" orientation="1e15">')
    (tmp_path / "g.xml").write_text(text)
    study = tmp_path / "g.toml"
    study.write_text(
        f'study = "network"\ntrials = 40\nchunk = 2\nseed = 1\n[network]\ngama_xml = "{tmp_path / "g.xml"}"\n'
    )
    try:
        done = subprocess.run(
            [sys.executable, "-m", "sim", "check", str(study)],
            capture_output=True,
            text=True,
            timeout=240,
            cwd=Path(__file__).parents[1],
        )
    except subprocess.TimeoutExpired:
        pytest.fail("sim check of a direction of 1e15 gon did not end")
    err = done.stderr.strip().splitlines()
    assert done.returncode == 2 and len(err) == 1, done.stderr
    # refused by the reader for its turns (X46's bound, before the absolute-term test)
    assert "<direction> attribute 'val'" in err[0] and "give it within a turn" in err[0]


def test_agnard_refuses_a_chunk_over_memory_before_it_checks_the_datum(monkeypatch):
    """Class: an agnard_block chunk whose normal equations cannot be held, on a block whose
    datum check is slow (large). Before: the datum check (eight adjustments of the whole
    block) ran first; here it would raise AssertionError."""
    from sim.studies.agnard import schema

    def datum_first(*a, **kw):
        raise AssertionError("the datum was checked before the chunk's memory")

    monkeypatch.setattr(schema, "check_datum", datum_first)
    with pytest.raises(ConfigError) as e:
        sim.load("studies/agnard_block.toml", trials=1_000_000, chunk=50_000)
    assert e.value.key == "chunk" and "17.5 GB" in str(e.value)


def test_write_table_refuses_a_column_name_utf8_cannot_hold(tmp_path):
    """Class: a column named with a lone surrogate (``os.fsdecode(b"\\xff")``). Before:
    ``UnicodeEncodeError`` from pyarrow; now one line naming ``columns``, nothing written."""
    name = os.fsdecode(b"x\xff")
    with pytest.raises(ConfigError) as e:
        sim.write_table(tmp_path / "t.parquet", {name: [1.0]}, {"a": 1})
    assert e.value.key == "columns" and "UTF-8" in str(e.value)
    assert not any(tmp_path.iterdir())
    sim.write_table(tmp_path / "t.parquet", {"x\u00e9": [1.0]}, {"a": 1})  # text beyond ASCII


def test_gama_files_parsed_by_threads_at_once_share_the_cache(monkeypatch):
    """Class: threads loading network studies from GNU Gama files at once. Before: about
    every thread ended in "RuntimeError: dictionary changed size during iteration"."""
    from sim.studies.network import gama_cache

    names = ("two_sets", "one_fixed", "directions_free")
    files = [Path(__file__).parent / "data" / "gama" / f"{n}.xml" for n in names]

    class Slow(dict):  # the race's window widened: the oldest found, then a pause
        def __iter__(self):
            it = super().__iter__()
            time.sleep(0.002)
            return it

    monkeypatch.setattr(gama_cache, "_PARSED", Slow())
    errors: list[str] = []

    def work(i: int) -> None:
        for k in range(20):
            try:
                rec = gama_cache.read_gama(files[(i + k) % 3])
            except Exception as e:  # noqa: BLE001 - what a thread met is the finding
                errors.append(repr(e))
                return
            assert rec["network.points"]

    old = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)  # threads switch between the dict's steps
    try:
        threads = [threading.Thread(target=work, args=(i,)) for i in range(8)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    finally:
        sys.setswitchinterval(old)
    assert errors == []
    assert len(gama_cache._PARSED) == gama_cache.KEPT
