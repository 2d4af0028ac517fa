"""The lead's own sweep of the session of 2026-11-28 evening (issue 26): ``python -m
benchmarks`` (``make bench``) given an ``--out`` holding what it did not write. Each test failed
on the code before its fix."""

from __future__ import annotations

import argparse

import pytest

from benchmarks import cli
from benchmarks.page import HEADING
from sim.mc.storage import provenance, write_table


def _check(out):
    ns = argparse.Namespace(out=str(out), rerun_files=None, rerun_workers=None, quick=False)
    cli._check_args(ns, ("store",))


def _refused(capsys, args, *words):
    assert cli.main(["--quick", "--only", "store", *args]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and all(w in err for w in words), err


def test_a_users_readme_in_out_is_refused_not_replaced(tmp_path, capsys):
    # before: --out DIR overwrote DIR/README.md (the page) without a word, whoever wrote it
    (tmp_path / "README.md").write_text("# my notes\n")
    _refused(capsys, ["--out", str(tmp_path)], "README.md", "was not written by the benchmark")
    assert (tmp_path / "README.md").read_text() == "# my notes\n"


def test_a_users_directory_named_like_the_scratch_store_is_refused(tmp_path, capsys):
    # before: the brown section removed DIR/million_trials.tmp with shutil.rmtree, whatever it held
    (tmp_path / "million_trials.tmp").mkdir()
    (tmp_path / "million_trials.tmp" / "thesis.tex").write_text("x")
    _refused(capsys, ["--out", str(tmp_path)], "million_trials.tmp")


def test_the_parent_of_studies_results_is_refused(tmp_path, capsys):
    # before: --out results wrote the bench's tables and page among the studies' directories
    (tmp_path / "brown_table1").mkdir()
    (tmp_path / "brown_table1" / "claims.parquet").write_bytes(b"")
    _refused(capsys, ["--out", str(tmp_path)], "holds studies' results directories")


def test_a_directory_the_bench_wrote_is_taken_again(tmp_path):
    write_table(tmp_path / "store.parquet", {"x": [1.0]}, provenance({"study": "bench"}))
    (tmp_path / "README.md").write_text(HEADING + "\n\nmore\n")
    (tmp_path / "million_trials.tmp" / "part-0").mkdir(parents=True)
    (tmp_path / "million_trials.tmp" / "part-0" / "chunk-000000.parquet").write_bytes(b"")
    _check(tmp_path)
    # a table of another study under the bench's name is not the bench's
    write_table(tmp_path / "engines.parquet", {"x": [1.0]}, provenance({"study": "brown"}))
    with pytest.raises(cli._ArgError, match="engines.parquet"):
        _check(tmp_path)
