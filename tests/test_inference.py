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
    Region,
    Statement,
    evaluate,
    explore,
    interval_from_se,
    parse_declaration,
    status,
)
from sim.claims.region import (
    decide_over,
    outcomes,
    region_row,
    region_table,
    region_verdict,
    statement_of,
)
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


# --------------------------------------------------------------------------- pinned by hand (issue 28)

Z = Statement("z", (1.0, 2.0), "value")  # zone [1, 2]


def test_interval_from_se_is_value_plus_minus_z_se():
    ev = interval_from_se([10, 20], [2, 4])
    z = 1.959963984540054  # scipy.stats.norm.ppf(0.975)
    np.testing.assert_allclose(ev["low"], [10 - 2 * z, 20 - 4 * z], rtol=1e-15)
    np.testing.assert_allclose(ev["high"], [10 + 2 * z, 20 + 4 * z], rtol=1e-15)
    assert ev["value"].tolist() == [10.0, 20.0] and ev["value"].dtype == float
    ev = interval_from_se(3, 0.5, level=0.90)
    np.testing.assert_allclose(ev["high"] - 3, 0.5 * 1.6448536269514722, rtol=1e-15)


def test_status_at_the_zone_edges():
    lo = np.array([1.0, 0.5, 2.5, 0.0, 2.0])
    hi = np.array([2.0, 1.0, 3.0, np.nextafter(1.0, 0), np.nextafter(2.0, 3)])
    s = status(Z, {"low": lo, "high": hi}, 5)
    # [1, 2] inside; touching an edge meets the zone; wholly below / above misses it
    assert s.tolist() == [HOLDS, UNDECIDED, FAILS, FAILS, UNDECIDED]
    assert s.dtype == np.int8


def test_status_of_a_value_alone_and_of_missing_values():
    v = np.array([1.5, 3.0])
    assert status(Z, {"value": v}, 2).tolist() == [HOLDS, FAILS]
    assert status(Z, {"value": v, "high": v + 0.1}, 2).tolist() == [HOLDS, FAILS]
    # a missing value (None or NaN, in low or in high alone) leaves the point undecided
    assert status(Z, [1.5, None], 2).tolist() == [HOLDS, UNDECIDED]
    assert status(Z, {"value": [1.5, None]}, 2).tolist() == [HOLDS, UNDECIDED]
    ev = {"low": [np.nan, 1.2, 0.0], "high": [0.5, np.nan, 0.5]}
    assert status(Z, ev, 3).tolist() == [UNDECIDED, UNDECIDED, FAILS]
    ev = {"low": [[1.2, 1.3], [np.nan, 1.1]], "high": [[1.4, 1.5], [1.5, 1.6]]}
    assert status(Z, ev, 2).tolist() == [HOLDS, UNDECIDED]  # element-wise NaN: that point only
    ev = {"low": [[1.2, 1.3], [1.2, 1.1]], "high": [[1.4, 1.5], [1.5, np.nan]]}
    assert status(Z, ev, 2).tolist() == [HOLDS, UNDECIDED]
    # a missing p is no evidence of a miss
    ev = {"low": [1.2, 1.2], "high": [1.5, 1.5], "p": [0.01, None]}
    assert status(Z, ev, 2).tolist() == [FAILS, HOLDS]


def test_status_names_a_statement_with_the_wrong_number_of_points():
    with pytest.raises(ValueError, match="statement z: evidence must have a leading axis of 3"):
        status(Z, np.ones(4), 3)
    with pytest.raises(ValueError, match="statement z"):
        status(Z, {"low": np.ones(3), "high": np.ones(4)}, 3)


def test_evaluate_stacks_statements_at_the_default_level():
    ev = {"z": {"low": [1.2, 1.2], "high": [1.5, 1.5], "p": [0.049, 0.05]}, "y": [1.5, 9.0]}
    y = Statement("y", (1.5, 1.5), "value", decimals=1)
    s = evaluate([Z, y], ev, 2)  # level 0.95: p < 0.05 fails
    assert s.tolist() == [[FAILS, HOLDS], [HOLDS, FAILS]] and s.dtype == np.int8
    assert evaluate([Z], ev, 2, level=0.9).tolist() == [[FAILS], [FAILS]]  # p < 0.1
    e = evaluate([], ev, 4)
    assert e.shape == (4, 0) and e.dtype == np.int8
    with pytest.raises(ValueError, match="the model gave no evidence for: a, b$"):
        evaluate([Statement("a", (1.0, 1.0)), Z, Statement("b", (1.0, 1.0))], ev, 2)


def _hand_region():
    """Four points of inputs a (free, 0-10) and c (fixed at 3), two statements."""
    c = Input("c_mm", 3.0, 3.0)
    x = {"a_mm": np.array([1.0, 2.0, 4.5, 8.0]), "c_mm": np.full(4, 3.0)}
    st = np.array([[HOLDS, HOLDS], [HOLDS, UNDECIDED], [UNDECIDED, HOLDS], [FAILS, HOLDS]])
    s = [Statement("s1", (1.0, 1.0)), Statement("s2", (1.0, 1.0))]
    return Region([A, c], s, x, st, 0.9, {"a_mm": (1.0, 0.5), "c_mm": (0.0, 0.0)}, {"o": 1})


def test_region_points_bounds_and_description():
    r = _hand_region()
    assert r.accepted.tolist() == [True, True, True, False]
    assert r.confirmed.tolist() == [True, False, False, False]
    assert r.points()["a_mm"].tolist() == [1.0, 2.0, 4.5]
    m = np.array([False, True, False, True])
    assert r.points(m)["a_mm"].tolist() == [2.0, 8.0]
    # the fixed input is left out; four significant digits only when asked for
    assert r.describe() == "a_mm 1-4.5"
    assert r.describe(m) == "a_mm 2-8"
    assert r.describe(np.array([False, True, False, False])) == "a_mm 2"  # one value: no range
    assert r.describe(np.zeros(4, bool)) == "nowhere"
    r.x["a_mm"][:] = [1.23456, 2.0, 4.5, 8.0]
    assert r.describe() == "a_mm 1.23-4.5" and r.describe(digits=4) == "a_mm 1.235-4.5"
    r2 = Region([A, B], r.statements, {"a_mm": r.x["a_mm"], "b_mm": 10 - r.x["a_mm"]},
                r.status, 0.9, {})  # fmt: skip
    assert r2.describe() == "a_mm 1.23-4.5, b_mm 5.5-8.77"


def test_without_keeps_the_points_and_sets_statements_aside():
    r = _hand_region()
    w = r.without(["s1"])
    assert [s.id for s in w.statements] == ["s2"]
    assert w.status.tolist() == [[HOLDS], [UNDECIDED], [HOLDS], [HOLDS]]
    assert w.accepted.tolist() == [True] * 4
    assert w.inputs == r.inputs and w.x is r.x and w.level == 0.9
    assert w.resolution == r.resolution and w.outputs == {"o": 1}


def test_explore_validates_its_arguments():
    args = ([A], [], lambda x: {}, np.random.default_rng(0))
    bad = [dict(n=1), dict(rounds=-1), dict(per_point=0), dict(level=0.0), dict(level=1.0),
           dict(level=1.5)]  # fmt: skip
    for kw in bad:
        with pytest.raises(ValueError, match=r"^explore: need n >= 2, rounds >= 0, per_point"):
            explore(*args, **kw)
    r = explore(*args, n=2, rounds=1, per_point=1, level=0.5)
    assert r.n >= 2 and r.level == 0.5


def test_explore_design_resolution_and_defaults():
    c = Input("c_mm", 2.0, 6.0)  # a range that does not start at 0
    f = Input("f_mm", 3.0, 3.0)  # fixed

    def m(x):
        return {"c": x["c_mm"], "f": x["f_mm"]}

    st = [Statement("c", (3.0, 5.0), "range")]
    r = explore([c, f], st, m, np.random.default_rng(2), rounds=0)
    # n = 1024 points by default, one free input: spacing (6 - 2) / 1024
    assert r.n == 1024 and r.level == 0.95
    assert r.resolution == {"c_mm": (4 / 1024, 4 / 1024), "f_mm": (0.0, 0.0)}
    assert r.x["f_mm"].tolist() == [3.0] * 1024
    assert 2.0 <= r.x["c_mm"].min() < 2.0 + 4 / 1024 and 6.0 - 4 / 1024 < r.x["c_mm"].max() < 6.0
    # a scrambled design: another seed gives other points, the same seed the same ones
    r2 = explore([c, f], st, m, np.random.default_rng(3), rounds=0)
    assert not np.array_equal(r.x["c_mm"], r2.x["c_mm"])
    r3 = explore([c, f], st, m, np.random.default_rng(2), rounds=0)
    assert np.array_equal(r.x["c_mm"], r3.x["c_mm"])
    # refinement halves the spacing per round at the boundary (c = 3 and c = 5)
    r = explore([c, f], st, m, np.random.default_rng(2))
    assert r.resolution["c_mm"] == (4 / 1024, 4 / 1024 / 8)
    d = explore([c, f], st, m, np.random.default_rng(2), n=1024, rounds=3, per_point=4)
    assert np.array_equal(d.x["c_mm"], r.x["c_mm"])


def test_explore_caps_the_new_points_per_round():
    r = explore([A, B], [SUM, A_UP], model, np.random.default_rng(1), n=64, rounds=2,
                per_point=2, max_new=10)  # fmt: skip
    assert r.n == 64 + 2 * 10  # 5 boundary points a round, 2 new points each


def test_explore_with_one_plate_evidence_and_dict_outputs():
    """A one-plate p decides at the region's level in the design and in every refinement round;
    a dict output with p = None is carried through the rounds."""

    def m(x):
        a = x["a_mm"]
        p = np.where(a < 3.0, 0.01, 0.5)  # a plate as extreme as the paper's is rare for a < 3
        return {
            "one": {"value": a, "low": a - 0.1, "high": a + 0.1, "p": p},
            "b": {"value": a, "low": a, "high": a, "p": None},
        }

    one = Statement("one", (0.0, 0.0), "lower")
    r = explore([A, B], [one], m, np.random.default_rng(4), n=128, rounds=2,
                refine_on=[Statement("b", (6.0, 6.0), "lower")])  # fmt: skip
    a = r.x["a_mm"]
    assert np.array_equal(r.accepted, a >= 3.0)
    assert r.n > 128 and r.outputs["b"]["p"] is None
    assert r.outputs["b"]["value"].tolist() == a.tolist()
    # the prediction's boundary (a = 6) is refined like the region's (a = 3)
    near = lambda t: np.sum(np.abs(a[128:] - t) < 0.2)  # noqa: E731
    assert near(3.0) > 0 and near(6.0) > 0
    assert np.array_equal(outcomes(r, Statement("b", (6.0, 6.0), "lower")) == HOLDS, a >= 6)


def test_outcomes_over_a_region_use_its_level():
    r = _hand_region()
    ev = {"low": [1.2] * 4, "high": [1.5] * 4, "p": [0.05, 0.09, 0.1, 0.2]}
    assert outcomes(r, Z, ev).tolist() == [FAILS, FAILS, HOLDS, HOLDS]  # level 0.9: p < 0.1


def test_region_verdict_of_a_one_point_region():
    # one point decides nothing over the region (the sample-size rule, test_region_rule.py)
    assert region_verdict(1, 1, 0) == "inconclusive" == region_verdict(1, 0, 1)
    assert region_verdict(1, 0, 0) == "undecidable"


def test_statement_of_a_book_row_keeps_its_words():
    b = ClaimBook(
        [
            {
                "id": "q",
                "kind": "prediction",
                "source": "p. 3",
                "paper": "about 2",
                "form": "value",
                "ref": 2.0,
                "decimals": 0,
                "tol": 0.25,
            }
        ],  # fmt: skip
        [],
    )
    s = statement_of(b, "q")
    assert s == Statement("q", (2.0, 2.0), "value", 0, 0.25, "about 2", "p. 3")
    assert s.zone == (1.25, 2.75) and statement_of(b, "q", "upper").zone == (-math.inf, 2.75)


def test_missing_numbers_in_the_evidence_leave_a_point_undecided():
    ev = interval_from_se([1.5, 1.5], [0.1, None])  # no standard error: no interval
    assert np.isnan(ev["low"][1]) and np.isnan(ev["high"][1])
    assert status(Z, ev, 2).tolist() == [HOLDS, UNDECIDED]
    assert status(Z, {"low": [None, 1.2], "high": [0.5, 1.5]}, 2).tolist() == [UNDECIDED, HOLDS]
    assert status(Z, {"low": [1.2, 1.2], "high": [1.5, None]}, 2).tolist() == [HOLDS, UNDECIDED]


def _plate_model(x):
    a = x["a_mm"]
    p = np.where(a < 3.0, 0.01, np.where(a < 5.0, 0.07, 0.5))
    return {"one": {"value": a, "low": a - 0.1, "high": a + 0.1, "p": p}}


def test_explore_decides_a_one_plate_p_at_its_level_in_every_round():
    one = Statement("one", (0.0, 0.0), "lower")
    for level, edge in ((0.95, 3.0), (0.90, 5.0)):  # p = 0.07 passes at 95 %, fails at 90 %
        r = explore([A, B], [one], _plate_model, np.random.default_rng(4), n=128, rounds=2,
                    level=level, refine_on=[one])  # fmt: skip
        assert r.n > 128
        assert np.array_equal(r.accepted, r.x["a_mm"] >= edge), level
        # as a prediction refined on (no statements: the whole box is the region), the
        # boundary refined is where it starts to hold at the region's level
        r = explore([A, B], [], _plate_model, np.random.default_rng(4), n=128, rounds=1,
                    level=level, refine_on=[one])  # fmt: skip
        a, h = r.x["a_mm"][128:], 128 ** (-1 / 2)
        assert a.size > 0 and np.all(np.abs(a - edge) <= 10 * (1.5 * h * math.sqrt(2) + h / 2))


def test_refinement_tells_apart_the_predictions_it_refines_on():
    """Three predictions over a region that is the whole box: a <= 5, a >= 5 (each point
    satisfies one or both) and b >= 5. The boundaries a = 5 (between the first two) and b = 5
    (the third's) are refined, and nothing else."""

    def m(x):
        return {"lt": x["a_mm"], "ge": x["a_mm"], "b": x["b_mm"]}

    preds = [Statement("lt", (5.0, 5.0), "upper"), Statement("ge", (5.0, 5.0), "lower")]
    preds.append(Statement("b", (5.0, 5.0), "lower"))
    r = explore([A, B], [], m, np.random.default_rng(6), n=256, rounds=1, refine_on=preds)
    a, b, h = r.x["a_mm"][256:], r.x["b_mm"][256:], 256 ** (-1 / 2)
    near_a, near_b = (np.abs(v - 5.0) <= 10 * (1.5 * h * math.sqrt(2) + h / 2) for v in (a, b))
    assert np.all(near_a | near_b)
    assert np.any(near_a & ~near_b) and np.any(near_b & ~near_a)


def test_refinement_stays_within_its_radius_of_the_boundary():
    """Round one refines points with a neighbour of the other label within 1.5 h sqrt(d) (unit
    cube, h = n^(-1/d)) and jitters them by at most h/2: every new point lies within
    1.5 h sqrt(d) + h/2 of the boundary a = 4.5 (10 mm per unit)."""
    r = explore([A, B], [A_UP], model, np.random.default_rng(7), n=1024, rounds=1)
    h = 1024 ** (-1 / 2)
    new = r.x["a_mm"][1024:]
    assert new.size > 0
    assert np.max(np.abs(new - 4.5)) <= 10 * (1.5 * h * math.sqrt(2) + h / 2)


def test_the_cap_on_new_points_applies_only_when_exceeded():
    kw = dict(n=256, rounds=1, per_point=2)
    free = explore([A, B], [SUM, A_UP], model, np.random.default_rng(8), max_new=10**6, **kw)
    n_new = free.n - 256
    assert n_new > 0
    at = explore([A, B], [SUM, A_UP], model, np.random.default_rng(8), max_new=n_new, **kw)
    assert np.array_equal(at.x["a_mm"], free.x["a_mm"])


def test_a_region_of_fixed_inputs_is_not_refined():
    """With every input fixed there is nothing to refine, even when a Monte-Carlo model's
    statuses differ between the (identical) points."""
    c = Input("c_mm", 3.0, 3.0)

    def noisy(x):
        return {"z": np.resize([1.5, 9.0], len(x["c_mm"]))}  # holds, fails, holds, ...

    r = explore([c], [Z], noisy, np.random.default_rng(0), n=8, rounds=2)
    assert r.n == 8 and r.accepted.tolist() == [True, False] * 4
    assert r.resolution == {"c_mm": (0.0, 0.0)}
