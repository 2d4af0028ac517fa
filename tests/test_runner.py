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
from oneline import one_line

from sim.cli import main
from sim.mc.runner import ChunkStore, chunk_rng, jackknife, make_executor, run_chunks
from sim.studies import RunContext

ROOT = Path(__file__).resolve().parent.parent
STUDY = ROOT / "studies" / "brown_table1.toml"
#: brown_table1 at 20 trials, its region of unprinted inputs at the smallest size (no test
#: here looks at it)
SMALL = 'study = "brown_table1"\ntrials = 20\nchunk = 1\nregion = {points = 256, rounds = 0}\n'
REGION = ["--set", "region.points=256", "--set", "region.rounds=0"]


def same_result(a: Path, b: Path) -> bool:
    """Bit-for-bit equal data and equal provenance apart from the code version (which other
    work in the tree may change between two runs)."""
    from sim.mc.storage import read_provenance

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
        store.save(0, k, 8, _toy(chunk_rng(9, 0, k), 8), 9)
    calls = []

    def counting(rng, n):
        calls.append(n)
        return _toy(rng, n)

    res = run_chunks(counting, 50, 9, 8, ctx=ctx)
    assert len(calls) == 4  # 7 chunks in all, 3 were done
    for k in full:
        assert np.array_equal(full[k], res[k])
    rows = pq.read_table(tmp_path / "trials").to_pydict()
    assert len(rows["x0"]) == 50  # none lost, none twice
    assert sorted(zip(rows["chunk"], rows["trial_in_chunk"])) == sorted(
        set(zip(rows["chunk"], rows["trial_in_chunk"]))
    )


def test_process_pool_equals_in_process():
    a = run_chunks(_toy, 40, 3, 7, quiet=True)
    ex = make_executor("local", workers=2)
    try:
        b = run_chunks(_toy, 40, 3, 7, ctx=RunContext(quiet=True, executor=ex))
    finally:
        ex.close()
    for k in a:
        assert np.array_equal(a[k], b[k])


def test_dask_local_cluster_equals_local(tiny_run):
    """``--executor dask`` starting its own LocalCluster gives the files of the 1-worker run
    (the session's tiny run of brown_table1) bit for bit."""
    pytest.importorskip("distributed")
    local = tiny_run("brown_table1")
    dask = tiny_run("brown_table1", "--executor", "dask", "--workers", "2")  # as docs/cli.md
    for f in (
        "claims.parquet",
        "points.parquet",
        "table1_trials.parquet",
        "trials/part-0/chunk-000002.parquet",
    ):
        assert same_result(local / f, dask / f), f


def test_refuses_to_mix_a_different_config(tmp_path, capsys):
    o = tmp_path / "o"
    args = ["run", str(STUDY), "--out", str(o), "--trials", "20", "--quiet", "--set", "chunk=1"]
    args += [*REGION, "--no-figures"]
    assert main(args) == 0
    assert main(args + ["--seed", "2"]) == 2
    err = capsys.readouterr().err
    assert "different config" in err and "--overwrite" in err
    assert main(args + ["--seed", "2", "--overwrite"]) == 0
    assert pq.read_table(o / "claims.parquet").schema.metadata  # replaced, complete


def _children(pid: int) -> list[int]:
    try:
        return [int(c) for c in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
    except OSError:
        return []


def _alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0] not in ("Z", "X")
    except OSError:
        return False


def test_kill_9_then_same_command_finishes_missing_chunks(tmp_path, capsys):
    """A ``--workers 2`` run killed with ``kill -9``: a second run into the same --out while it
    lives stops at once (exit 2, naming its pid), the workers die with it, no partial ``.tmp``
    stays, and the same command finishes the missing chunks."""
    out = tmp_path / "res"
    cmd = [
        sys.executable,
        "-m",
        "sim",
        "run",
        str(STUDY),
        "--out",
        str(out),
        "--trials",
        "20000",
        "--quiet",
        "--no-figures",  # its trials are read, not its figures
        "--set",
        "chunk=50",
        *REGION,
    ]
    stage = tmp_path / ".res.partial" / "trials" / "part-0"
    p = subprocess.Popen(
        cmd + ["--workers", "2"], cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    t0 = time.time()
    while time.time() - t0 < 120:
        if stage.exists() and len(list(stage.glob("chunk-*.parquet"))) >= 3:
            break
        time.sleep(0.05)
    second = main(cmd[3:] + ["--overwrite"])  # the same --out while the first one lives
    workers = _children(p.pid)
    os.kill(p.pid, signal.SIGKILL)
    p.wait()
    one_line(capsys, second, f"running sim (pid {p.pid})")
    done = len(list(stage.glob("chunk-*.parquet")))
    assert 3 <= done < 400, "the run finished before it could be killed; make it longer"
    assert not out.exists()  # nothing that looks complete
    assert workers, "the pool had no workers"
    t0 = time.time()
    while any(_alive(w) for w in workers) and time.time() - t0 < 20:
        time.sleep(0.1)
    assert not any(_alive(w) for w in workers), "pool workers outlived the killed run"
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "resuming" in r.stderr
    rows = pq.read_table(out / "trials").to_pydict()
    assert not list(out.rglob("*.tmp")) and not (out / ".lock").exists()
    assert len(rows["chunk"]) == 20000
    assert len(set(zip(rows["chunk"], rows["trial_in_chunk"]))) == 20000
    # that a killed and resumed run equals an uninterrupted one is shown for every study in
    # test_all_studies.py (a second full 20,000-trial run here would repeat it)


def test_full_disk_is_one_line_and_no_result(tmp_path, capsys, monkeypatch):
    import errno

    import sim.mc.runner as runner

    def full(*a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(runner.pq, "write_table", full)
    out = tmp_path / "o"
    argv = ["run", str(STUDY), "--out", str(out), "--trials", "20", "--quiet", "--set", "chunk=1"]
    one_line(capsys, main(argv), "No space left")
    assert not out.exists()


def test_degenerate_cell_in_a_sweep_is_recorded_and_the_sweep_goes_on(tmp_path, capsys):
    """A 2 x 2 grid passes validation but makes the pivot model's reduced normals singular."""
    f = tmp_path / "s.toml"
    f.write_text(SMALL + '[sweep]\n"plate.grid" = [2, 5]\n')
    out = tmp_path / "sw"
    assert main(["run", str(f), "--out", str(out), "--quiet", "--no-figures"]) == 0
    t = pq.read_table(out / "sweep.parquet").to_pydict()
    assert t["plate.grid"] == [2, 5]
    assert t["feasible"] == [False, True]
    assert "singular" in t["reason"][0]
    # a plain run of the degenerate cell is a one-line error, exit 2
    g = tmp_path / "g.toml"
    g.write_text(SMALL + "[plate]\ngrid = 2\n")
    one_line(capsys, main(["run", str(g), "--out", str(tmp_path / "g"), "--quiet"]), "singular")


# --- sweeps are bounded, estimates stop oversized runs, statistics are numbers -------------


@pytest.mark.parametrize(
    "sweep, needle",
    [
        ('"errors.setting_sigma_um" = {start = 1.0, stop = nan, num = 2}', "stop must be a finite"),
        (
            '"errors.setting_sigma_um" = {start = "a", stop = 2.0, num = 2}',
            "start must be a finite",
        ),
        ('"errors.setting_sigma_um" = {start = 1.0, stop = 2.0, step = 1e-12}', "more than 10000"),
        ('"errors.setting_sigma_um" = {start = 1.0, stop = 2.0, num = 5000000}', "num must be"),
        ('replicates = 3000000\n"errors.settings" = [2]', "sweep.replicates"),
        ('"errors.settings" = [2, 3]\n"plate.grid" = {start = 3, stop = 9000, step = 1}', "cells"),
    ],
)
def test_sweep_cell_count_is_finite_and_bounded(tmp_path, capsys, sweep, needle):
    f = tmp_path / "s.toml"
    f.write_text(SMALL + f"[sweep]\n{sweep}\n")
    one_line(capsys, main(["run", str(f), "--out", str(tmp_path / "o"), "--quiet"]), needle)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_dotted_range_syntax_and_sweep_chunks_carry_provenance(tmp_path):
    from sim.mc.storage import read_provenance

    f = tmp_path / "s.toml"
    f.write_text(SMALL + "[sweep]\nerrors.settings = {start = 2, stop = 3, num = 2}\n")
    assert main(["run", str(f), "--out", str(tmp_path / "o"), "--quiet", "--no-figures"]) == 0
    t = pq.read_table(tmp_path / "o" / "sweep.parquet").to_pydict()
    assert t["errors.settings"] == [2.0, 3.0] and t["feasible"] == [True, True]
    prov = read_provenance(
        tmp_path / "o" / "cells" / "cell0001_r0" / "trials" / "part-0" / "chunk-000001.parquet"
    )
    assert prov["config"]["errors.settings"] == 3 and prov["sweep_cell"] == "cell0001_r0"
    assert prov["spawn_key"] == [0, 1] and "numpy" in prov["versions"]
    import json

    assert "tqdm" in json.loads((tmp_path / "o" / "run.json").read_text())["versions"]


def test_a_sweep_whose_every_cell_fails_exits_2_with_the_reasons(tmp_path, capsys):
    f = tmp_path / "s.toml"
    f.write_text(SMALL + '[sweep]\n"plate.spacing_mm" = [80.0, 90.0]\n')
    one_line(
        capsys,
        main(["run", str(f), "--out", str(tmp_path / "o"), "--quiet"]),
        "every cell failed (2 of 2)",
        "plate",
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_the_estimate_stops_an_oversized_run_at_once(tmp_path, capsys, monkeypatch):
    from sim.mc.estimate import estimate
    from sim.studies import load_study

    region = ["region.points=256", "region.rounds=0"]  # the region's share, as small as it goes
    _, cfg = load_study(STUDY, region)
    small = estimate(cfg)
    _, cfg = load_study(STUDY, region + ["plate.grid=200", "plate.spacing_mm=1.0"])
    big = estimate(cfg)
    assert big.unknowns == 2 * 200**2 + 7 and big.bytes > 1000 * small.bytes
    args = ["run", str(STUDY), "--out", str(tmp_path / "o"), "--quiet", "--set", "chunk=100"]
    one_line(capsys, main(args + ["--max-memory-gb", "0.001"]), "GiB limit", "4,000 trials")
    monkeypatch.setenv("SIM_MAX_ADJUSTMENTS", "1000")
    one_line(capsys, main(args), "adjustments")
    assert not (tmp_path / "o").exists()


def test_require_finite_and_write_table_refuse_non_finite_statistics(tmp_path):
    from sim.mc.config import StudyError
    from sim.mc.runner import require_finite
    from sim.mc.storage import NonFiniteError, write_table

    assert require_finite("x", [1.0, 2.0], "part").tolist() == [1.0, 2.0]
    with pytest.raises(StudyError, match="dilution: sigma_um is not finite .*change errors.x"):
        require_finite("sigma_um", [1.0, np.inf, np.nan], "dilution", key="errors.x")
    write_table(tmp_path / "ok.parquet", {"a": [1.0, np.nan]}, {})  # NaN may mean missing
    with pytest.raises(NonFiniteError, match="column a is inf"):
        write_table(tmp_path / "bad.parquet", {"a": [1.0, np.inf]}, {})
    with pytest.raises(NonFiniteError, match="claim c2"):
        write_table(
            tmp_path / "claims.parquet",
            {
                "claim": ["c1", "c2"],
                "value": [1.0, 2.0],
                "ci_low": [0.5, np.nan],
                "ci_high": [2.0, 3.0],
                "verdict": ["holds", "fails"],
            },
            {},
        )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ok.parquet"]
    write_table(
        tmp_path / "claims.parquet",
        {
            "claim": ["c1"],
            "value": [None],
            "ci_low": [None],
            "ci_high": [None],
            "verdict": ["not comparable"],
        },
        {},
    )
    with pytest.raises(StudyError, match="at least 20 chunks"):
        jackknife(lambda t: t[0], np.ones((1, 2)))
