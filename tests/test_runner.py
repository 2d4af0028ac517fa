"""Runner reliability: executors give identical output, killed runs resume, no mixing."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from sim.cli import main
from sim.runner import ChunkStore, chunk_rng, jackknife, make_executor, run_chunks
from sim.studies import RunContext

ROOT = Path(__file__).resolve().parent.parent
STUDY = ROOT / "studies" / "brown_table1.toml"


def same_result(a: Path, b: Path) -> bool:
    """Bit-for-bit equal data and equal provenance apart from the code version (which other
    work in the tree may change between two runs)."""
    from sim.storage import read_provenance

    ta, tb = pq.read_table(a), pq.read_table(b)
    pa_, pb_ = read_provenance(a), read_provenance(b)
    for p in (pa_, pb_):
        p.pop("code_hash", None)
        p.pop("git_commit", None)
    return ta.equals(tb) and pa_ == pb_


def _toy(rng, n):
    x = rng.normal(size=(n, 3))
    return {"rows.x0": x[:, 0], "x": x, "sum.s": x.sum(0)[None]}


def test_chunk_streams_are_spawned_children():
    a = chunk_rng(5, 2, 3).normal(size=4)
    b = np.random.default_rng(np.random.SeedSequence(5).spawn(3)[2].spawn(4)[3]).normal(size=4)
    assert np.array_equal(a, b)


def test_store_resumes_and_gives_the_same_result(tmp_path):
    full = run_chunks(_toy, 50, 9, 8, quiet=True)
    store = ChunkStore(tmp_path / "trials")
    ctx = RunContext(quiet=True, store=store)
    # a run that stopped after 3 chunks: only those files exist
    for k in range(3):
        store.save(0, k, 8, _toy(chunk_rng(9, 0, k), 8))
    calls = []

    def counting(rng, n):
        calls.append(n)
        return _toy(rng, n)

    res = run_chunks(counting, 50, 9, 8, ctx=ctx)
    assert len(calls) == 4                     # 7 chunks in all, 3 were done
    for k in full:
        assert np.array_equal(full[k], res[k])
    rows = pq.read_table(tmp_path / "trials").to_pydict()
    assert len(rows["x0"]) == 50               # none lost, none twice
    assert sorted(zip(rows["chunk"], rows["trial_in_chunk"])) == sorted(set(zip(rows["chunk"], rows["trial_in_chunk"])))


def test_process_pool_equals_in_process():
    a = run_chunks(_toy, 40, 3, 7, quiet=True)
    ex = make_executor("local", workers=2)
    try:
        b = run_chunks(_toy, 40, 3, 7, ctx=RunContext(quiet=True, executor=ex))
    finally:
        ex.close()
    for k in a:
        assert np.array_equal(a[k], b[k])


def test_dask_local_cluster_equals_local(tmp_path):
    pytest.importorskip("distributed")
    outs = {}
    for name, extra in (("local", []), ("dask", ["--executor", "dask", "--workers", "2"])):
        o = tmp_path / name
        assert main(["run", str(STUDY), "--out", str(o), "--trials", "60", "--quiet",
                     "--set", "chunk=20"] + extra) == 0
        outs[name] = o
    for f in ("claims.parquet", "points.parquet", "table1_trials.parquet",
              "trials/part-0/chunk-000002.parquet"):
        assert same_result(outs["local"] / f, outs["dask"] / f), f


def test_workers_give_bit_identical_files(tmp_path):
    for w in ("1", "2"):
        assert main(["run", str(STUDY), "--out", str(tmp_path / w), "--trials", "60", "--quiet",
                     "--workers", w, "--set", "chunk=20"]) == 0
    for f in ("claims.parquet", "points.parquet", "trials/part-0/chunk-000001.parquet"):
        assert same_result(tmp_path / "1" / f, tmp_path / "2" / f), f


def test_refuses_to_mix_a_different_config(tmp_path, capsys):
    o = tmp_path / "o"
    args = ["run", str(STUDY), "--out", str(o), "--trials", "20", "--quiet", "--set", "chunk=10"]
    assert main(args) == 0
    assert main(args + ["--seed", "2"]) == 2
    err = capsys.readouterr().err
    assert "different config" in err and "--overwrite" in err
    assert main(args + ["--seed", "2", "--overwrite"]) == 0
    assert pq.read_table(o / "claims.parquet").schema.metadata  # replaced, complete


def test_kill_9_then_same_command_finishes_missing_chunks(tmp_path):
    out = tmp_path / "res"
    cmd = [sys.executable, "-m", "sim", "run", str(STUDY), "--out", str(out), "--trials", "20000",
           "--quiet", "--set", "chunk=100"]
    stage = tmp_path / ".res.partial" / "trials" / "part-0"
    p = subprocess.Popen(cmd, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t0 = time.time()
    while time.time() - t0 < 120:
        if stage.exists() and len(list(stage.glob("chunk-*.parquet"))) >= 3:
            break
        time.sleep(0.05)
    os.kill(p.pid, signal.SIGKILL)
    p.wait()
    done = len(list(stage.glob("chunk-*.parquet")))
    assert 3 <= done < 200, "the run finished before it could be killed; make it longer"
    assert not out.exists()                      # nothing that looks complete
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "resuming" in r.stderr
    rows = pq.read_table(out / "trials").to_pydict()
    assert len(rows["chunk"]) == 20000
    assert len(set(zip(rows["chunk"], rows["trial_in_chunk"]))) == 20000
    # identical to an uninterrupted run
    ref = tmp_path / "ref"
    assert main(["run", str(STUDY), "--out", str(ref), "--trials", "20000", "--quiet",
                 "--set", "chunk=100"]) == 0
    for f in ("claims.parquet", "points.parquet", "table1_trials.parquet"):
        assert same_result(out / f, ref / f), f


def test_full_disk_is_one_line_and_no_result(tmp_path, capsys, monkeypatch):
    import errno

    import sim.runner as runner

    def full(*a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(runner.pq, "write_table", full)
    out = tmp_path / "o"
    assert main(["run", str(STUDY), "--out", str(out), "--trials", "20", "--quiet",
                 "--set", "chunk=10"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "No space left" in err[0]
    assert not out.exists()


def test_jackknife_of_a_mean_matches_the_standard_error():
    rng = np.random.default_rng(4)
    x = rng.normal(2.0, 3.0, size=(40, 50))              # 40 chunks of 50 draws
    sums = np.stack([x.sum(1), np.full(40, 50.0)], 1)
    est, lo, hi = jackknife(lambda t: t[0] / t[1], sums)
    se = x.std(ddof=1) / np.sqrt(x.size)
    assert est == pytest.approx(x.mean())
    # the jackknife SE of a mean over equal chunks is the between-chunk SE of the mean
    from scipy import stats
    assert (hi - lo) / 2 / stats.t.ppf(0.975, 39) == pytest.approx(
        x.mean(1).std(ddof=1) / np.sqrt(40), rel=1e-9)
    assert 0.6 < (hi - lo) / 2 / 1.96 / se < 1.4


def test_degenerate_cell_in_a_sweep_is_recorded_and_the_sweep_goes_on(tmp_path, capsys):
    """A 2 x 2 grid passes validation but makes the pivot model's reduced normals singular."""
    f = tmp_path / "s.toml"
    f.write_text('study = "brown_table1"\ntrials = 20\nchunk = 10\n'
                 '[sweep]\n"plate.grid" = [2, 5]\n')
    out = tmp_path / "sw"
    assert main(["run", str(f), "--out", str(out), "--quiet"]) == 0
    t = pq.read_table(out / "sweep.parquet").to_pydict()
    assert t["plate.grid"] == [2, 5]
    assert t["feasible"] == [False, True]
    assert "singular" in t["reason"][0]
    # a plain run of the degenerate cell is a one-line error, exit 2
    g = tmp_path / "g.toml"
    g.write_text('study = "brown_table1"\ntrials = 20\nchunk = 10\n[plate]\ngrid = 2\n')
    assert main(["run", str(g), "--out", str(tmp_path / "g"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "singular" in err[0]
