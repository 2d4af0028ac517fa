"""The classes of the sweep doors28c (brief D28c: ``make verify`` and ``sim report`` during a
``make reproduce`` that really re-runs studies, and results that travel: copied, renamed,
moved under a link, read-only, made at another commit), one case each; each failed on the code
before its fix. Copies (``cp -a``, ``tar`` without times, a ``git clone``), a renamed or
linked results directory, an extra directory, a figure deleted and a table of another seed
were all right already.

* a results tree on a read-only mount (a clone checked out read-only, a bind mount): ``sim
  report`` (and the report step of ``make verify``) said "Read-only file system:
  results/agnard_block/.README.md.22149.tmp", a file the user never saw: removing the
  temporary that could not be made failed too there (EROFS, not ENOENT), and that error
  replaced the one being reported (:class:`sim.mc.storage.atomic_path`).
* the reproducibility record did not say which results it checked: a study re-run after
  ``make verify`` (``make reproduce`` after an edit, at a newer commit, or in another terminal
  while verify ran), its results replaced by a copy or removed, still read "within tolerance:
  yes" in the report's *Reproducibility* section (the committed REPORT.md said so of every
  study re-run the day after its record). The record now holds the sha256 of the tables each
  comparison read, and the section says which results are not the ones checked
  (:func:`sim.report.verify.record.markdown`).
* ``make verify`` during a ``make reproduce`` that publishes new results of the study it is
  comparing: the tables read before the publish were of the old run, the rest of the new one,
  and the FAILED line listed deviations that no re-run had (not "stale"); the comparison is
  now made again when the directory changed while it read it
  (:func:`sim.report.verify.rerun._settled`). The test publishes between two tables.
* ``make verify`` whose comparison failed (exit 1) wrote the failure into the record but left
  REPORT.md as it was: it went on showing the previous check's "yes" for results that had
  just failed (the report step ran only after a success). A failed comparison now rebuilds
  the report before make stops; a refused request (2) or an interrupt (130) does not.
* a clone made with ``core.autocrlf=true`` (Git for Windows' default) checked every text file
  out with CRLF line ends: each study's code hash (the bytes of its modules) and the sha256 of
  Wolf's tables changed, so every committed result was "made by other code" (``make
  reproduce`` re-ran them all on a fresh clone) and ``make verify`` failed wolf_polynomial as
  "of another config (keys table1.sha256, table3.sha256)". ``.gitattributes`` now checks text
  out with LF whatever the setting.
* a committed claims table rewritten without its Parquet metadata (pandas, or pyarrow
  without ``schema.metadata``) passed ``make verify`` ("ok", its numbers matched, and the
  record said so) while ``sim show`` and ``sim report`` refused it as "not a claims table
  written by sim" (make verify's own report step then failed): verify now refuses what they
  refuse, naming the file (:func:`sim.report.verify.rerun._not_as_written`).
"""

import errno
import os
import pathlib
import shutil
import subprocess
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from oneline import SIM_ERROR, one_line

import sim.report.verify.rules as rules
from sim.cli import main
from sim.mc.outputs import stage_dir
from sim.mc.publish import publish
from sim.report.verify import main as verify_main
from sim.report.verify import markdown
from tests.test_doors18c import MAKE, fake_project, run_make

ROOT = Path(__file__).resolve().parent.parent


def _read_only(monkeypatch, top: Path) -> None:
    """Everything under ``top`` as on a read-only mount (``mount -o remount,ro,bind``): writing
    a file there and removing one, even one that is not there, is EROFS (root writes through
    every mode bit, and a test may not mount, so the test says it)."""

    def under(p) -> bool:
        return Path(os.fsdecode(p)).resolve().is_relative_to(top.resolve())

    real_unlink, real_write_text = os.unlink, pathlib.Path.write_text

    def unlink(p, *a, **k):
        if under(p):
            raise OSError(errno.EROFS, "Read-only file system", os.fsdecode(p))
        return real_unlink(p, *a, **k)

    def write_text(self, *a, **k):
        if under(self):
            raise OSError(errno.EROFS, "Read-only file system", str(self))
        return real_write_text(self, *a, **k)

    monkeypatch.setattr(os, "unlink", unlink)
    monkeypatch.setattr(pathlib.Path, "write_text", write_text)


@pytest.mark.long
def test_sim_report_on_a_read_only_mount_names_the_readme_not_its_temporary(
    tiny_run, tmp_path, monkeypatch, capsys
):
    results = tmp_path / "results"
    shutil.copytree(tiny_run("network_plate"), results / "network_plate")
    before = {p: p.read_bytes() for p in results.rglob("*") if p.is_file()}
    _read_only(monkeypatch, results)
    rc = main(["report", "--results", str(results)])
    line = one_line(capsys, rc, "Read-only file system", prefix=SIM_ERROR)
    assert line.endswith(str(results / "network_plate" / "README.md")), line
    assert ".tmp" not in line
    assert {p: p.read_bytes() for p in results.rglob("*") if p.is_file()} == before


def _results_and_rerun(tmp_path: Path, tiny_run) -> tuple[Path, Path]:
    """``results/network_plate`` (committed) and ``scratch/network_plate`` (its re-run)."""
    results, scratch = tmp_path / "results", tmp_path / "scratch"
    for d in (results, scratch):
        shutil.copytree(tiny_run("network_plate"), d / "network_plate")
    return results, scratch


def _row(text: str, study: str) -> str:
    return next(ln for ln in text.splitlines() if ln.startswith(f"| {study} |"))


def test_the_report_does_not_call_results_replaced_after_verify_verified(
    tiny_run, tmp_path, capsys
):
    results, scratch = _results_and_rerun(tmp_path, tiny_run)
    args = ["--results", str(results), "--scratch", str(scratch), "--no-rerun"]
    assert verify_main(args) == 0
    capsys.readouterr()
    assert _row(markdown(results), "network_plate").endswith("| yes |  |")
    shutil.rmtree(results / "network_plate")  # make reproduce after the study file was edited
    shutil.copytree(tiny_run("network_plate", "--set", "seed=5"), results / "network_plate")
    text = markdown(results)
    row = _row(text, "network_plate")
    assert "| yes |" not in row and "not checked now" in row and "changed" in row, row
    assert "run make verify again" in text
    shutil.rmtree(results / "network_plate")  # a copy of the results without this study
    shutil.copytree(tiny_run("network_plate"), results / "network_plate_copy")
    text = markdown(results)
    assert "no longer there" in _row(text, "network_plate")
    assert "Not checked: network_plate_copy" in text


def test_verify_compares_again_when_a_run_publishes_while_it_reads(
    tiny_run, tmp_path, monkeypatch, capsys
):
    results, scratch = _results_and_rerun(tmp_path, tiny_run)
    out = results / "network_plate"
    stage = stage_dir(out)  # make reproduce's run of the edited study file, finished
    shutil.copytree(tiny_run("network_plate", "--set", "seed=5"), stage)
    real, read = rules.compare_tables, []

    def compare_tables(a, b, cmp, mode="full"):
        real(a, b, cmp, mode)
        read.append(a.name)
        if len(read) == 1:  # between the first table and the second: the run publishes
            publish(stage, out)

    monkeypatch.setattr(rules, "compare_tables", compare_tables)
    rc = verify_main(["--results", str(results), "--scratch", str(scratch), "--no-rerun"])
    text = capsys.readouterr().out
    assert rc == 1 and len(read) > 1 and not stage.exists()
    assert text.startswith("network_plate: FAILED; nothing compared\n"), text
    assert "another config than the re-run (keys seed)" in text and "allowed" not in text, text
    assert "not checked now" not in _row(markdown(results), "network_plate")


@pytest.mark.skipif(MAKE is None, reason="no make on this machine")
@pytest.mark.parametrize("code, report", [(0, True), (1, True), (2, False), (130, False)])
def test_a_failed_comparison_of_make_verify_rebuilds_the_report(tmp_path, code, report):
    log, fake = tmp_path / "calls.log", tmp_path / "python"
    fake.write_text(  # a Python whose verify ends with the code, every other command with 0
        f'#!/bin/sh\necho "$*" >> {log}\ncase "$*" in *sim.report.verify*) exit {code};; esac\n',
        encoding="utf-8",
    )
    fake.chmod(0o755)
    p = run_make(fake_project(tmp_path, str(fake)), "verify")
    calls = [ln for ln in log.read_text(encoding="utf-8").splitlines() if ln.startswith("-m ")]
    verify, rebuild = "-m sim.report.verify --results results --workers 2", "-m sim report"
    assert calls == [verify, *([f"{rebuild} --results results"] if report else [])], calls
    assert p.returncode == (0 if code == 0 else 2), p.stderr
    assert code == 0 or f"verify] Error {code}" in p.stderr, p.stderr


#: one committed file of each kind a study's staleness or a comparison reads: code, a study
#: file, a data file it hashes, a run record, a table, a figure, a page
KINDS = [
    "sim/mc/codehash.py",
    "studies/wolf_polynomial.toml",
    "studies/data/wolf_table1.csv",
    "results/brown_table1/run.json",
    "results/brown_table1/claims.parquet",
    "results/brown_table1/table1.png",
    "README.md",
]


@pytest.mark.skipif(shutil.which("git") is None, reason="needs git")
def test_a_clone_made_with_autocrlf_holds_every_file_as_committed(tmp_path):
    env = {**os.environ, "GIT_CONFIG_GLOBAL": os.devnull, "GIT_CONFIG_NOSYSTEM": "1"}
    env |= {k: "t" for k in ("GIT_AUTHOR_NAME", "GIT_COMMITTER_NAME")}
    env |= {k: "t@t" for k in ("GIT_AUTHOR_EMAIL", "GIT_COMMITTER_EMAIL")}
    src, dst = tmp_path / "src", tmp_path / "clone"
    for f in [*KINDS, ".gitattributes"]:
        if (ROOT / f).is_file():  # (before the fix there was no .gitattributes)
            (src / f).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(ROOT / f, src / f)
    for cmd in (["init", "-q", str(src)], ["-C", str(src), "add", "-A"]):
        subprocess.run(["git", *cmd], env=env, check=True, capture_output=True)
    subprocess.run(["git", "-C", str(src), "commit", "-qm", "x"], env=env, check=True)
    clone = ["git", "-c", "core.autocrlf=true", "clone", "-q", str(src), str(dst)]
    subprocess.run(clone, env=env, check=True, capture_output=True)
    changed = [f for f in KINDS if (dst / f).read_bytes() != (ROOT / f).read_bytes()]
    assert changed == [], f"checked out otherwise than committed: {changed}"


def test_verify_refuses_a_claims_table_that_lost_its_metadata_as_the_report_does(
    tiny_run, tmp_path, capsys
):
    results, scratch = _results_and_rerun(tmp_path, tiny_run)
    f = results / "network_plate" / "claims.parquet"
    pq.write_table(pq.read_table(f).replace_schema_metadata(None), f)  # another tool's copy
    args = ["--results", str(results), "--scratch", str(scratch), "--no-rerun", "--no-record"]
    rc = verify_main(args)
    out = capsys.readouterr().out
    assert rc == 1 and out.startswith("network_plate: FAILED; nothing compared\n"), out
    assert f"{f} is not a claims table written by sim" in out, out
    one_line(capsys, main(["report", "--results", str(results)]), f"{f} is not a claims table")
