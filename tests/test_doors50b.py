"""The batch, verify and report doors used carelessly (doors50b, brief B51): each class through
a real door; each test fails on the code before its fix:

* the batch's own options put after ``--`` among sim run's (``-- -j 2``, ``-- --report``,
  ``-- --stale-only``, ``-- --timings t.json``, a beginning ``--stale``) were called
  "unrecognized arguments" with a wrong guess ("did you mean --workers?", "--set?", "--trials?",
  for ``--job`` "a batch's output: give --results") or ``--results`` "an option of sim
  report": each is named as the batch's own, to give before ``--``;
* ``python -m sim.batch --report`` into a results directory whose ``REPORT.md`` is the user's
  (a file of theirs, a directory, a link) ran every study, for hours overnight, and then
  failed on the report (exit 2): refused before any run, one line naming it;
* ``make verify`` of a network whose study file reads a GNU Gama file moved away since the run
  called the study "FAILED; nothing compared" and recorded it as not reproduced (exit 1):
  exit 2, one line naming the key and the file, nothing recorded.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import TRIANGLE_NETWORK
from oneline import one_line

import sim.batch
from sim.cli import main as cli_main
from sim.report.verify import main as verify_main

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize(
    ("own", "named"),
    [
        (["-j", "2"], "-j"),
        (["-j2"], "-j"),
        (["--jobs=2"], "--jobs"),
        (["--job", "2"], "--job (--jobs?)"),
        (["--report"], "--report"),
        (["--stale"], "--stale (--stale-only?)"),
        (["--results=x"], "--results"),
    ],
)
def test_the_batchs_own_option_after_the_double_dash_is_named_as_its(capsys, tmp_path, own, named):
    """Class: an option of the batch given among sim run's. Before: "unrecognized arguments:
    -j 2 (did you mean --workers?)" (or --set?, --trials?, "an option of sim report", and for
    ``--job 2`` "a batch's output: give --results DIR before --")."""
    st = tmp_path / "tri.toml"
    st.write_text(TRIANGLE_NETWORK, encoding="utf-8")
    rc = sim.batch.main([str(st), "--results", str(tmp_path / "r"), "--", "--no-figures", *own])
    line = one_line(capsys, rc, f"{named} is an option of sim.batch, not of sim run")
    assert "give it before --" in line and "did you mean" not in line
    assert not (tmp_path / "r").exists()


def test_a_batch_report_over_a_users_report_md_is_refused_before_the_runs(capsys, tmp_path):
    """Class: ``--report`` into a results directory whose REPORT.md the suite did not write.
    Before: every study ran (and published) and then sim report refused it, exit 2."""
    st = tmp_path / "tri.toml"
    st.write_text(TRIANGLE_NETWORK, encoding="utf-8")
    results = tmp_path / "r"
    results.mkdir()
    mine = results / "REPORT.md"
    mine.write_text("# my notes\n", encoding="utf-8")
    rc = sim.batch.main([str(st), "--results", str(results), "--report", "--", "--no-figures"])
    one_line(capsys, rc, f"--report: {mine} was not written by sim report")
    assert not (results / "tri").exists()  # nothing ran
    assert mine.read_text(encoding="utf-8") == "# my notes\n"


def test_verify_of_a_network_whose_gama_file_moved_away_records_no_failure(capsys, tmp_path):
    """Class: ``make verify`` of results whose study file reads a GNU Gama file that was moved
    away since the run. Before: "gnet: FAILED; nothing compared / the re-run exited with 2",
    exit 1, and reproducibility.parquet recorded the study as not reproduced: now exit 2, one
    line naming the file and the key, nothing recorded."""
    gama = tmp_path / "net.xml"
    shutil.copy(ROOT / "tests" / "data" / "gama" / "one_fixed.xml", gama)
    (studies := tmp_path / "st").mkdir()
    study = studies / "gnet.toml"
    study.write_text(
        f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{gama}"\n',
        encoding="utf-8",
    )
    results = tmp_path / "r"
    assert cli_main(["run", str(study), "--out", str(results / "gnet"), "--no-figures"]) == 0
    gama.rename(tmp_path / "moved.xml")
    capsys.readouterr()
    argv = ["--results", str(results), "--studies", str(studies), "--scratch", str(tmp_path / "s")]
    rc = verify_main(argv)
    err = capsys.readouterr().err
    assert rc == 2 and "Traceback" not in err, err
    last = err.splitlines()[-1]
    assert last.startswith("sim verify: error: gnet: a file its study file"), err
    assert "network.gama_xml" in last and str(gama) in last
    assert not (results / "reproducibility.parquet").exists()
