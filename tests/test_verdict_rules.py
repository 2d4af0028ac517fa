"""Every verdict rule of sim.claims.book on both sides of each threshold, at the threshold and
with intervals that straddle a zone edge (issue 28). The numbers are exact in binary (halves,
quarters) so that "at the threshold" means equal, not equal to rounding.
"""

import math
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from sim.claims import book as bk
from sim.claims import rules
from sim.claims.book import ClaimBook, decide, write_claims
from sim.claims.inference import FAILS, HOLDS, UNDECIDED, Statement, status
from sim.claims.rules import P_FAIL
from sim.mc.storage import read_provenance

ROOT = Path(__file__).resolve().parent.parent
BELOW = np.nextafter(1.25, -np.inf)  # the largest float below the zone's lower edge
ABOVE = np.nextafter(2.75, np.inf)  # the smallest float above its upper edge
ZONE = (1.25, 2.75)


def one(kind="prediction", **spec):
    base = {"id": "c", "source": "s", "paper": "p", "kind": kind}
    return ClaimBook([{**base, **spec}], [], "<test>")


# --------------------------------------------------------------------------- value, share, count
@pytest.mark.parametrize("form", ["value", "share", "count"])
@pytest.mark.parametrize(
    "interval, outcome",
    [
        ((1.5, 2.5), "holds"),  # inside
        ((1.25, 2.75), "holds"),  # the zone itself: both edges touch, still inside
        ((1.25, 1.25), "holds"),  # a point on the lower edge
        ((2.75, 2.75), "holds"),  # a point on the upper edge
        ((1.0, 1.5), "inconclusive"),  # straddles the lower edge
        ((2.5, 3.0), "inconclusive"),  # straddles the upper edge
        ((1.0, 3.0), "inconclusive"),  # covers the zone and more
        ((1.0, 1.25), "inconclusive"),  # ends on the lower edge: meets the zone
        ((2.75, 3.0), "inconclusive"),  # starts on the upper edge
        ((1.0, BELOW), "fails"),  # ends just below the zone
        ((ABOVE, 3.0), "fails"),  # starts just above it
        ((0.0, 0.5), "fails"),
        ((BELOW, BELOW), "fails"),  # a point just outside
        ((ABOVE, ABOVE), "fails"),
    ],
)
def test_value_rule_on_both_sides_and_at_each_edge(form, interval, outcome):
    assert decide(form, interval, ZONE) == outcome


def test_the_zone_is_the_printed_rounding_widened_by_tol():
    # 2 printed with 0 decimals stands for [1.5, 2.5]; tol 0.25 widens that to [1.25, 2.75]
    r = one(form="value", ref=2, decimals=0, tol=0.25).score("c", 2.0, (1.25, 2.75))
    assert (r["ref_low"], r["ref_high"]) == (1.5, 2.5)
    assert (r["zone_low"], r["zone_high"]) == ZONE and r["tol"] == 0.25
    assert r["outcome"] == r["verdict"] == "holds" and r["holds"] is True
    r = one(form="value", ref=2, decimals=0, tol=0.25).score("c", 3.0, (ABOVE, 3.0))
    assert r["verdict"] == "fails" and r["holds"] is False
    r = one(form="value", ref=2, decimals=0, tol=0.25).score("c", 2.75, (2.5, 3.0))
    assert r["verdict"] == "inconclusive" and r["holds"] is None
    # decimals 1: half a unit of 0.1; no decimals: an exact reference, tol alone decides
    r = one(form="value", ref=2, decimals=1, tol=0.0).score("c", 2.0, interval="exact")
    assert r["zone_low"] == pytest.approx(1.95, abs=1e-15)
    assert r["zone_high"] == pytest.approx(2.05, abs=1e-15)
    r = one(form="value", ref=2, tol=0.5).score("c", 2.0, interval="exact")
    assert (r["zone_low"], r["zone_high"]) == (1.5, 2.5) and (r["ref_low"], r["ref_high"]) == (2, 2)


def test_an_exact_value_is_a_point_and_never_inconclusive():
    for v, outcome in ((1.25, "holds"), (2.75, "holds"), (BELOW, "fails"), (ABOVE, "fails")):
        r = one(form="value", ref=2, decimals=0, tol=0.25).score("c", float(v), interval="exact")
        assert r["outcome"] == outcome and (r["ci_low"], r["ci_high"]) == (v, v)


def test_an_exact_value_over_the_rounding_of_printed_inputs_is_decided_as_an_interval():
    # a recomputation from printed digits (docs/verdict-rules.md): its range over their
    # rounding straddling the zone edge cannot decide, inside holds, outside fails
    for ci, outcome in (((2.5, 3.0), "inconclusive"), ((1.5, 2.5), "holds"), ((3.0, 3.5), "fails")):
        r = one(form="value", ref=2, decimals=0, tol=0.25).score("c", sum(ci) / 2, ci, "exact")
        assert (r["outcome"], r["interval"], r["ci_low"], r["ci_high"]) == (outcome, "exact", *ci)


# --------------------------------------------------------------------------- bounds
@pytest.mark.parametrize(
    "form, interval, outcome",
    [
        ("upper", (-1e300, 2.75), "holds"),  # at the bound
        ("upper", (0.0, 2.5), "holds"),
        ("upper", (2.5, 3.0), "inconclusive"),  # straddles the bound
        ("upper", (ABOVE, 3.0), "fails"),  # just beyond
        ("upper", (2.75, 3.0), "inconclusive"),
        ("lower", (1.25, 1e300), "holds"),
        ("lower", (1.0, 1.5), "inconclusive"),
        ("lower", (1.0, BELOW), "fails"),
        ("lower", (1.0, 1.25), "inconclusive"),
    ],
)
def test_bounds_are_half_infinite_zones(form, interval, outcome):
    r = one(form=form, ref=2, decimals=0, tol=0.25).score("c", float(interval[1]), interval)
    if form == "upper":
        assert r["zone_low"] == -math.inf and r["zone_high"] == 2.75
    else:
        assert r["zone_low"] == 1.25 and r["zone_high"] == math.inf
    assert r["outcome"] == outcome
    assert rules.zone(form, (2.0, 2.0), 0.5, 0.25) == (r["zone_low"], r["zone_high"])


# --------------------------------------------------------------------------- range
@pytest.mark.parametrize(
    "lo, hi, outcome",
    [
        ([1.5, 2.0], [2.0, 2.5], "holds"),
        ([1.25, 2.0], [2.0, 2.75], "holds"),  # elements on both edges
        ([1.5, 2.5], [2.0, 3.0], "inconclusive"),  # one straddles the upper edge
        ([1.0, 2.0], [1.5, 2.5], "inconclusive"),  # one straddles the lower edge
        ([1.5, 2.75], [2.0, 3.0], "inconclusive"),  # one starts on the upper edge
        ([1.0, 1.5], [1.25, 2.0], "inconclusive"),  # one ends on the lower edge
        ([1.5, ABOVE], [2.0, 3.0], "fails"),  # one wholly above
        ([0.0, 1.5], [BELOW, 2.0], "fails"),  # one wholly below
        ([0.0, 2.5], [BELOW, 3.0], "fails"),  # a failing element outweighs a straddling one
    ],
)
def test_range_rule_element_by_element(lo, hi, outcome):
    elems = (np.array(lo), np.array(hi))
    assert decide("range", (min(lo), max(hi)), ZONE, elems=elems) == outcome
    r = one(form="range", ref=[1.5, 2.5], tol=0.25).score("c", elems=elems)
    assert r["outcome"] == outcome and (r["zone_low"], r["zone_high"]) == ZONE
    assert r["value"] == min((a + b) / 2 for a, b in zip(lo, hi))
    assert r["value_high"] == max((a + b) / 2 for a, b in zip(lo, hi))
    assert (r["ci_low"], r["ci_high"]) == (min(lo), max(hi))


def test_a_range_without_elements_is_decided_on_its_interval():
    assert decide("range", (1.5, 2.5), ZONE) == "holds"
    assert decide("range", (1.0, 2.5), ZONE) == "inconclusive"
    assert decide("range", (ABOVE, 3.0), ZONE) == "fails"


# --------------------------------------------------------------------------- one plate
def test_the_one_plate_threshold_is_5_percent():
    assert P_FAIL == 0.05


@pytest.mark.parametrize(
    "p, interval, outcome",
    [
        (0.049, (1.5, 2.5), "fails"),  # below the threshold, even with the spread inside
        (0.03, (1.5, 2.5), "fails"),  # a threshold moved to 0.01 would not fail it
        (0.0, (1.5, 2.5), "fails"),
        (0.05, (1.5, 2.5), "holds"),  # at the threshold: not rare enough to fail
        (0.051, (1.5, 2.5), "holds"),
        (0.05, (1.0, 2.5), "inconclusive"),  # the spread straddles a zone edge
        (1.0, (2.5, 3.0), "inconclusive"),
        (1.0, (1.25, 2.75), "holds"),
        (0.5, (ABOVE, 3.0), "inconclusive"),  # wholly outside, yet p says a plate like it is common
    ],
)
def test_one_plate_rule(p, interval, outcome):
    assert decide("one-plate", interval, ZONE, p_plate=p) == outcome


def test_decide_knows_only_the_forms():
    with pytest.raises(
        ValueError, match=r"^form must be one of value, share, count, upper, lower, "
    ):
        decide("roughly", (1.5, 2.5), ZONE)


def test_one_plate_needs_a_p():
    for p in (None, math.nan):
        with pytest.raises(ValueError, match="^a one-plate claim needs p_plate$"):
            decide("one-plate", (1.5, 2.5), ZONE, p_plate=p)


PLATES = np.arange(1.0, 1001.0)  # 1000 plates 1, 2, ..., 1000: their shares are exact


@pytest.mark.parametrize(
    "ref, decimals, p, outcome",
    [
        (24.5, 1, 0.048, "fails"),  # 24 plates below 24.55: q = 0.024
        (25.5, 1, 0.05, "holds"),  # 25 plates below: p = 0.05, at the threshold
        (25.0, None, 0.049, "fails"),  # no rounding given (h = 0): the tie counts half
        (25.0, 1, 0.05, "holds"),  # "25.0" is 24.95-25.05: plate 25 prints as it, counts whole
        (24.5, 0, 0.049, "fails"),  # "24" ... h = 0.5: the plate on the edge 25.0 counts half
        (25.0, 0, 0.05, "holds"),  # h = 0.5: 25 plates below 25.5
        (975.5, 1, 0.05, "holds"),  # the upper tail, at the threshold
        (976.5, 1, 0.048, "fails"),
        (976.0, 0, 0.05, "holds"),  # h = 0.5: 25 plates above 975.5
        (976.5, 0, 0.049, "fails"),  # the plate on the edge 976.0 counts half
        (500.5, 1, 1.0, "holds"),
    ],
)
def test_one_plate_claims_from_plates(ref, decimals, p, outcome):
    """The book passes half a unit of the printed last decimal to the one-plate p."""
    spec = {"form": "one-plate", "ref": ref, "tol": 1000.0}
    if decimals is not None:
        spec["decimals"] = decimals
    r = one(**spec).score("c", samples=PLATES)
    assert r["p_plate"] == pytest.approx(p, abs=1e-15) and r["outcome"] == outcome
    assert r["interval"] == "spread" and r["value"] == 500.5
    # the central 95 %: numpy's percentile at (n - 1) q between order statistics
    assert (r["ci_low"], r["ci_high"]) == pytest.approx((25.975, 975.025), rel=1e-14)


def test_one_plate_central_range_is_2_5_to_97_5_percent():
    # zone [40, 961]: the 5-95 % range (50.95-950.05) would lie inside, the 2.5-97.5 % range
    # (25.975-975.025) does not: the plates do not decide the claim
    r = one(form="one-plate", ref=500.5, decimals=0, tol=460.0).score("c", samples=PLATES)
    assert (r["zone_low"], r["zone_high"]) == (40.0, 961.0)
    assert r["p_plate"] == 1.0 and r["outcome"] == "inconclusive"
    r = one(form="one-plate", ref=500.5, decimals=0, tol=475.0).score("c", samples=PLATES)
    assert (r["zone_low"], r["zone_high"]) == (25.0, 976.0) and r["outcome"] == "holds"


@pytest.mark.parametrize(
    "interval, p, outcome",
    [
        ((ABOVE, 3.0), 0.5, "inconclusive"),  # spread wholly outside, p common: not a miss
        ((1.0, BELOW), 0.05, "inconclusive"),  # at the threshold
        ((1.5, 2.5), 0.049, "fails"),  # spread inside, p rare: fails
        ((1.5, 2.5), 0.05, "holds"),
        ((1.0, 1.5), 0.2, "inconclusive"),
        ((ABOVE, 3.0), None, "fails"),  # no p: the interval's miss decides
        ((1.5, 2.5), None, "holds"),
    ],
)
def test_inference_status_with_a_one_plate_p_is_the_books_rule(interval, p, outcome):
    """``sim.claims.inference.status``: a one-plate p replaces the interval's miss
    (``p < 1 - level`` alone fails), exactly as ``decide`` does; without p the miss decides."""
    st = Statement("c", (2.0, 2.0), form="one-plate", decimals=0, tol=0.25)
    assert st.zone == ZONE
    ev = {"low": np.array([interval[0]]), "high": np.array([interval[1]])}
    if p is not None:
        ev["p"] = np.array([p])
        assert decide("one-plate", interval, ZONE, p_plate=p) == outcome
    code = {"holds": HOLDS, "fails": FAILS, "inconclusive": UNDECIDED}[outcome]
    assert status(st, ev, 1).tolist() == [code]
    # the level sets the threshold: at 99 % a p of 0.02 is not rare enough to fail
    if p == 0.049:
        assert status(st, {**ev, "p": np.array([0.02])}, 1, level=0.99).tolist() == [HOLDS]
        assert status(st, {**ev, "p": np.array([0.0099])}, 1, level=0.99).tolist() == [FAILS]


def test_a_one_plate_claim_without_plates_is_a_value():
    r = one(form="one-plate", ref=2, decimals=0, tol=0.25).score("c", 2.0, (1.0, 2.5))
    assert r["outcome"] == "inconclusive" and math.isnan(r["p_plate"])
    r = one(form="one-plate", ref=2, decimals=0, tol=0.25).score("c", 3.0, (ABOVE, 3.0))
    assert r["outcome"] == "fails"


def test_plates_of_a_claim_without_a_number_give_no_p():
    r = one(kind="finding").score("c", samples=PLATES)
    assert math.isnan(r["p_plate"]) and r["outcome"] is None and r["verdict"] == "finding"
    assert r["value"] == 500.5


# --------------------------------------------------------------------------- kinds
@pytest.mark.parametrize(
    "kind, interval, verdict, holds",
    [
        ("prediction", (1.5, 2.5), "holds", True),
        ("prediction", (ABOVE, 3.0), "fails", False),
        ("prediction", (1.0, 2.5), "inconclusive", None),
        ("paper-check", (1.5, 2.5), "holds", True),
        ("paper-check", (ABOVE, 3.0), "erratum", False),  # the paper contradicts its own data
        ("paper-check", (1.0, 2.5), "inconclusive", None),
        ("input", (ABOVE, 3.0), "input", None),
        ("self-check", (ABOVE, 3.0), "self-check", None),
        ("self-check", (1.5, 2.5), "self-check", None),
    ],
)
def test_the_verdict_follows_the_outcome_by_kind(kind, interval, verdict, holds):
    r = one(kind, form="value", ref=2, decimals=0, tol=0.25).score("c", 2.0, interval)
    assert r["verdict"] == verdict and r["holds"] is holds and r["kind"] == kind


def test_kinds_without_a_number():
    r = one("finding").score("c", 1.0, (0.5, 1.5))
    assert r["verdict"] == "finding" and r["outcome"] is None and r["holds"] is None
    assert math.isnan(r["zone_low"]) and math.isnan(r["ref_low"]) and math.isnan(r["tol"])
    assert r["form"] == ""
    b = ClaimBook(
        [{"id": "c", "source": "s", "paper": "p", "kind": "not comparable", "why": "no setup"}],
        [],
    )
    r = b.score("c", 1.0, (0.5, 1.5), note="extra")
    assert r["verdict"] == "not comparable" and r["note"] == "no setup extra"
    b = ClaimBook(
        [{"id": "c", "source": "s", "paper": "p", "kind": "not comparable", "why": "no setup"}],
        [],
    )
    assert b.score("c", 1.0, (0.5, 1.5))["note"] == "no setup"
    b = ClaimBook([{"id": "c", "source": "s", "paper": "p", "kind": "not comparable"}], [])
    assert b.path == "<claims>" and b.score("c", 1.0, (0.5, 1.5), note="n")["note"] == "n"
    assert rules.verdict_of("prediction", None) == "finding"
    assert rules.verdict_of("paper-check", None) == "finding"
    assert rules.verdict_of("paper-check", "fails") == "erratum"
    assert {v: rules.holds_of(v) for v in bk.VERDICTS} == {
        v: {"holds": True, "fails": False, "erratum": False}.get(v) for v in bk.VERDICTS
    }
    assert [v for v in bk.VERDICTS if rules.holds_of(v) is not None] == [
        "holds",
        "fails",
        "erratum",
    ]


# --------------------------------------------------------------------------- provenance
def test_claims_tables_state_their_interval_methods(tmp_path):
    b = one(form="value", ref=2, decimals=0, tol=0.25)
    path = write_claims(tmp_path / "claims.parquet", [b.score("c", 2.0, ZONE)], {"study": "t"}, b)
    prov = read_provenance(path)
    assert prov["study"] == "t"
    iv = prov["intervals"]
    assert iv["level"] == 0.95 and iv["min_chunks"] == 20 and iv["one_plate_p_fail"] == 0.05
    # the region verdicts' sample-size rule: 29 points bound the disagreeing share under 10 %
    assert (iv["region_min_points"], iv["region_share"], iv["region_level"]) == (29, 0.10, 0.95)
    assert set(iv["methods"]) == {
        "mean",
        "sd",
        "share",
        "bootstrap",
        "jackknife",
        "spread",
        "exact",
    }
    assert iv["interval_column"] == {
        "ci": "a Monte-Carlo confidence interval (mean, sd, share, bootstrap or jackknife)",
        "spread": "the one-plate 2.5-97.5 % range over simulated plates",
        "exact": "a deterministic value (or its range over the rounding of printed inputs)",
        "region": "decided over the consistent region of unprinted inputs (sim.claims.region)",
    }
    assert pq.read_table(path).column("interval").to_pylist() == ["ci"]


# --------------------------------------------------------------------------- one implementation
def test_the_one_plate_percentiles_are_written_once():
    """Studies take the one-plate spread from sim.claims.intervals, not their own percentiles."""
    hits = [
        str(p.relative_to(ROOT))
        for p in (ROOT / "sim").rglob("*.py")
        if "[2.5, 50, 97.5]" in p.read_text() or "[2.5, 97.5]" in p.read_text()
    ]
    assert hits == []


# --------------------------------------------------------------------------- the book's checks
def _msg(spec: dict) -> str:
    base = {"id": "c", "source": "s", "paper": "p", "kind": "prediction"}
    with pytest.raises(bk.ConfigError) as e:
        ClaimBook([{**base, **spec}], [], "b.toml")
    return str(e.value)


@pytest.mark.parametrize(
    "spec, message",
    [
        ({"colour": "red"}, "claim.colour: b.toml: claim 1: unknown key"),
        ({"id": ""}, "claim.id: b.toml: claim 1: missing or not text"),
        ({"source": 3}, "claim.source: b.toml: claim 1: missing or not text"),
        ({"paper": None}, "claim.paper: b.toml: claim 1: missing or not text"),
        (
            {"kind": "guess"},
            "claim.kind: b.toml: claim 1 (c): 'guess' is not one of prediction, input, "
            "self-check, paper-check, finding, not comparable",
        ),
        (
            {"form": "roughly", "ref": 1.0, "tol": 0},
            "claim.form: b.toml: claim 1 (c): form must be one of value, share, count, upper, "
            "lower, range, one-plate",
        ),
        (
            {"form": "value", "ref": "one", "tol": 0},
            "claim.ref: b.toml: claim 1 (c): ref must be a finite number or [low, high]",
        ),
        (
            {"form": "range", "ref": [1.0, 2.0, 3.0], "tol": 0},
            "claim.ref: b.toml: claim 1 (c): ref must be a finite number or [low, high]",
        ),
        (
            {"form": "range", "ref": [2.0, 1.0], "tol": 0},
            "claim.ref: b.toml: claim 1 (c): ref must be a finite number or [low, high]",
        ),
        (
            {"form": "value", "ref": math.inf, "tol": 0},
            "claim.ref: b.toml: claim 1 (c): ref must be a finite number or [low, high]",
        ),
        (
            {"form": "range", "ref": 1.0, "tol": 0},
            "claim.ref: b.toml: claim 1 (c): a range needs [low, high], the other forms one number",
        ),
        (
            {"form": "value", "ref": [1.0, 2.0], "tol": 0},
            "claim.ref: b.toml: claim 1 (c): a range needs [low, high], the other forms one number",
        ),
        (
            {"form": "value", "ref": [1.0, 1.0], "tol": 0},
            "claim.ref: b.toml: claim 1 (c): a range needs [low, high], the other forms one number",
        ),
        (
            {"form": "value", "ref": 1.0},
            "claim.tol: b.toml: claim 1 (c): state the deciding half-width tol >= 0",
        ),
        (
            {"form": "value", "ref": 1.0, "tol": -0.5},
            "claim.tol: b.toml: claim 1 (c): state the deciding half-width tol >= 0",
        ),
        (
            {"form": "value", "ref": 1.0, "tol": "small"},
            "claim.tol: b.toml: claim 1 (c): state the deciding half-width tol >= 0",
        ),
        ({}, "claim.ref: b.toml: claim 1 (c): a prediction needs the paper's number (ref)"),
        (
            {"kind": "paper-check"},
            "claim.ref: b.toml: claim 1 (c): a paper-check needs the paper's number (ref)",
        ),
    ],
)
def test_a_bad_claim_is_one_line_naming_the_key(spec, message):
    assert _msg(spec) == message


def test_what_the_book_accepts():
    # a range of two equal numbers, an integer reference and tol, a zero tol, kinds without ref
    for spec in (
        {"form": "range", "ref": [1, 1], "tol": 0},
        {"form": "count", "ref": 3, "tol": 1},
        {"kind": "input", "form": "value", "ref": 1.0, "tol": 0.0},
        {"kind": "finding"},
        {"kind": "not comparable", "why": "w", "headline": True},
        {"kind": "self-check", "form": "value", "ref": -2.0, "tol": 0.0, "decimals": 3},
    ):
        one(**{"kind": "prediction", **spec})
    with pytest.raises(bk.ConfigError) as e:
        ClaimBook(
            [
                {"id": "c", "source": "s", "paper": "p", "kind": "finding"},
                {"id": "c", "source": "s", "paper": "p", "kind": "finding"},
            ],
            [],
            "b.toml",
        )
    assert str(e.value) == "claim.id: b.toml: claim 2: duplicate id 'c'"
    with pytest.raises(bk.ConfigError) as e:
        ClaimBook([], [{"source": "s", "printed": "1.0"}], "b.toml")
    assert str(e.value) == "not_reproduced: b.toml: entry 1 needs exactly source, printed and why"
    nr = {"source": "s", "printed": "1.0", "why": "w"}
    assert ClaimBook([], [nr], "b.toml").not_reproduced == [nr]


def test_load_reads_a_toml_book_and_names_what_is_wrong(tmp_path):
    f = tmp_path / "claims.toml"
    f.write_text(
        '[[claim]]\nid = "c"\nsource = "s"\npaper = "p"\nkind = "finding"\n'
        '[[not_reproduced]]\nsource = "s"\nprinted = "1"\nwhy = "w"\n'
    )
    b = ClaimBook.load(f)
    assert b.path == str(f) and list(b.specs) == ["c"] and len(b.not_reproduced) == 1
    assert b.spec("c")["kind"] == "finding"
    with pytest.raises(
        bk.ConfigError,
        match=r"^claim.id: .*claims.toml: claim 'x', which the study scores, is not declared$",
    ):
        b.spec("x")
    f.write_text("[[claim]]\nid = \n")
    with pytest.raises(bk.ConfigError) as e:
        ClaimBook.load(f)
    assert str(e.value).startswith(f"claims: cannot read the claim book {f}: ")
    with pytest.raises(bk.ConfigError) as e:
        ClaimBook.load(tmp_path / "none.toml")
    assert str(e.value).startswith(f"claims: cannot read the claim book {tmp_path / 'none.toml'}")
    f.write_text("[[claim]]\n[[extra]]\n")
    with pytest.raises(bk.ConfigError) as e:
        ClaimBook.load(f)
    assert str(e.value) == f"extra: {f}: unknown table"
    f.write_text("")
    assert ClaimBook.load(f).specs == {} and ClaimBook.load(f).not_reproduced == []


def test_score_refuses_what_it_cannot_decide():
    b = one(form="value", ref=2, tol=0.5)
    with pytest.raises(ValueError, match=r"^claim 'c': give value and ci \(or elems / samples\)$"):
        b.score("c", 2.0)
    b = one(form="value", ref=2, tol=0.5)
    with pytest.raises(ValueError, match=r"^interval must be ci, spread or exact, not 'wide'$"):
        b.score("c", 2.0, (1.0, 3.0), "wide")
    b = one(form="value", ref=2, tol=0.5)
    b.score("c", 2.0, (1.0, 3.0))
    with pytest.raises(ValueError, match=r"^claim 'c' scored twice$"):
        b.score("c", 2.0, (1.0, 3.0))
    for bad in ((math.inf, (1.0, 3.0)), (2.0, (1.0, math.nan))):
        with pytest.raises(bk.StudyError) as e:
            one(form="value", ref=2, tol=0.5).score("c", *bad)
        assert str(e.value) == (
            "claim c: the simulated value is not finite (NaN or infinite); "
            "the run's configuration gives no usable number here"
        )
    with pytest.raises(bk.StudyError, match="^claim c: the simulated samples is not finite"):
        one(form="one-plate", ref=2, tol=0.5).score("c", samples=np.array([1.0, math.nan]))
    with pytest.raises(bk.StudyError, match="^claim c: the simulated element intervals is not"):
        one(form="range", ref=[1, 2], tol=0).score(
            "c", elems=(np.array([1.0]), np.array([math.inf]))
        )
    with pytest.raises(bk.StudyError, match="^claim c: the simulated value is not finite"):
        one(form="value", ref=2, tol=0.5).score("c", 2.0, (1.0, 3.0), value_high=math.nan)


def test_a_row_carries_everything_the_report_reads():
    b = one(form="value", ref=2, decimals=0, tol=0.25, headline=True)
    r = b.score("c", 2.0, (1.5, 2.5), note="n", value_high=2.25)
    assert list(r) == bk.CLAIM_COLUMNS
    assert r == {
        "claim": "c",
        "source": "s",
        "paper": "p",
        "form": "value",
        "kind": "prediction",
        "headline": True,
        "value": 2.0,
        "value_high": 2.25,
        "ci_low": 1.5,
        "ci_high": 2.5,
        "interval": "ci",
        "ref_low": 1.5,
        "ref_high": 2.5,
        "tol": 0.25,
        "zone_low": 1.25,
        "zone_high": 2.75,
        "p_plate": r["p_plate"],
        "outcome": "holds",
        "verdict": "holds",
        "holds": True,
        "note": "n",
    }
    assert math.isnan(r["p_plate"])
    r = one(form="value", ref=2, tol=0.5).score("c", 2.0, (1.5, 2.5))
    assert r["headline"] is False and math.isnan(r["value_high"]) and r["note"] == ""
    r = one(form="range", ref=[1, 2], tol=0).score(
        "c", 1.2, elems=(np.array([1.0, 1.5]), np.array([1.25, 2.0])), value_high=1.9
    )
    assert (r["value"], r["value_high"]) == (1.2, 1.9)


def test_not_comparable_rows():
    spec = {"id": "c", "source": "s", "paper": "p", "kind": "not comparable", "why": "w"}
    b = ClaimBook([{**spec, "form": "value", "ref": 3.0, "tol": 0.0}], [], "<t>")
    r = b.not_comparable("c", note="n")
    assert list(r) == bk.CLAIM_COLUMNS
    assert (r["claim"], r["form"], r["kind"], r["verdict"], r["outcome"], r["note"]) == (
        "c",
        "value",
        "not comparable",
        "not comparable",
        None,
        "w n",
    )
    assert (r["ref_low"], r["ref_high"], r["interval"], r["holds"]) == (3.0, 3.0, "exact", None)
    for k in ("value", "value_high", "ci_low", "ci_high", "tol", "zone_low", "p_plate"):
        assert math.isnan(r[k]), k
    b.check_complete()  # scored
    b = ClaimBook([{**spec, "form": "range", "ref": [1.0, 2.0], "tol": 0.0}], [], "<t>")
    r = b.not_comparable("c")
    assert (r["ref_low"], r["ref_high"], r["note"]) == (1.0, 2.0, "w")
    r = ClaimBook([spec], [], "<t>").not_comparable("c")
    assert math.isnan(r["ref_low"]) and r["form"] == ""
    del spec["why"]  # no reason in the book: the note alone
    assert ClaimBook([spec], [], "<t>").not_comparable("c", note="n")["note"] == "n"
    b = one(form="value", ref=2, tol=0.5)
    with pytest.raises(ValueError, match=r"^claim 'c' is declared 'prediction', not 'not comp"):
        b.not_comparable("c")


def test_write_claims_checks_the_book_and_writes_not_reproduced(tmp_path):
    nr = {"source": "s", "printed": "1.0", "why": "w"}
    specs = [{"id": i, "source": "s", "paper": "p", "kind": "finding"} for i in ("a", "b", "c")]
    b = ClaimBook(specs, [nr], "<t>")
    with pytest.raises(
        ValueError, match=r"^claim.id: <t>: declared claims the study does not score: a, b, c$"
    ):
        b.check_complete()
    rows = [b.score("a", 1.0, interval="exact"), b.score("c", 1.0, interval="exact")]
    with pytest.raises(
        ValueError, match=r"^claim.id: <t>: declared claims the study does not score: b$"
    ):
        write_claims(tmp_path / "claims.parquet", rows, {}, b)
    assert not (tmp_path / "claims.parquet").exists()
    rows.append(b.score("b", 2.0, (1.0, 3.0)))
    write_claims(tmp_path / "claims.parquet", rows, {"study": "t"}, b)
    t = pq.read_table(tmp_path / "not_reproduced.parquet").to_pydict()
    assert t == {"source": ["s"], "printed": ["1.0"], "why": ["w"]}
    assert read_provenance(tmp_path / "not_reproduced.parquet") == {"study": "t"}
    t = pq.read_table(tmp_path / "claims.parquet").to_pydict()
    assert (
        t["claim"] == ["a", "c", "b"] and t["ci_low"] == [1.0] * 3 and t["zone_low"] == [None] * 3
    )
    write_claims(tmp_path / "bare.parquet", rows, {})  # without a book: rows only
    assert not (tmp_path / "bare_not_reproduced.parquet").exists()
    assert bk._null(math.inf) is None and bk._null(-math.inf) is None and bk._null(1.5) == 1.5
    assert bk._null(math.nan) is None and bk._null("x") == "x" and bk._null(None) is None


# --------------------------------------------------------------------------- off the paper's setup
def _row(claim, kind, outcome, interval="exact", note=""):
    verdict = rules.verdict_of(kind, outcome)
    return {
        "claim": claim,
        "kind": kind,
        "interval": interval,
        "outcome": outcome,
        "verdict": verdict,
        "holds": rules.holds_of(verdict),
        "note": note,
    }


def test_off_paper_makes_every_prediction_a_finding_and_names_the_inputs():
    rows = [
        _row("block_mm", "input", "fails"),  # a printed input the run does not match
        _row("n_plates", "input", "fails"),
        _row("sigma_um", "input", "holds"),  # matches: not named
        _row("noise_um", "input", "fails", interval="ci"),  # not exact: not a setup input
        _row("p1", "prediction", "holds"),
        _row("p2", "prediction", "fails", note="see fig. 3"),
        _row("p3", "prediction", None),  # already a finding
        _row("c1", "paper-check", "fails"),  # an erratum stays an erratum
        _row("s1", "self-check", "holds"),
    ]
    out = rules.off_paper(rows)
    assert len(out) == len(rows)
    why = (
        "not a test of the paper: this run's printed inputs differ from the paper's "
        "(block_mm, n_plates), so the rule's outcome ({}) is a finding about this run's setup"
    )
    p1, p2 = out[4], out[5]
    assert p1 == {**rows[4], "verdict": "finding", "holds": None, "note": why.format("holds")}
    assert p2 == {
        **rows[5],
        "verdict": "finding",
        "holds": None,
        "note": why.format("fails") + "; see fig. 3",
    }
    assert p1["outcome"] == "holds" and p2["outcome"] == "fails"  # the rule's outcome is kept
    for k in (0, 1, 2, 3, 6, 7, 8):
        assert out[k] == rows[k]
    assert out[7]["verdict"] == "erratum" and out[6]["verdict"] == "finding"


@pytest.mark.parametrize(
    "bad",
    [
        _row("x", "input", "holds"),  # the input matches the paper
        _row("x", "input", "fails", interval="ci"),  # not an exact configuration value
        _row("x", "self-check", "fails"),  # not an input
        _row("x", "prediction", "fails"),
    ],
)
def test_a_run_on_the_papers_setup_comes_back_unchanged(bad):
    rows = [bad, _row("p1", "prediction", "holds"), _row("p2", "prediction", "fails")]
    out = rules.off_paper(iter(rows))
    assert out == rows
