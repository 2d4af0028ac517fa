"""Results and studies that came from elsewhere (doors51k, brief K52): a colleague's results
unpacked from a zip, copied with ``cp -r``/``cp -rL``, made by an older commit, moved, merged by
hand or opened on a read-only share, read and re-run through every door; each test fails on the
code before its fix:

* ``python -m sim.batch --stale-only`` over current results on a read-only share refused every
  study ("cannot be replaced by this run ... choose another --results", exit 2) although it
  would run none of them: the current ones are "up to date" now, a stale one is still refused;
* ``make verify`` of results on a read-only share re-ran every study (hours) and only then
  failed writing ``reproducibility.parquet`` (exit 2): refused before any re-run, naming
  ``--no-record``;
* results of an older commit unpacked outside the project were noted by ``sim show``,
  ``sim report`` and ``sim.Results`` as "make reproduce re-runs what is stale", a command that
  re-runs only the project's ``results/``: outside them the note names ``sim run ... --out DIR
  --overwrite``.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest
from conftest import TRIANGLE_NETWORK
from oneline import one_line

import sim
import sim.batch
import sim.report.verify.cli as verify_cli
from sim.cli import main as cli_main

ROOT = Path(__file__).resolve().parents[1]


def _read_only(monkeypatch, root: Path) -> None:
    """``root`` as on a read-only share (or another user's): nobody may write in it (root
    bypasses file modes, and a test may not mount; ``os.access`` is what the suite asks)."""
    real = os.access

    def access(path, mode, *args, **kwargs):
        if mode & os.W_OK and os.path.abspath(path) == str(root):
            return False
        return real(path, mode, *args, **kwargs)

    monkeypatch.setattr(os, "access", access)


def test_stale_only_over_current_read_only_results_says_up_to_date(capsys, monkeypatch, tmp_path):
    """Class: ``--stale-only`` over shared results on a read-only share. Before: every study,
    current or not, "cannot be replaced by this run (you may not write in ...)", exit 2 and no
    word of which were current; now the current one is "up to date" (exit 0) and only a study
    that would run is refused."""
    study, other = tmp_path / "tri.toml", tmp_path / "tri2.toml"
    study.write_text(TRIANGLE_NETWORK, encoding="utf-8")
    other.write_text(TRIANGLE_NETWORK, encoding="utf-8")
    results = tmp_path / "shared"
    assert cli_main(["run", str(study), "--out", str(results / "tri"), "--no-figures"]) == 0
    tri2 = ["run", str(other), "--out", str(results / "tri2"), "--no-figures", "--seed", "3"]
    assert cli_main(tri2) == 0  # another seed: not current, a batch would replace it
    capsys.readouterr()
    _read_only(monkeypatch, results)
    argv = ["--stale-only", "--results", str(results), str(study), "--", "--no-figures"]
    assert sim.batch.main(argv) == 0, capsys.readouterr().err
    assert "tri: up to date" in capsys.readouterr().out
    rc = sim.batch.main([*argv[:-2], str(other), "--", "--no-figures"])  # stale: would run
    one_line(capsys, rc, str(other), "cannot be replaced", "you may not write in")


def test_verify_into_read_only_results_is_refused_before_any_rerun(capsys, monkeypatch, tmp_path):
    """Class: ``make verify`` of results on a read-only share. Before: every study was re-run,
    and then "cannot write <results>/reproducibility.parquet: Read-only file system", exit 2
    (hours of re-runs for nothing); now one line before any re-run, naming --no-record."""
    results = tmp_path / "shared"
    results.mkdir()
    _read_only(monkeypatch, results)

    def rerun(*args, **kwargs):
        raise AssertionError("a re-run started")

    monkeypatch.setattr(verify_cli, "verify", rerun)
    rc = verify_cli.main(["--results", str(results), "--studies", str(tmp_path)])
    one_line(capsys, rc, f"you may not write in {results}", "--no-record")
    with pytest.raises(AssertionError, match="a re-run started"):  # --no-record: it goes on
        verify_cli.main(["--results", str(results), "--studies", str(tmp_path), "--no-record"])


def test_older_results_elsewhere_are_not_sent_to_make_reproduce(capsys, monkeypatch, tmp_path):
    """Class: results of an older commit unpacked outside the project. Before: "was made by
    another version of the suite's code ...: make reproduce re-runs what is stale" from show,
    report and the API, though make reproduce never re-runs them; the project's own results/
    keep that note."""
    shared = tmp_path / "from_a_colleague"
    shutil.copytree(ROOT / "results" / "network_plate", shared / "network_plate")
    monkeypatch.setattr("sim.stale.study_code_hash", lambda study: "f" * 16)  # an older run
    assert cli_main(["show", str(shared / "network_plate")]) == 0
    err = capsys.readouterr().err
    assert "another version" in err and "--overwrite makes them current" in err, err
    assert "make reproduce re-runs" not in err
    assert cli_main(["show", str(ROOT / "results" / "network_plate")]) == 0
    err = capsys.readouterr().err
    assert "another version" in err and "make reproduce re-runs what is stale" in err, err
    with pytest.warns(UserWarning, match=r"--overwrite makes them current \(not make reproduce"):
        sim.Results(shared / "network_plate", "network").table("claims")
