"""The classes of the sweep doors36q (issue 26: do the doors that print one results directory
agree -- ``sim show``, ``sim show --markdown`` (its README.md), ``sim report``, the API and
the end of ``sim run``?), one case each; each failed on the code before its fix.

* ``sim show``'s table gave a self-check that could not decide its own rule as ``self-check``,
  the verdict of one that held, while its counts below (and README.md's table, ``self-check
  (inconclusive)``) called it undecided: the row now gives the outcome in brackets as
  README.md's table does (:func:`sim.report.run_summary.verdict_cell`).
"""

from __future__ import annotations

from sim.report import run_summary
from sim.report.run_summary import terminal_table


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
