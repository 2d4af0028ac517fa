"""The doors besides the paper studies' files: the Python API's arguments, the chunk store's
identity checks, output ownership (nested outputs, a user's files, a damaged staging
directory), the batch driver's refusals and the suite report's ownership of REPORT.md."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import sim
from benchmarks.cli import tiny_overrides
from sim.cli import main
from sim.mc.config import ConfigError
from sim.mc.runner import ChunkStore, run_chunks
from sim.mc.storage import read_table
from sim.studies import RunContext

ROOT = Path(__file__).resolve().parent.parent
STUDY = ROOT / "studies" / "brown_table1.toml"
TINY = list(tiny_overrides(STUDY))


def _run(out: Path, *extra: str) -> int:
    """A tiny run into ``out`` without figures (these tests are about what it writes where)."""
    return main(["run", str(STUDY), "--out", str(out), "--quiet", "--no-figures", *TINY, *extra])


# --- the Python API ------------------------------------------------------------------------


@pytest.mark.parametrize("bad", [123, None, 1.5, b"studies/x.toml", "", "no/such/study.toml"])
def test_load_names_a_bad_study_file_argument(bad):
    with pytest.raises(ConfigError, match="study_file"):
        sim.load(bad)


@pytest.mark.parametrize(
    "kw, key",
    [
        ({"out": 5}, "out"),
        ({"out": ""}, "out"),
        ({"workers": "2"}, "workers"),
        ({"workers": 0}, "workers"),
        ({"workers": True}, "workers"),
        ({"executor": "threads"}, "executor"),
        ({"trials": 2.5}, "trials"),
        ({"seed": "7"}, "seed"),
        ({"overwrite": "yes"}, "overwrite"),
        ({"scheduler": "nowhere"}, "scheduler"),
    ],
)
def test_run_names_a_bad_argument(tmp_path, kw, key):
    st = sim.load(STUDY, trials=20, chunk=1)
    with pytest.raises(ConfigError, match=f"^{key}"):
        st.run(**({"out": tmp_path / "o"} | kw))
    assert not (tmp_path / "o").exists()


def test_a_table_name_must_be_a_name(tmp_path):
    res = sim.Results(tmp_path, "brown_table1")
    with pytest.raises(ConfigError, match="table"):
        res.table(3)


# --- chunks carry their identity -----------------------------------------------------------


def _toy(rng, n):
    x = rng.normal(size=(n, 2))
    return {"rows.x0": x[:, 0], "x": x}


def _store(tmp_path, name="trials", prov=None):
    return ChunkStore(tmp_path / name, prov or {"study": "toy", "config": {"a": 1}})


def test_a_chunk_that_is_not_what_its_name_says_is_computed_again(tmp_path):
    clean = run_chunks(_toy, 40, 9, 10, quiet=True)["x"]
    store = _store(tmp_path)
    run_chunks(_toy, 40, 9, 10, ctx=RunContext(quiet=True, store=store))
    d = tmp_path / "trials" / "part-0"
    c0, c1 = d / "chunk-000000.parquet", d / "chunk-000001.parquet"
    tmp = d / "swap"
    c0.rename(tmp), c1.rename(c0), tmp.rename(c1)  # swapped
    other = _store(tmp_path, "other")  # another seed's chunk put in place of chunk 2
    run_chunks(_toy, 40, 10, 10, ctx=RunContext(quiet=True, store=other))
    shutil.copy(tmp_path / "other" / "part-0" / "chunk-000002.parquet", d / "chunk-000002.parquet")
    foreign = _store(tmp_path, "foreign", {"study": "toy", "config": {"a": 2}})  # another config
    run_chunks(_toy, 40, 9, 10, ctx=RunContext(quiet=True, store=foreign))
    shutil.copy(
        tmp_path / "foreign" / "part-0" / "chunk-000003.parquet",
        c1.with_name("chunk-000003.parquet"),
    )
    calls = []

    def counting(rng, n):
        calls.append(n)
        return _toy(rng, n)

    again = run_chunks(counting, 40, 9, 10, ctx=RunContext(quiet=True, store=_store(tmp_path)))
    assert calls == [10, 10, 10, 10]  # every chunk was refused and computed again
    assert np.array_equal(again["x"], clean)


def test_chunks_beyond_the_run_are_strays(tmp_path):
    store = _store(tmp_path)
    run_chunks(_toy, 40, 9, 10, ctx=RunContext(quiet=True, store=store))
    extra = tmp_path / "trials" / "part-0" / "chunk-000009.parquet"
    shutil.copy(tmp_path / "trials" / "part-0" / "chunk-000000.parquet", extra)
    store2 = _store(tmp_path)
    run_chunks(_toy, 40, 9, 10, ctx=RunContext(quiet=True, store=store2))
    assert store2.strays() == [extra]


def test_a_finished_run_has_exactly_its_trials_and_their_hashes(tmp_path):
    out = tmp_path / "out"
    assert _run(out) == 0
    rec = json.loads((out / "run.json").read_text())
    chunks = sorted(p.relative_to(out).as_posix() for p in (out / "trials").rglob("*.parquet"))
    assert sorted(rec["chunk_sha256"]) == chunks and len(chunks) >= 2
    assert set(chunks) <= set(rec["files"])


# --- output ownership ----------------------------------------------------------------------


def test_a_users_file_in_a_results_directory_survives_a_rerun(tmp_path):
    out = tmp_path / "out"
    assert _run(out) == 0
    (out / "my-notes.txt").write_text("mine")
    assert _run(out, "--seed", "5", "--overwrite") == 0
    assert (out / "my-notes.txt").read_text() == "mine"
    assert read_table(out / "claims.parquet").num_rows > 0


def test_an_output_inside_another_run_is_refused(tmp_path, capsys):
    out = tmp_path / "out"
    assert _run(out) == 0
    for inner in (out / "sub", out / "trials" / "x"):
        assert _run(inner) == 2
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and "belongs to another run" in err
        assert not inner.exists()


def test_a_damaged_staging_directory_is_named_and_replaced_by_overwrite(tmp_path, capsys):
    out = tmp_path / "out"
    assert _run(out) == 0
    stage = tmp_path / ".out.partial"
    stage.mkdir()
    shutil.copy(out / "run.json", stage / "run.json")
    (stage / "trials" / "part-0" / "chunk-000000.parquet").mkdir(parents=True)
    shutil.rmtree(out)
    assert _run(out) == 2
    assert "damaged" in capsys.readouterr().err
    assert _run(out, "--overwrite") == 0
    assert (out / "claims.parquet").is_file() and not stage.exists()


def test_report_never_replaces_a_report_it_did_not_write(tmp_path, capsys):
    d = tmp_path / "res"
    d.mkdir()
    (d / "REPORT.md").write_text("# my own report\n")
    assert main(["report", "--results", str(d)]) == 2
    err = capsys.readouterr().err  # no study results there either: refused before anything
    assert "not written by sim report" in err or "no study results in" in err
    assert err.count("\n") == 1 and (d / "REPORT.md").read_text() == "# my own report\n"
    (d / "notes.txt").write_text("mine\n")  # a directory of the user's, no REPORT.md
    assert main(["report", "--results", str(d)]) == 2
    assert "no study results in" in capsys.readouterr().err
    assert sorted(p.name for p in d.iterdir()) == ["REPORT.md", "notes.txt"]


def test_report_names_a_claims_table_that_is_not_ours(tmp_path, capsys):
    import pyarrow as pa
    import pyarrow.parquet as pq

    (tmp_path / "res" / "x").mkdir(parents=True)
    pq.write_table(pa.table({"a": [1, 2]}), tmp_path / "res" / "x" / "claims.parquet")
    assert main(["report", "--results", str(tmp_path / "res")]) == 2
    err = capsys.readouterr().err
    assert "claims.parquet is not a claims table" in err and err.count("\n") == 1


# --- the batch driver ----------------------------------------------------------------------


def _batch(*args, cwd=ROOT):
    return subprocess.run(
        [sys.executable, "-m", "sim.batch", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=120,
    )


def test_batch_refuses_two_runs_into_one_directory_before_running(tmp_path):
    other = tmp_path / "b"
    other.mkdir()
    shutil.copy(STUDY, other / STUDY.name)
    for args in (
        [str(STUDY), str(STUDY)],
        [str(STUDY), str(other / STUDY.name)],
        [str(STUDY), "--", "--out", str(tmp_path / "x")],
    ):
        r = _batch("--results", str(tmp_path / "r"), *args)
        assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
        assert not (tmp_path / "r").exists() and not (tmp_path / "x").exists()


def test_batch_timings_into_a_missing_directory_fails_at_once(tmp_path):
    r = _batch(
        "--results", str(tmp_path / "r"), "--timings", str(tmp_path / "no" / "t.json"), str(STUDY)
    )
    assert r.returncode == 2 and "--timings" in r.stderr
    assert not (tmp_path / "r").exists()
