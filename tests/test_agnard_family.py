"""The Holm family of one-plate rows (``sim.claims.family``), as Agnard's joint X, Y rows use
it, and the XY columns as paper-checks of the quadrature of X and Y. No simulation: the
rule on hand-made p values and statuses, and on a small synthetic region."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sim.claims.book import ClaimBook
from sim.claims.family import (
    family_evidence,
    family_outcomes,
    family_over,
    family_row,
    family_status,
    holm,
    mc_p,
)
from sim.claims.inference import FAILS, HOLDS, UNDECIDED, Input, Region, Statement, status
from sim.studies.agnard.claims import JOINT, MEMBERS, load_book, quadrature_check


def test_holm_is_the_step_down_rule():
    adj = holm([0.01, 0.04, 0.03, 0.005])
    # sorted 0.005, 0.01, 0.03, 0.04 times 4, 3, 2, 1, then the running maximum
    assert np.allclose(adj, [0.03, 0.06, 0.06, 0.02])
    assert np.all(holm([0.9, 0.8]) == 1.0)


def test_family_fails_holds_and_stays_undecided():
    p = np.array(
        [
            [0.352, 0.012],  # Agnard's 21-control check X, Y: Holm 0.024 -> fails
            [0.03, 0.6],  # fails alone (0.03), not after the correction (0.06)
            [0.75, 0.9],  # neither contradicted, members undecided -> undecided
            [0.5, 0.4],  # neither contradicted, both members hold -> holds
        ]
    )
    members = np.array([[UNDECIDED, FAILS], [FAILS, HOLDS], [UNDECIDED, UNDECIDED], [HOLDS, HOLDS]])
    hp, st = family_status(p, members)
    assert np.allclose(hp, [0.024, 0.06, 1.0, 0.8])
    assert list(st) == [FAILS, UNDECIDED, UNDECIDED, HOLDS]
    with pytest.raises(ValueError, match="shape"):
        family_status(p, members[:, :1])


def _book() -> ClaimBook:
    one = dict(source="s", kind="prediction", form="one-plate", decimals=0, tol=1.0)
    return ClaimBook(
        [
            dict(id="t.x", paper="X 14", ref=14, **one),
            dict(id="t.y", paper="Y 21", ref=21, **one),
            dict(
                id="t.xy",
                source="s",
                paper="X and Y",
                kind="prediction",
                form="lower",
                ref=0.05,
                tol=0,
                headline=True,
            ),
        ],  # fmt: skip
        [],
    )


N = 500  # Agnard's main blocks: the members' plug-in p are 2 k / 500


@pytest.mark.parametrize(
    ("px", "py", "ox", "oy", "verdict", "value"),
    [  # Y's 3 of 500 blocks: Monte-Carlo p 2 * 4 / 501, Holm twice that (plug-in: 0.024)
        (0.352, 0.012, "inconclusive", "fails", "fails", 16 / 501),
        (0.4, 0.7, "inconclusive", "inconclusive", "inconclusive", 404 / 501),
        (0.4, 0.7, "holds", "holds", "holds", 404 / 501),
    ],
)
def test_family_row_at_the_configured_inputs(px, py, ox, oy, verdict, value):
    members = [
        {"claim": "t.x", "p_plate": px, "outcome": ox},
        {"claim": "t.y", "p_plate": py, "outcome": oy},
    ]
    row = family_row(_book(), "t.xy", members, n=N)
    assert math.isclose(row["value"], value)
    assert row["outcome"] == row["verdict"] == verdict
    assert row["holds"] == {"holds": True, "fails": False}.get(verdict)
    assert "Holm-adjusted" in row["note"]


def _region(px, py, spread_x) -> Region:
    """Three explored points, every one accepted (no constraints), the members' one-plate
    evidence given per point: p and the 95 % spread of one plate."""
    n = len(px)
    sx, sy = np.asarray(spread_x, float), np.full(n, 2.0)
    return Region(
        [Input("a_1", 0.0, 1.0)],
        [],
        {"a_1": np.linspace(0, 1, n)},
        np.zeros((n, 0), np.int8),
        0.95,
        {"a_1": (0.5, 0.5)},
        {
            "t.x": {"value": np.full(n, 14.0), "low": 14 - sx, "high": 14 + sx, "p": np.array(px)},
            "t.y": {"value": np.full(n, 21.0), "low": 21 - sy, "high": 21 + sy, "p": np.array(py)},
        },
    )


@pytest.mark.parametrize(
    ("px", "py", "spread_x", "verdict"),
    [
        ([0.3, 0.5, 0.9], [0.4, 0.8, 0.6], [2.0, 2.0, 2.0], "undecidable"),  # wide spreads
        # fails at all 3 points: too few for a region verdict (29, sim.claims.region)
        ([0.01, 0.02, 0.001], [0.5, 0.5, 0.5], [2.0, 2.0, 2.0], "inconclusive"),
        ([0.01, 0.5, 0.5], [0.5, 0.5, 0.5], [2.0, 2.0, 2.0], "fails or undecided"),
    ],
)
def test_family_over_a_region(px, py, spread_x, verdict):
    row = family_over(_book(), _region(px, py, spread_x), "t.xy", ["t.x", "t.y"], note="n.b.", n=N)
    assert row["verdict"] == verdict and row["interval"] == "region"
    assert "Holm's step-down correction); n.b." in row["note"]
    hp = [holm(mc_p([a, b], N)).min() for a, b in zip(px, py)]
    assert math.isclose(row["value"], min(hp)) and math.isclose(row["value_high"], max(hp))
    assert (
        "one test of t.x, t.y per point (the Monte-Carlo p 2(k+1)/(n+1) of 500 simulated "
        "plates each, Holm's step-down correction)"
    ) in row["note"]
    why = {  # what the reader is told besides the verdict
        "undecidable": "no point of the region decides it: the Holm p is 0.61-1.00 (never "
        "below 0.05), and at every point some member's one-block spread reaches outside its "
        "zone (the block neither confirms nor contradicts it)",
        "inconclusive": "inconclusive: region sampled at 3 points, fails at all of them: a "
        "region verdict needs 29",
        "fails or undecided": "holds at 0 of 3 region points, fails at 1, undecided at 2",
    }[verdict]
    assert why in row["note"]
    if verdict == "inconclusive":
        assert "undecided at" not in row["note"] and "decides it" not in row["note"]


def test_family_over_an_empty_region_names_the_conflict():
    reg = _region([0.5, 0.5], [0.5, 0.5], [0.1, 0.1])
    empty = Region(
        [Input("a_1", 0.0, 1.0)],
        [Statement("c", (0.0, 0.0), form="upper")],
        {"a_1": np.array([0.2, 0.8])},
        np.full((2, 1), FAILS, np.int8),
        0.95,
        {"a_1": (0.5, 0.5)},
        reg.outputs,
    )
    row = family_over(_book(), empty, "t.xy", ["t.x", "t.y"], n=N)
    assert row["verdict"] == "undecidable"
    assert (
        "none of the 2 explored inputs is consistent with the printed statements (conflicting: c)"
        in (row["note"])
    )


def test_family_row_names_every_member_with_its_p():
    members = [
        {"claim": "t.x", "p_plate": 0.4, "outcome": "holds"},
        {"claim": "t.y", "p_plate": 0.03, "outcome": "fails"},
    ]
    row = family_row(_book(), "t.xy", members, note="the block", n=N)
    assert row["note"] == (  # Monte-Carlo p 202 / 501 and 17 / 501
        "one test of 2 one-plate rows over 500 simulated plates each (the Monte-Carlo p "
        "2(k+1)/(n+1), Holm's step-down correction): "
        "t.x: p 0.400, Monte-Carlo p 0.403 (holds), Holm-adjusted 0.403; "
        "t.y: p 0.030, Monte-Carlo p 0.034 (fails), Holm-adjusted 0.068; the block"
    )


def test_the_xy_columns_are_paper_checks_of_the_quadrature():
    """Every XY row is a paper-check whose tol is the half-width of sqrt(X^2 + Y^2) over the
    printed rounding of X and Y (to the 0.01 cm the book prints), and the paper's own
    numbers pass it; the headline of each check-point block is its joint X, Y row."""
    book = load_book()
    xy = [c for c in book.specs if c.endswith("_xy_cm") and c.startswith("agnard.control_")]
    assert len(xy) == 4
    for cid in xy:
        s = book.spec(cid)
        x, y = (book.spec(cid.replace("_xy_", f"_{c}_"))["ref"] for c in ("x", "y"))
        half = max(math.hypot(x + 0.5, y + 0.5) - math.hypot(x, y),
                   math.hypot(x, y) - math.hypot(x - 0.5, y - 0.5))  # fmt: skip
        assert s["kind"] == "paper-check" and not s.get("headline")
        assert abs(s["tol"] - half) <= 0.01, cid
        v = quadrature_check(book, cid).value
        assert abs(v - s["ref"]) <= 0.5 + s["tol"], cid
    for j in JOINT.values():
        assert book.spec(j)["headline"] and book.spec(j)["form"] == "lower"
        assert all(book.spec(m)["form"] == "one-plate" for m in MEMBERS[j])


def test_family_evidence_gives_a_region_the_family_rule():
    """Wolf's families reach the region through evidence (``family_evidence``): the region's
    status of a lower bound 0.05 on the Holm p must be ``family_status`` at every point -- both
    sides of 0.05 (0.049 and 0.05 exactly, in binary), a member short of holding, a NaN p."""
    p = np.array([[0.0245, 0.9], [0.025, 0.9], [0.3, 0.04], [0.3, 0.6], [0.3, 0.6], [np.nan, 0.6]])
    member = np.array(
        [[HOLDS, HOLDS], [HOLDS, HOLDS], [HOLDS, FAILS], [HOLDS, UNDECIDED], [HOLDS, HOLDS],
         [HOLDS, HOLDS]]
    )  # fmt: skip
    bound = Statement("family", (0.05, 0.05), form="lower")
    got = status(bound, family_evidence(p, member), len(p))
    assert got.tolist() == family_status(p, member)[1].tolist()
    assert got.tolist() == [FAILS, HOLDS, UNDECIDED, UNDECIDED, HOLDS, UNDECIDED]
    ev = family_evidence(p, member)
    assert sorted(ev) == ["high", "low", "value"] and ev["low"].dtype == float
    assert np.array_equal(ev["value"], ev["high"], equal_nan=True)
    hp, st = family_status(p, member)
    assert hp.dtype == float and st.dtype == np.int8 and np.isnan(hp[-1])


@pytest.mark.parametrize("n", [1, 20, 500])
def test_mc_p_is_the_monte_carlo_tests_p(n):
    """2 (k + 1) / (n + 1) from the plug-in 2 k / n: k = 0 (never 0), k = 1/2 (a plate on the
    edge), k = 1, and 1 where it would exceed 1 (k >= (n - 1) / 2) but not below."""
    k = np.array([0.0, 0.5, 1.0])
    want = np.minimum(1.0, 2 * (k + 1) / (n + 1))
    assert mc_p(2 * k / n, n) == pytest.approx(want, rel=1e-12)
    assert mc_p(np.array([1.0, (n - 1) / n]), n).tolist() == pytest.approx([1.0, 1.0])
    if n > 3:
        assert mc_p((n - 3) / n, n) == pytest.approx((n - 1) / (n + 1), rel=1e-12)
    got = mc_p(np.zeros((2, 3)), n)  # arrays in, arrays out
    assert got.shape == (2, 3) and got.dtype == float


@pytest.mark.parametrize("n", [0, -1, 0.5, float("nan")])
def test_mc_p_refuses_fewer_than_one_plate(n):
    with pytest.raises(ValueError, match="simulated plates n must be >= 1"):
        mc_p(np.array([0.1]), n)


@pytest.mark.parametrize(("k", "st"), [(3, FAILS), (4, UNDECIDED)])
def test_family_status_takes_the_monte_carlo_p_of_n_plates(k, st):
    """At n = 399 a family of two fails at k = 3 (Holm 2 * 2 * 4 / 400 = 0.04) and not at
    k = 4 (0.05 exactly), where the plug-in 2 * 2 * 4 / 399 = 0.040 would fail it."""
    p = np.array([[2 * k / 399, 0.9]])
    member = np.array([[FAILS, UNDECIDED]])
    hp, got = family_status(p, member, 399)
    assert hp[0] == pytest.approx(4 * (k + 1) / 400, rel=1e-12) and got.tolist() == [st]
    assert family_status(p, member)[0][0] == pytest.approx(4 * k / 399, rel=1e-12)
    assert family_status(p, member)[1].tolist() == [FAILS]
    ev = family_evidence(p, member, 399)
    assert ev["value"][0] == pytest.approx(hp[0]) and ev["high"][0] == pytest.approx(hp[0])


def test_family_outcomes_over_a_region_use_n():
    reg = _region([6 / 399, 0.5], [0.5, 0.5], [2.0, 2.0])  # X at k = 3, then k = 99.75
    hp, st = family_outcomes(_book(), reg, ["t.x", "t.y"], n=399)
    assert hp == pytest.approx([0.04, 1.0]) and st.tolist() == [FAILS, UNDECIDED]
    hp1, _ = family_outcomes(_book(), reg, ["t.x", "t.y"], n=1)
    assert hp1 == pytest.approx([1.0, 1.0])
