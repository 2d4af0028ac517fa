"""A self-check that did not hold its own rule, counted apart (issue 26: doors21b left an
inconclusive self-check counted as a plain one). network_gridplate_2500's false-alarm share
(0.061, its interval reaching past the test's level) read "4 self-check" in ``sim show``, in
its README and on REPORT.md's first screen, as if Monte Carlo and theory agreed; REPORT.md's
counts per study named only a *failed* self-check. Now both count it apart, alike."""

from __future__ import annotations

from sim.report.markdown import verdict_counts
from sim.report.run_summary import verdict_line

CLAIMS = [
    {"kind": "self-check", "verdict": "self-check", "outcome": "holds"},
    {"kind": "self-check", "verdict": "self-check", "outcome": "holds"},
    {"kind": "self-check", "verdict": "self-check", "outcome": "inconclusive"},
    {"kind": "self-check", "verdict": "self-check", "outcome": "fails"},
    {"kind": "finding", "verdict": "finding", "outcome": None},
]


def test_the_verdict_line_counts_a_self_check_that_did_not_hold_apart():
    assert verdict_line(CLAIMS) == (
        "5 claims: 2 self-check, 1 self-check failed, 1 self-check undecided, 1 finding"
    )


def test_the_counts_per_study_name_the_failed_and_the_undecided_self_checks():
    c = verdict_counts(CLAIMS)
    assert (c["self-check"], c["self-check failed"], c["self-check undecided"]) == (4, 1, 1)
    assert verdict_counts(CLAIMS[:2])["self-check undecided"] == 0
