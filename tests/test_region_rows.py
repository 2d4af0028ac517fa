"""The claims rows and tables of predictions decided over a consistent region
(sim.claims.region): every column a report reads, for every region verdict and kind, checked
against values written out by hand (issue 28: the surviving mutants of region_row,
decide_over, evidence_of_row, region_table, holds_together and inputs_table)."""

import math

import numpy as np
import pytest
from test_inference import A_UP, SUM, A, B  # the synthetic problem of the inference tests

from sim.claims.book import ClaimBook
from sim.claims.inference import Statement, explore
from sim.claims.region import (
    INPUT_COLUMNS,
    RegionVerdict,
    decide_over,
    evidence_of_row,
    holds_together,
    inputs_table,
    region_row,
    region_table,
)

SPEC = {"source": "s", "paper": "p", "form": "lower", "ref": 5.0, "tol": 0.0}


def book():
    kinds = {"pred": "prediction", "check": "paper-check", "inp": "input", "self": "self-check"}
    return ClaimBook([{**SPEC, "id": c, "kind": k} for c, k in kinds.items()], [], "<test>")


def model(x):
    a, b = x["a_mm"], x["b_mm"]
    return {
        "sum": a + b,
        "a_up": a,
        "zero": np.zeros_like(a),
        "b": {"value": b, "low": b - 1.0, "high": b + 1.0},
        "b_int": np.round(b).astype(int),
    }


def region(*statements, n=256, rounds=1):
    st = statements or (SUM, A_UP)
    return explore([A, B], list(st), model, np.random.default_rng(5), n=n, rounds=rounds)


# --------------------------------------------------------------------------- evidence_of_row
def test_evidence_of_a_row_is_its_interval_and_a_one_plate_p():
    row = {"value": 2.0, "ci_low": 1.5, "ci_high": 2.5, "p_plate": 0.25, "form": "one-plate"}
    assert evidence_of_row(row) == {"value": 2.0, "low": 1.5, "high": 2.5, "p": 0.25}
    # p belongs to one-plate rows only (a value row's p_plate is NaN and must not decide)
    assert evidence_of_row({**row, "form": "value"}) == {
        "value": 2.0,
        "low": 1.5,
        "high": 2.5,
        "p": None,
    }


# --------------------------------------------------------------------------- region_row
RV = {
    "holds": RegionVerdict("x", "holds", 40, 40, 0, "a_mm 0-4", "nowhere", ""),
    "fails": RegionVerdict("x", "fails", 40, 0, 40, "nowhere", "a_mm 0-4", ""),
    "depends": RegionVerdict("x", "depends", 7, 3, 2, "a_mm 0-1", "a_mm 3-4", "N"),
    "holds or undecided": RegionVerdict(
        "x", "holds or undecided", 7, 3, 0, "a_mm 0-1", "nowhere", "N"
    ),  # fmt: skip
    "fails or undecided": RegionVerdict(
        "x", "fails or undecided", 7, 0, 2, "nowhere", "a_mm 3-4", "N"
    ),  # fmt: skip
    "undecidable": RegionVerdict("x", "undecidable", 7, 0, 0, "nowhere", "nowhere", "D"),
}
WHERE = {
    "holds": "holds at all 40 points of the region (fails on under 7.2 % of it, 95 %)",
    "fails": "fails at all 40 points of the region (holds on under 7.2 % of it, 95 %)",
    "depends": "holds for a_mm 0-1; fails for a_mm 3-4 (N)",
    "holds or undecided": "holds for a_mm 0-1, fails nowhere in the region, undecided at the rest (N)",
    "fails or undecided": "holds nowhere in the region; fails for a_mm 3-4, undecided at the rest (N)",
    "undecidable": "undecidable: D",
}
HOLDS_COL = {"holds": True, "fails": False}


@pytest.mark.parametrize("verdict", list(RV))
def test_region_row_of_a_prediction(verdict):
    row = region_row(book(), "pred", RV[verdict], [4.0, 2.5, np.nan, 3.0])
    # the value and interval are the smallest and largest finite value over the region
    assert (row["value"], row["ci_low"], row["ci_high"], row["value_high"]) == (2.5, 2.5, 4.0, 4.0)
    assert row["interval"] == "region" and row["claim"] == "pred" and row["kind"] == "prediction"
    assert row["outcome"] == row["verdict"] == verdict
    assert row["holds"] is HOLDS_COL.get(verdict)
    assert row["note"] == WHERE[verdict]


@pytest.mark.parametrize("verdict", list(RV))
def test_region_row_of_a_paper_check_is_an_erratum_where_it_fails_everywhere(verdict):
    row = region_row(book(), "check", RV[verdict], [3.0], note="recomputed")
    assert row["outcome"] == verdict
    assert row["verdict"] == ("erratum" if verdict == "fails" else verdict)
    assert row["holds"] is HOLDS_COL.get(verdict)
    assert row["note"] == WHERE[verdict] + "; recomputed"


@pytest.mark.parametrize("cid, verdict", [("inp", "input"), ("self", "self-check")])
def test_region_row_of_other_kinds_keeps_the_kind_as_verdict(cid, verdict):
    for v in ("fails", "holds", "depends"):
        row = region_row(book(), cid, RV[v], [6.0, 7.0])
        assert (row["outcome"], row["verdict"]) == (v, verdict)
        assert row["holds"] is HOLDS_COL.get(v)  # the region's answer, as for a prediction


def test_region_row_skips_points_without_a_value():
    row = region_row(book(), "pred", RV["holds"], [3, None, 1.5])
    assert (row["value"], row["value_high"]) == (1.5, 3.0)


def test_region_row_of_an_empty_region_has_no_value():
    row = region_row(book(), "pred", RV["undecidable"], [np.nan, np.inf])
    for k in ("value", "value_high", "ci_low", "ci_high"):
        assert math.isnan(row[k]), k
    assert (row["interval"], row["outcome"], row["verdict"]) == ("region",) + ("undecidable",) * 2
    assert row["holds"] is None and row["note"] == "undecidable: D"
    row = region_row(book(), "check", RV["undecidable"], [], note="why")
    assert math.isnan(row["value"]) and row["note"] == "undecidable: D; why"


# --------------------------------------------------------------------------- decide_over
def test_decide_over_an_empty_region_names_the_conflicts():
    big = Statement("zero", (5.0, 5.0), "value")  # the model gives 0: contradicted alone
    neg = Statement("a_up", (-3.0, -3.0), "upper")  # a <= -3: contradicted alone
    r = region(big, neg, rounds=0)
    assert r.empty
    v = decide_over(r, Statement("b", (5.0, 5.0), "lower"))
    assert v == RegionVerdict(
        "b", "undecidable", 0, 0, 0, "nowhere", "nowhere",
        "none of the 256 explored inputs is consistent with the printed statements"
        " (conflicting: zero; a_up)",
    )  # fmt: skip
    # a minimal set of two statements that cannot hold together: "a + b" names both
    lo = Statement("a_up", (6.0, 6.0), "lower")  # a >= 6 with a <= 4.5 below
    r = region(A_UP, lo, rounds=0)
    assert decide_over(r, Statement("b", (5.0, 5.0), "lower")).note == (
        "none of the 256 explored inputs is consistent with the printed statements"
        " (conflicting: a_up + a_up)"
    )


@pytest.mark.parametrize(
    "t, verdict",
    [(3.9, "holds"), (5.5, "holds or undecided"), (7.5, "depends"),
     (10.5, "fails or undecided"), (11.1, "fails")],
)  # fmt: skip
def test_decide_over_says_where_and_how_often(t, verdict):
    r = region()
    spec = Statement("b", (t, t), "lower", decide="a finer b")
    v = decide_over(r, spec)
    b = r.x["b_mm"]
    h, f = r.accepted & (b - 1 >= t), r.accepted & (b + 1 < t)
    n, nh, nf = int(r.accepted.sum()), int(h.sum()), int(f.sum())
    assert (v.id, v.verdict, v.n_points, v.n_holds, v.n_fails) == ("b", verdict, n, nh, nf)
    assert v.holds_where == (r.describe(h) if nh else "nowhere")
    assert v.fails_where == (r.describe(f) if nf else "nowhere")
    if verdict in ("holds", "fails"):
        assert v.note == ""
    else:
        assert v.note == (
            f"holds at {nh} of {n} region points, fails at {nf}, undecided at {n - nh - nf}"
        )
        assert n - nh - nf > 0


def test_an_undecidable_prediction_says_what_would_decide_it():
    r = region()
    wide = {"value": r.x["b_mm"], "low": r.x["b_mm"] - 20, "high": r.x["b_mm"] + 20}
    spec = Statement("b", (5.0, 5.0), "lower", decide="a finer b")
    assert decide_over(r, spec, wide).note == "a finer b"
    assert decide_over(r, Statement("b", (5.0, 5.0), "lower"), wide).note == (
        "no input of the region decides it"
    )


# --------------------------------------------------------------------------- tables
def test_region_table_columns():
    r = region()
    acc = r.accepted
    pred = Statement("b", (7.0, 7.0), "lower")
    cols = region_table(r, [pred], ["b", "b_int", "sum"])
    assert cols["a_mm"] == r.x["a_mm"][acc].tolist()
    assert cols["confirmed"] == r.confirmed[acc].tolist()
    b = r.x["b_mm"][acc]
    assert (
        cols["b"]
        == np.where(b - 1 >= 7, "holds", np.where(b + 1 < 7, "fails", "undecided")).tolist()
    )
    assert cols["b__value"] == b.tolist()  # from a dict's value
    assert cols["sum__value"] == (r.x["a_mm"] + r.x["b_mm"])[acc].tolist()
    # value columns are floats whatever the model returns (one Parquet type per column)
    assert cols["b_int__value"] == np.round(b).tolist()
    assert all(type(x) is float for x in cols["b_int__value"])


def test_holds_together_and_the_inputs_table():
    r = region()
    p1 = Statement("b", (6.0, 6.0), "lower")  # holds where b >= 7
    p2 = Statement("sum", (10.0, 10.0), "upper", decimals=0)  # a + b <= 10.5: everywhere
    b = r.x["b_mm"]
    assert np.array_equal(holds_together(r, [p1, p2]), r.accepted & (b - 1 >= 6))
    assert np.array_equal(holds_together(r, [p2]), r.accepted)
    assert np.array_equal(holds_together(r, []), r.accepted)
    t = inputs_table(r, [p1, p2])
    together = r.accepted & (b - 1 >= 6)
    assert list(t) == list(INPUT_COLUMNS) and t["input"] == ["a_mm", "b_mm"]
    assert t["together_low"][1] == b[together].min() and t["together_high"][1] == b[together].max()
    assert t["region_low"][1] == b[r.accepted].min()
    assert t["n_points"] == [r.n] * 2 and t["n_region"] == [int(r.accepted.sum())] * 2
    assert t["n_together"] == [int(together.sum())] * 2
