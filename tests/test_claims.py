"""The verdict rules of sim.claims.book on constructed cases (issue 11)."""

import math

import numpy as np
import pytest

from sim.claims.book import ClaimBook
from sim.mc.config import ConfigError, StudyError


def book(**spec):
    base = {"id": "t.c", "source": "s", "paper": "p", "kind": "prediction"}
    return ClaimBook([{**base, **spec}], [], "<test>")


def test_value_holds_fails_inconclusive():
    b = book(form="value", ref=0.71, decimals=2, tol=0.01)  # zone 0.695-0.725
    assert b.score("t.c", 0.706, (0.696, 0.718))["verdict"] == "holds"
    b = book(form="value", ref=0.71, decimals=2, tol=0.01)
    assert b.score("t.c", 0.80, (0.78, 0.82))["verdict"] == "fails"
    b = book(form="value", ref=0.71, decimals=2, tol=0.01)
    r = b.score("t.c", 0.72, (0.70, 0.74))
    assert r["verdict"] == "inconclusive" and r["holds"] is None
    assert math.isclose(r["zone_low"], 0.695) and math.isclose(r["zone_high"], 0.725)


def test_vacuous_interval_is_never_a_hold():
    # a share whose 95 % interval is [0, 1] covers every admissible value
    b = book(form="share", ref=0.8, decimals=1, tol=0.05)
    assert b.score("t.c", 0.5, (0.0, 1.0))["verdict"] == "inconclusive"


def test_range_contained_and_not():
    b = book(form="range", ref=[5, 15], tol=0)
    r = b.score("t.c", elems=(np.array([7.0, 12.0]), np.array([8.5, 14.0])))
    assert r["verdict"] == "holds" and r["value"] == 7.75 and r["value_high"] == 13.0
    b = book(form="range", ref=[5, 15], tol=0)
    assert (
        b.score("t.c", elems=(np.array([7.0, 15.5]), np.array([8.0, 16.0])))["verdict"] == "fails"
    )
    b = book(form="range", ref=[5, 15], tol=0)
    assert (
        b.score("t.c", elems=(np.array([7.0, 14.0]), np.array([8.0, 16.0])))["verdict"]
        == "inconclusive"
    )


def test_bounds():
    b = book(form="upper", ref=2.0, tol=0)
    assert b.score("t.c", 1.0, (0.5, 1.5))["verdict"] == "holds"
    b = book(form="upper", ref=2.0, tol=0)
    assert b.score("t.c", 11.5, (10.7, 12.3))["verdict"] == "fails"
    b = book(form="lower", ref=2.0, tol=0)
    assert b.score("t.c", 2.1, (1.9, 2.3))["verdict"] == "inconclusive"


def test_exact_is_never_inconclusive():
    b = book(form="value", ref=43, tol=0)
    assert b.score("t.c", 43.0, interval="exact")["verdict"] == "holds"
    b = book(form="value", ref=43, tol=0)
    assert b.score("t.c", 44.0, interval="exact")["verdict"] == "fails"


def test_erratum_is_a_failing_paper_check():
    b = book(kind="paper-check", form="value", ref=0.999978669, decimals=9, tol=0)
    r = b.score("t.c", 0.999978663, interval="exact", note="recomputed from A-F")
    assert r["verdict"] == "erratum" and r["holds"] is False
    b = book(kind="paper-check", form="value", ref=0.999978669, decimals=9, tol=0)
    assert b.score("t.c", 0.9999786692, interval="exact")["verdict"] == "holds"


def test_one_plate_statistic():
    rng = np.random.default_rng(1)
    x = rng.normal(1.6, 0.15, 4000)
    b = book(form="one-plate", ref=1.6, decimals=1, tol=0.5)
    r = b.score("t.c", samples=x)
    assert r["verdict"] == "holds" and 0.9 < r["p_plate"] <= 1.0
    b = book(form="one-plate", ref=1.6, decimals=1, tol=0.5)
    r = b.score("t.c", samples=x + 1.0)  # the paper's plate is far in the tail
    assert r["verdict"] == "fails" and r["p_plate"] < 0.05
    b = book(form="one-plate", ref=1.6, decimals=1, tol=0.05)  # plates too spread to decide
    assert b.score("t.c", samples=x)["verdict"] == "inconclusive"


def test_inputs_and_self_checks_are_classed_apart():
    b = book(kind="input", form="value", ref=0.85, decimals=2, tol=0.01)
    r = b.score("t.c", 0.80, (0.79, 0.81))
    assert r["verdict"] == "input" and r["outcome"] == "fails"
    b = book(kind="self-check", form="value", ref=1.0, tol=0.01)
    r = b.score("t.c", 1.0, (0.998, 1.002))
    assert r["verdict"] == "self-check" and r["outcome"] == "holds"


def test_not_finite_is_an_error_not_a_verdict():
    b = book(form="value", ref=1.0, tol=0.1)
    with pytest.raises(StudyError, match="not finite"):
        b.score("t.c", math.nan, (0.0, 1.0))


def test_book_validation_names_the_key():
    with pytest.raises(ConfigError, match="claim.tol"):
        book(form="value", ref=1.0)
    with pytest.raises(ConfigError, match="claim.kind"):
        book(kind="predicted")
    with pytest.raises(ConfigError, match="claim.form"):
        book(form="roughly", ref=1.0, tol=0)
    with pytest.raises(ConfigError, match="claim.ref"):
        book(form="range", ref=1.0, tol=0)
    with pytest.raises(ConfigError, match="claim.colour"):
        book(colour="red")


def test_every_declared_claim_must_be_scored():
    b = ClaimBook(
        [
            {"id": "a", "source": "s", "paper": "p", "kind": "finding"},
            {"id": "b", "source": "s", "paper": "p", "kind": "finding"},
        ],
        [],
    )
    b.score("a", 1.0, interval="exact")
    with pytest.raises(ValueError, match="does not score: b"):
        b.check_complete()


def test_not_comparable_rows_are_written_with_no_number(tmp_path):
    import pyarrow.parquet as pq

    from sim.claims.book import write_claims

    b = ClaimBook(
        [
            {
                "id": "t.nc",
                "source": "s",
                "paper": "p",
                "kind": "not comparable",
                "why": "the setup is not printed",
            },
            {
                "id": "t.v",
                "source": "s",
                "paper": "p",
                "kind": "prediction",
                "form": "value",
                "ref": 1.0,
                "tol": 0.1,
            },
        ],
        [],
        "<test>",
    )
    rows = [b.not_comparable("t.nc"), b.score("t.v", 1.0, (0.95, 1.05))]
    write_claims(tmp_path / "claims.parquet", rows, {"study": "t"}, b)
    t = pq.read_table(tmp_path / "claims.parquet").to_pydict()
    assert t["value"][0] is None and t["verdict"] == ["not comparable", "holds"]
    assert t["note"][0] == "the setup is not printed"


def test_a_bound_is_written_with_its_open_side_null(tmp_path):
    import pyarrow.parquet as pq

    from sim.claims.book import write_claims
    from sim.report.markdown import claims_markdown

    b = book(form="upper", ref=2.0, tol=0)
    write_claims(tmp_path / "claims.parquet", [b.score("t.c", 1.0, (0.5, 1.5))], {"study": "t"}, b)
    t = pq.read_table(tmp_path / "claims.parquet").to_pydict()
    assert t["zone_low"] == [None] and t["zone_high"] == [2.0] and t["verdict"] == ["holds"]
    assert "≤ 2" in claims_markdown(tmp_path / "claims.parquet")


def test_claims_table_declares_how_each_column_is_compared(tmp_path):
    """make verify compares a claims table by the rule declared with each column (exact for
    the verdicts, within the interval for the values): write_claims must declare them."""
    from sim.claims.book import CLAIM_TOLERANCES, write_claims
    from sim.mc.storage import read_tolerances

    b = book(form="value", ref=1.0, tol=0.1)
    write_claims(tmp_path / "claims.parquet", [b.score("t.c", 1.0, (0.95, 1.05))], {}, b)
    tol = read_tolerances(tmp_path / "claims.parquet")
    assert set(tol) == set(CLAIM_TOLERANCES) and tol["verdict"]["kind"] == "exact"
    assert tol["value"]["kind"] == "mc"


def test_one_plate_claim_given_an_exact_value_is_decided_as_a_value():
    b = book(kind="input", form="one-plate", ref=1.7, decimals=1, tol=0)
    r = b.score("t.c", 1.7, interval="exact")
    assert r["verdict"] == "input" and r["outcome"] == "holds" and r["p_plate"] != r["p_plate"]
