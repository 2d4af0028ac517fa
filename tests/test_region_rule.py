"""The sample-size rule of region verdicts (sim.claims.region, issues 26/28 follow-up): a
prediction that holds (fails) at every accepted point of a consistent region is "holds"
("fails") only over at least REGION_MIN_POINTS = 29 points, the fewest whose exact 95 % bound
on the share of the region where it disagrees, 1 - 0.05**(1/k), is at most 10 %; with fewer
it is "inconclusive", saying why. The bound is checked against scipy.stats (the
Clopper-Pearson bound of 0 of k, and the binomial probability of no disagreeing point)."""

import numpy as np
import pytest
from scipy import stats

from sim.claims.book import VERDICTS, ClaimBook
from sim.claims.book_region import region_rows
from sim.claims.inference import Input, Statement, explore
from sim.claims.region import (
    REGION_LEVEL,
    REGION_MIN_POINTS,
    REGION_SHARE,
    REGION_VERDICTS,
    decide_over,
    points_needed,
    region_row,
    region_verdict,
    share_bound,
)
from sim.studies.agnard.decide import without_snooping
from sim.studies.agnard.leads import HOW

K = REGION_MIN_POINTS


def test_the_rule_is_29_points_for_a_share_of_10_percent_at_95():
    assert (REGION_SHARE, REGION_LEVEL, K) == (0.10, 0.95, 29)
    assert share_bound(29) <= 0.10 < share_bound(28)  # 9.82 % and 10.15 %
    assert "inconclusive" in REGION_VERDICTS and "inconclusive" in VERDICTS


@pytest.mark.parametrize("k", [1, 2, 5, 16, 28, 29, 35, 100, 2261])
@pytest.mark.parametrize("level", [0.95, 0.99])
def test_the_bound_is_the_exact_clopper_pearson_bound_of_none_in_k(k, level):
    b = share_bound(k, level)
    # the one-sided upper bound for 0 of k: the level quantile of Beta(1, k)
    assert b == pytest.approx(stats.beta.ppf(level, 1, k), rel=1e-9)
    # at that share, no disagreeing point among k is exactly as likely as 1 - level
    assert stats.binom.pmf(0, k, b) == pytest.approx(1 - level, rel=1e-9)
    if k == 2:  # the brief's agnard_block_104: 2 points bound it only under 78 %
        assert round(100 * b) == {0.95: 78, 0.99: 90}[level]


def test_the_bound_of_an_unsampled_region_is_the_whole_region():
    assert share_bound(0) == 1.0 and share_bound(-3) == 1.0


@pytest.mark.parametrize("share", [0.5, 0.3, 0.2, 0.1, 0.05, 0.01])
@pytest.mark.parametrize("level", [0.9, 0.95, 0.99])
def test_points_needed_is_the_fewest_points_whose_bound_is_small_enough(share, level):
    # brute force with scipy: the first k at which k agreeing points are rarer than 1 - level
    # for a region where the share `share` disagrees
    k = next(k for k in range(1, 10_000) if stats.binom.pmf(0, k, share) <= 1 - level + 1e-12)
    assert points_needed(share, level) == k
    assert share_bound(k, level) <= share < share_bound(k - 1, level) if k > 1 else True


@pytest.mark.parametrize("k", [1, 5, 29])
def test_points_needed_counts_a_bound_equal_to_the_share_as_enough(k):
    assert points_needed(share_bound(k), 0.95) == k  # "at most" the share, not "under"
    assert points_needed(0.96, 0.95) == 1  # one point already bounds it under 95 %


@pytest.mark.parametrize("share, level", [(0.0, 0.95), (1.0, 0.95), (0.1, 0.0), (0.1, 1.0)])
def test_points_needed_refuses_a_share_or_level_outside_0_1(share, level):
    with pytest.raises(ValueError, match="0 < share < 1"):
        points_needed(share, level)


@pytest.mark.parametrize(
    "counts, verdict",
    [
        ((K - 1, K - 1, 0), "inconclusive"),
        ((K, K, 0), "holds"),
        ((K + 1, K + 1, 0), "holds"),
        ((K - 1, 0, K - 1), "inconclusive"),
        ((K, 0, K), "fails"),
        ((K + 1, 0, K + 1), "fails"),
        ((1, 1, 0), "inconclusive"),
        ((2, 0, 2), "inconclusive"),
        ((2, 1, 1), "depends"),  # a point on each side proves it: no minimum
        ((3, 1, 1), "depends"),
        ((3, 1, 0), "holds or undecided"),  # not a region-wide decision: unchanged
        ((3, 0, 1), "fails or undecided"),
        ((K - 1, 0, 0), "undecidable"),
        ((0, 0, 0), "undecidable"),
    ],
)
def test_region_verdict_on_both_sides_of_the_minimum(counts, verdict):
    assert region_verdict(*counts) == verdict


def test_region_verdict_takes_the_minimum_it_is_given():
    assert region_verdict(5, 5, 0, min_points=5) == "holds"
    assert region_verdict(4, 0, 4, min_points=5) == "inconclusive"
    assert region_verdict(5, 0, 5, min_points=5) == "fails"


# ------------------------------------------------------------------ a tiny region, end to end
A = Input("a_mm", 0.0, 10.0)
ANY = Statement("a_any", (0.0, 0.0), "lower", decimals=0)  # a >= -0.5: every point


def _region(n: int):
    """A one-input region of ``n`` accepted points (nothing constrains a) with the exact
    evidence ``a`` for a prediction "a >= ref" (id ``p``)."""
    r = explore([A], [ANY], lambda x: {"a_any": x["a_mm"], "p": x["a_mm"]},
                np.random.default_rng(5), n=n, rounds=0)  # fmt: skip
    assert int(r.accepted.sum()) == n
    return r


def _book(ref: float) -> ClaimBook:
    spec = {"source": "s", "paper": "p", "form": "lower", "ref": ref, "tol": 0.0}
    return ClaimBook(
        [{**spec, "id": "p", "kind": "prediction"}, {**spec, "id": "c", "kind": "paper-check"}],
        [],
    )


TOO_FEW = (
    "region sampled at 16 points, {} at all of them: a region verdict needs 29 (bounds the "
    "share where it {} under 10 %, 95 %)"
)


def test_a_prediction_holding_at_16_points_is_inconclusive_and_says_why():
    r = _region(16)
    v = decide_over(r, Statement("p", (-1.0, -1.0), "lower"), r.x["a_mm"])
    assert (v.verdict, v.n_points, v.n_holds, v.n_fails) == ("inconclusive", 16, 16, 0)
    assert v.note == TOO_FEW.format("holds", "fails")
    assert v.text == f"inconclusive ({v.note})"
    (row,) = region_rows(_book(-1.0), r, ["p"])
    assert (row["outcome"], row["verdict"], row["holds"]) == ("inconclusive",) * 2 + (None,)
    assert row["note"] == "inconclusive: " + TOO_FEW.format("holds", "fails")
    assert row["interval"] == "region" and "points of the region" not in row["note"]


def test_a_paper_check_failing_at_16_points_is_inconclusive_not_an_erratum():
    r = _region(16)
    v = decide_over(r, Statement("c", (11.0, 11.0), "lower"), r.x["a_mm"])
    assert (v.verdict, v.n_fails) == ("inconclusive", 16)
    assert v.note == TOO_FEW.format("fails", "holds")
    row = region_row(_book(11.0), "c", v, r.x["a_mm"])
    assert (row["outcome"], row["verdict"], row["holds"]) == ("inconclusive",) * 2 + (None,)


def test_a_prediction_holding_at_32_points_holds_and_states_its_bound():
    r = _region(32)
    (row,) = region_rows(_book(-1.0), r, ["p"])
    assert (row["outcome"], row["verdict"], row["holds"]) == ("holds", "holds", True)
    assert row["note"] == "holds at all 32 points of the region (fails on under 8.9 % of it, 95 %)"
    v = decide_over(r, Statement("c", (11.0, 11.0), "lower"), r.x["a_mm"])
    row = region_row(_book(11.0), "c", v, r.x["a_mm"])
    assert (row["outcome"], row["verdict"], row["holds"]) == ("fails", "erratum", False)
    assert row["note"] == "fails at all 32 points of the region (holds on under 8.9 % of it, 95 %)"


def test_a_prediction_that_depends_at_16_points_still_depends():
    r = _region(16)
    (row,) = region_rows(_book(5.0), r, ["p"])
    assert row["outcome"] == "depends" and row["note"].startswith("holds for a_mm ")


# ------------------------------------------------------------ agnard's undecidable rejection row
def test_an_undecidable_rejection_row_keeps_no_region_verdict_in_its_note():
    """agnard_block_104 (snoop.max_reject = 0): the digital-rejection row is undecidable by
    construction; its note keeps how it was decided, not "holds at all 2 points"."""
    how = HOW[2:] + " 2 explored input vectors"
    for lead in ("holds at all 40 points of the region (fails on under 7.2 % of it, 95 %)",
                 "inconclusive: " + TOO_FEW.format("holds", "fails")):  # fmt: skip
        row = {"claim": "agnard.pass_rejections.digital", "kind": "prediction",
               "outcome": "holds", "verdict": "holds", "holds": True, "note": f"{lead}; {how}"}  # fmt: skip
        (out,) = without_snooping({"snoop.max_reject": 0}, [row])
        assert (out["outcome"], out["verdict"], out["holds"]) == ("undecidable",) * 2 + (None,)
        assert out["note"].startswith("undecidable: snoop.max_reject = 0")
        assert out["note"].endswith("; " + how)
        assert "at all" not in out["note"] and "inconclusive" not in out["note"]
    assert without_snooping({"snoop.max_reject": 3}, [row]) == [row]
