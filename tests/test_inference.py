"""The joint inference of unprinted inputs (sim.claims.inference) and verdicts over its region
(sim.claims.region), on synthetic problems whose region is known analytically."""

import math

import numpy as np
import pytest

from sim.claims.book import ClaimBook
from sim.claims.inference import (
    FAILS,
    HOLDS,
    UNDECIDED,
    Input,
    Statement,
    explore,
    interval_from_se,
    parse_declaration,
    status,
)
from sim.claims.region import decide_over, region_row, region_table
from sim.mc.config import ConfigError

A = Input("a_mm", 0.0, 10.0)
B = Input("b_mm", 0.0, 10.0)
SUM = Statement("sum", (10.0, 10.0), "value", decimals=0)  # a + b in [9.5, 10.5]
A_UP = Statement("a_up", (4.0, 4.0), "upper", decimals=0)  # a <= 4.5


def model(x):
    a, b = x["a_mm"], x["b_mm"]
    return {"sum": a + b, "a_up": a, "b_up": b, "a_low": a, "b": b, "big": np.zeros_like(a)}


def region(*extra, n=1024, rounds=3, seed=1):
    return explore(
        [A, B], [SUM, A_UP, *extra], model, np.random.default_rng(seed), n=n, rounds=rounds
    )


def test_known_region_exact_and_resolved():
    r = region()
    p = r.points()
    # every accepted point satisfies the analytic conditions, and every rejected one violates them
    ok = (np.abs(r.x["a_mm"] + r.x["b_mm"] - 10) <= 0.5) & (r.x["a_mm"] <= 4.5)
    assert np.array_equal(ok, r.accepted)
    # the projections reach the analytic ones within the boundary resolution
    (alo, ahi), (blo, bhi) = r.bounds()["a_mm"], r.bounds()["b_mm"]
    ha, hb = r.resolution["a_mm"][1], r.resolution["b_mm"][1]
    assert r.resolution["a_mm"][1] < r.resolution["a_mm"][0]  # refinement did refine
    # a statement's boundary to the boundary spacing; a face of the possible box to the design's
    assert 0 <= alo <= r.resolution["a_mm"][0] and 4.5 - ha <= ahi <= 4.5
    assert 10 - r.resolution["b_mm"][0] <= bhi <= 10
    # b's lowest value lies at a corner (a = 4.5, b = 5) of the region: a few spacings
    assert 5.0 <= blo <= 5.0 + 6 * hb
    assert len(p["a_mm"]) == r.accepted.sum() > 50
    assert r.conflicts == []
    # the refinement concentrates points at the boundary: more points than the design
    assert r.n > 1024


def test_empty_region_names_minimal_conflict():
    b_up = Statement("b_up", (3.0, 3.0), "upper", decimals=0)  # b <= 3.5: with a <= 4.5, a+b < 9.5
    r = region(b_up)
    assert r.empty
    assert r.conflicts == [("sum", "a_up", "b_up")]  # no pair alone conflicts
    v = decide_over(r, Statement("b", (1.0, 1.0), "lower"))
    assert v.verdict == "undecidable" and "sum + a_up + b_up" in v.note


def test_statement_contradicted_alone():
    r = region(Statement("a_low", (11.0, 11.0), "lower"))  # a >= 11: outside the possible range
    assert r.empty and r.conflicts == [("a_low",)]


def test_monte_carlo_noise_widens_the_region_by_its_interval():
    se = 1.0
    st = Statement("a_mc", (5.0, 5.0), "value", decimals=0)

    def mc(x):
        return {"a_mc": interval_from_se(x["a_mm"], np.full_like(x["a_mm"], se))}

    r = explore([A], [st], mc, np.random.default_rng(2), n=256, rounds=4)
    z = 1.959963984540054
    lo, hi = r.bounds()["a_mm"]
    h = r.resolution["a_mm"][1]
    assert 4.5 - z * se - h <= lo <= 4.5 - z * se + h
    assert 5.5 + z * se - h <= hi <= 5.5 + z * se + h
    # confirmed (interval inside the zone) is empty: the interval (width 3.9) exceeds the zone
    assert not r.confirmed.any()


@pytest.mark.parametrize(
    "form, ref, lo, hi, expect",
    [
        ("value", 2.0, 1.6, 2.4, HOLDS),  # zone [1.5, 2.5] (decimals 0)
        ("value", 2.0, 1.4, 2.4, UNDECIDED),
        ("value", 2.0, 2.6, 3.0, FAILS),
        ("value", 2.0, 0.0, 1.49, FAILS),
        ("upper", 2.0, -5.0, 2.49, HOLDS),
        ("upper", 2.0, 2.51, 9.0, FAILS),
        ("lower", 2.0, 1.51, 9.0, HOLDS),
        ("lower", 2.0, 0.0, 1.49, FAILS),
    ],
)
def test_point_status_both_sides(form, ref, lo, hi, expect):
    st = Statement("s", (ref, ref), form, decimals=0)
    assert status(st, {"low": [lo], "high": [hi]}, 1)[0] == expect


def test_point_status_elements_and_one_plate():
    st = Statement("r", (1.0, 2.0), "range")
    ev = np.array([[1.2, 1.8], [1.2, 2.1], [1.2, 0.5]])  # every element in / outside
    assert status(st, ev, 3).tolist() == [HOLDS, FAILS, FAILS]
    one = Statement("o", (1.0, 1.0), "one-plate", decimals=1)
    ev = {"low": [0.96, 0.96, 0.5], "high": [1.04, 1.04, 1.5], "p": [0.5, 0.049, 0.3]}
    assert status(one, ev, 3).tolist() == [HOLDS, FAILS, UNDECIDED]


@pytest.mark.parametrize(
    "t, verdict",
    [
        (4.9, "holds"),  # every region point has b >= 5
        (5.5, "depends"),
        (7.5, "depends"),
        (10.1, "fails"),  # no region point has b > 10 (the possible range)
    ],
)
def test_verdicts_on_both_sides_of_thresholds(t, verdict):
    r = region()
    v = decide_over(r, Statement("b", (t, t), "lower"))
    assert v.verdict == verdict
    if verdict == "depends":
        lo, hi = (float(s) for s in v.holds_where.split("b_mm ")[1].split("-"))
        assert t <= lo <= t + 2 * r.resolution["b_mm"][1] and hi <= 10
        assert v.n_holds + v.n_fails == v.n_points


def test_undecidable_says_what_would_decide():
    r = region()
    wide = {"low": np.full(r.n, -1.0), "high": np.full(r.n, 1.0)}
    st = Statement("big", (0.0, 0.0), "upper", decide="a plate measured twice")
    v = decide_over(r, st, wide)
    assert v.verdict == "undecidable" and v.note == "a plate measured twice"
    # the same prediction with an exact value decides
    assert decide_over(r, st).verdict == "holds"


def test_region_table_one_row_per_accepted_vector():
    r = region()
    cols = region_table(r, [Statement("b", (7.5, 7.5), "lower")], values=["sum"])
    n = int(r.accepted.sum())
    assert {len(c) for c in cols.values()} == {n}
    assert set(cols["sum"]) <= {"holds", "undecided"} and set(cols["b"]) == {"holds", "fails"}
    assert all(9.5 <= s <= 10.5 for s in cols["sum__value"])


def test_declaration_validated():
    doc = {
        "inputs": {"offset_mm": {"low": 0, "high": 60, "why": "the scale"}},
        "statements": {"closure": {"ref": 1.6, "decimals": 1, "paper": "1.6 um"}},
    }
    (i,), (s,) = parse_declaration(doc)
    assert i.high == 60 and s.zone == pytest.approx((1.55, 1.65))
    bad = [
        ({"inputs": {"offset": {"low": 0, "high": 1}}}, "inputs.offset"),
        ({"inputs": {"o_mm": {"low": 2, "high": 1}}}, "inputs.o_mm"),
        ({"inputs": {"o_mm": {"low": 0, "hgh": 1}}}, "inputs.o_mm.hgh"),
        ({"inputs": {"o_mm": {"low": 0, "high": 1}}, "statements": {"s": {}}}, "statements.s.ref"),
        (
            {
                "inputs": {"o_mm": {"low": 0, "high": 1}},
                "statements": {"s": {"ref": 1, "form": "x"}},
            },
            "statements.s.form",
        ),
        ({"inputs": {"o_mm": {"low": 0, "high": math.inf}}}, "inputs.o_mm"),
    ]
    for d, key in bad:
        with pytest.raises(ConfigError) as e:
            parse_declaration(d)
        assert str(e.value).startswith(key), str(e.value)


def test_region_row_carries_the_region_verdict():
    book = ClaimBook(
        [
            {
                "id": "b",
                "source": "s",
                "paper": "p",
                "kind": "prediction",
                "form": "lower",
                "ref": 7.5,
                "tol": 0.0,
            }
        ],
        [],
    )
    r = region()
    st = Statement("b", (7.5, 7.5), "lower")
    row = region_row(book, "b", decide_over(r, st), r.points()["b_mm"], "extra")
    assert row["verdict"] == "depends" and row["holds"] is None and row["interval"] == "region"
    assert row["value"] == pytest.approx(r.bounds()["b_mm"][0]) and row["value_high"] <= 10
    assert "holds for" in row["note"] and row["note"].endswith("extra")


def test_refine_on_resolves_where_a_prediction_holds():
    pred = Statement("b", (7.5, 7.5), "lower")
    plain = region(rounds=3)
    refined = explore(
        [A, B], [SUM, A_UP], model, np.random.default_rng(1), n=1024, rounds=3, refine_on=[pred]
    )
    h = refined.resolution["b_mm"][1]

    def low(r):
        return decide_over(r, pred).holds_where.split("b_mm ")[1].split("-")[0]

    # the refined lower end of "holds for b >= 7.5" is within the boundary spacing of 7.5,
    # and closer than the unrefined one
    assert 7.5 <= float(low(refined)) <= 7.5 + h
    assert float(low(refined)) - 7.5 <= float(low(plain)) - 7.5


def test_write_explored_keeps_every_vector_of_an_empty_region(tmp_path):
    """An empty region still shows what was tried: one row per explored vector, none
    accepted, each statement's outcome and value, and the inputs table beside it."""
    from sim.claims.book_region import write_explored
    from sim.mc.storage import read_table

    r = region(Statement("a_low", (11.0, 11.0), "lower"), n=64, rounds=0)
    write_explored(tmp_path / "scan_region.parquet", r, {})
    t = read_table(tmp_path / "scan_region.parquet").to_pydict()
    assert len(t["a_mm"]) == r.n == 64 and not any(t["accepted"])
    assert set(t["a_low"]) == {"fails"}
    assert np.allclose(t["sum__value"], np.add(t["a_mm"], t["b_mm"]))
    inp = read_table(tmp_path / "scan_region_inputs.parquet").to_pydict()
    assert inp["input"] == ["a_mm", "b_mm"] and inp["n_region"] == [0, 0]
    assert all(math.isnan(v) for v in inp["region_low"])


def test_pixel_inputs_are_declared_in_their_unit():
    (i,), _ = parse_declaration({"inputs": {"grid_sigma_px": {"low": 0, "high": 0.5}}})
    assert i.name == "grid_sigma_px"


def test_setting_a_statement_aside_restores_what_the_others_leave():
    """A statement that empties the region alone, set aside, leaves exactly the region of
    the other statements on the same points."""
    a_low = Statement("a_low", (11.0, 11.0), "lower")
    r = region(a_low, n=256, rounds=0)
    assert r.empty
    rest = r.without(["a_low"])
    assert [s.id for s in rest.statements] == ["sum", "a_up"] and rest.n == r.n
    ok = (np.abs(r.x["a_mm"] + r.x["b_mm"] - 10) <= 0.5) & (r.x["a_mm"] <= 4.5)
    assert np.array_equal(rest.accepted, ok) and ok.any()
