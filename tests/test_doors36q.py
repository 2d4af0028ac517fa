"""The classes of the sweep doors36q (issue 26: do the doors that print one results directory
agree -- ``sim show``, ``sim show --markdown`` (its README.md), ``sim report``, the API and
the end of ``sim run``?), one case each; each failed on the code before its fix.

* ``sim show``'s table gave a self-check that could not decide its own rule as ``self-check``,
  the verdict of one that held, while its counts below (and README.md's table, ``self-check
  (inconclusive)``) called it undecided: the row now gives the outcome in brackets as
  README.md's table does (:func:`sim.report.run_summary.verdict_cell`);
* a run off the paper's setup (``--set errors.setting_sigma_um=3``): README.md says so at its
  top ("Off the paper's setup (...): its predictions are findings ..."), but ``sim show`` and
  the end of ``sim run`` printed the same verdicts without a word of it: both now give
  README.md's line below their counts (:func:`sim.report.off_paper.off_note`), and
  ``sim report``'s line on the run's configuration (REPORT.md) gives it too.
"""

from __future__ import annotations

import shutil

from sim.cli import main
from sim.report import run_summary
from sim.report.run_summary import terminal_summary, terminal_table
from sim.studies import get_study


def test_show_gives_a_self_checks_outcome_as_the_readme_and_the_counts_do(tiny_run, monkeypatch):
    d = tiny_run("network_brown")
    rows = run_summary.records(d / "claims.parquet")
    i = next(i for i, r in enumerate(rows) if r["kind"] == "self-check" and r["outcome"] == "holds")
    rows[i] = {**rows[i], "outcome": "inconclusive"}  # a self-check its rule left undecided
    monkeypatch.setattr(run_summary, "records", lambda p: rows)
    text = terminal_table(d)
    line = next(ln for ln in text.splitlines() if ln.startswith(rows[i]["claim"]))
    assert line.rstrip().endswith("self-check (inconclusive)"), line
    undecided = sum(r["kind"] == "self-check" and r["outcome"] == "inconclusive" for r in rows)
    shown = sum(ln.rstrip().endswith("self-check (inconclusive)") for ln in text.splitlines())
    assert shown == undecided and f"{undecided} self-check undecided" in text


def test_show_and_the_end_of_a_run_say_a_run_is_off_the_papers_setup(tiny_run, capsys):
    d = tiny_run("brown_table1", "--set=errors.setting_sigma_um=3.0")
    said = next(ln for ln in (d / "README.md").read_text().splitlines() if "Off the paper" in ln)
    said = said.strip("*.")
    assert main(["show", str(d)]) == 0
    assert said in capsys.readouterr().out.splitlines()
    assert said in terminal_summary(d, get_study=get_study).splitlines()


def test_report_says_a_run_is_off_the_papers_setup(tiny_run, tmp_path, capsys):
    d = tiny_run("brown_table1", "--set=errors.setting_sigma_um=3.0")
    said = next(ln for ln in (d / "README.md").read_text().splitlines() if "Off the paper" in ln)
    shutil.copytree(d, tmp_path / "r" / "off")
    assert main(["report", "--results", str(tmp_path / "r")]) == 0
    capsys.readouterr()
    line = next(
        ln
        for ln in (tmp_path / "r" / "REPORT.md").read_text().splitlines()
        if ln.startswith("- [off]")
    )
    assert said.strip("*") in line
