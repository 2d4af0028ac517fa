"""The region verdict's label (sim.claims.region.region_verdict): a prediction that holds
nowhere in the consistent region but fails somewhere reads "fails or undecided", never
"depends"; its mirror reads "holds or undecided"; "depends" needs both sides. Checked on the
counts and on a synthetic region whose answer is analytic (a + b = 10 +- 0.5, a <= 4.5, so
b spans [5, 10]) with interval evidence [b - 1, b + 1] for the prediction "b >= t"."""

import numpy as np
import pytest

from sim.claims.book import VERDICTS, ClaimBook
from sim.claims.inference import Input, Statement, explore
from sim.claims.region import REGION_VERDICTS, decide_over, region_row, region_verdict

A = Input("a_mm", 0.0, 10.0)
B = Input("b_mm", 0.0, 10.0)
SUM = Statement("sum", (10.0, 10.0), "value", decimals=0)  # a + b in [9.5, 10.5]
A_UP = Statement("a_up", (4.0, 4.0), "upper", decimals=0)  # a <= 4.5


@pytest.mark.parametrize(
    "counts, verdict",
    [
        ((40, 40, 0), "holds"),  # 29 points or more (sim.claims.region.REGION_MIN_POINTS)
        ((40, 0, 40), "fails"),
        ((10, 10, 0), "inconclusive"),  # too few points (tests/test_region_rule.py)
        ((10, 0, 10), "inconclusive"),
        ((10, 9, 1), "depends"),
        ((10, 1, 9), "depends"),
        ((10, 1, 1), "depends"),  # both sides, undecided between
        ((10, 9, 0), "holds or undecided"),
        ((10, 1, 0), "holds or undecided"),
        ((10, 0, 9), "fails or undecided"),
        ((10, 0, 1), "fails or undecided"),
        ((10, 0, 0), "undecidable"),
        ((0, 0, 0), "undecidable"),  # an empty region
    ],
)
def test_region_verdict_names_the_set_of_point_outcomes(counts, verdict):
    assert region_verdict(*counts) == verdict
    assert verdict in REGION_VERDICTS and verdict in VERDICTS


def _region():
    def model(x):
        return {"sum": x["a_mm"] + x["b_mm"], "a_up": x["a_mm"]}

    return explore([A, B], [SUM, A_UP], model, np.random.default_rng(3), n=512, rounds=2)


def _evidence(r):
    b = r.x["b_mm"]
    return {"value": b, "low": b - 1.0, "high": b + 1.0}


@pytest.mark.parametrize(
    "t, verdict",
    [
        (3.9, "holds"),  # b - 1 >= 4 >= t at every region point
        (5.5, "holds or undecided"),  # holds for b >= 6.5; b + 1 >= 6 > t: fails nowhere
        (7.5, "depends"),  # holds for b >= 8.5, fails for b < 6.5
        (10.5, "fails or undecided"),  # holds needs b >= 11.5: nowhere; fails for b < 9.5
        (11.1, "fails"),  # b + 1 <= 11 < t everywhere
    ],
)
def test_decide_over_on_both_sides_of_each_label(t, verdict):
    r = _region()
    v = decide_over(r, Statement("b", (t, t), "lower"), _evidence(r))
    assert v.verdict == verdict, v
    b = r.x["b_mm"][r.accepted]
    # the counts are the analytic conditions at the accepted points
    assert v.n_holds == int(np.sum(b - 1 >= t)) and v.n_fails == int(np.sum(b + 1 < t))
    if verdict == "fails or undecided":
        assert v.holds_where == "nowhere" and "b_mm" in v.fails_where
        assert v.text.startswith("fails or undecided: holds nowhere")
    if verdict == "holds or undecided":
        assert v.fails_where == "nowhere" and "b_mm" in v.holds_where


def test_row_of_a_prediction_that_holds_nowhere():
    """Its claims row reads 'fails or undecided' (holds null); a paper check with that
    verdict is not an erratum (the recomputation does not fail everywhere)."""
    spec = {"source": "s", "paper": "p", "form": "lower", "ref": 10.5, "tol": 0.0}
    book = ClaimBook(
        [{**spec, "id": "b", "kind": "prediction"}, {**spec, "id": "c", "kind": "paper-check"}],
        [],
    )
    r = _region()
    st = Statement("b", (10.5, 10.5), "lower")
    v = decide_over(r, st, _evidence(r))
    vals = r.x["b_mm"][r.accepted]
    row = region_row(book, "b", v, vals)
    assert (row["outcome"], row["verdict"], row["holds"]) == ("fails or undecided",) * 2 + (None,)
    assert row["note"].startswith("holds nowhere in the region; fails for a_mm")
    assert "b_mm" in row["note"] and "undecided at the rest" in row["note"]
    row = region_row(book, "c", v, vals)
    assert row["verdict"] == "fails or undecided" and row["holds"] is None
