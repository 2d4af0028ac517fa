"""The bridge from claim books to consistent regions (sim.claims.book_region), the region
declarations of the four studies (Wolf, Salsig, grid plates, Agnard), and Wolf's joint Table 2
test (Holm)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sim.claims.book import ClaimBook
from sim.claims.book_region import load_declaration, plate_ref, region_rows, sample_evidence
from sim.claims.inference import FAILS, HOLDS, UNDECIDED, explore, status
from sim.claims.region import statement_of
from sim.mc.config import ConfigError

BASE = {"source": "s", "paper": "p", "kind": "prediction"}


def _book(*specs) -> ClaimBook:
    return ClaimBook([{**BASE, **s} for s in specs], [], "<test>")


@pytest.mark.parametrize(
    "spec",
    [
        {"id": "v", "form": "value", "ref": 1.5, "decimals": 1, "tol": 0.15},
        {"id": "u", "form": "upper", "ref": 21, "decimals": 0, "tol": 0.0},
        {"id": "l", "form": "lower", "ref": 1.5, "tol": 0.0},
        {"id": "r", "form": "range", "ref": [3.0, 8.3], "decimals": 1, "tol": 0.0},
    ],
)
def test_statement_zone_is_the_books_zone(spec):
    """The inference statement of a claim decides on the zone the claim book writes."""
    book = _book(spec)
    row = book.score(spec["id"], 0.0, (0.0, 0.0), "exact")
    zl, zh = statement_of(book, spec["id"]).zone
    assert zl == row["zone_low"] and zh == row["zone_high"]


def test_sample_evidence_matches_the_books_one_plate_rule():
    """Point by point, the spread and p of ``sample_evidence`` are the book's (same plates)."""
    rng = np.random.default_rng(4)
    x = rng.normal([[1.0], [1.4], [2.5]], 0.2, (3, 400))
    ref = 1.5
    spec = {"id": "a", "form": "one-plate", "ref": ref, "decimals": 1, "tol": 0.1}
    ev = sample_evidence(x, *plate_ref(spec))
    for i in range(3):
        row = _book(spec).score("a", samples=x[i])
        assert math.isclose(ev["p"][i], row["p_plate"], abs_tol=1e-12)
        assert math.isclose(ev["low"][i], row["ci_low"]) and math.isclose(
            ev["high"][i], row["ci_high"]
        )
    st = status(statement_of(_book(spec), "a"), ev, 3)
    # far below the zone with p ~ 0: fails; centred: undecided (one plate spreads wider)
    assert st[0] == FAILS and st[2] == FAILS and st[1] == UNDECIDED


def test_region_rows_depend_on_where_the_prediction_holds():
    """A 1-D input with an analytic answer: the prediction 'x <= 0.3' (exact evidence x)
    holds on [0, 0.3] of the region [0, 1]: depends, and where it holds is reported."""
    book = _book({"id": "p", "form": "upper", "ref": 0.3, "tol": 0.0})
    from sim.claims.inference import Input

    reg = explore(
        [Input("x_mm", 0.0, 1.0)],
        [],
        lambda x: {"p": x["x_mm"]},
        np.random.default_rng(1),
        n=64,
        rounds=0,
    )
    (row,) = region_rows(book, reg, ["p"])
    assert row["verdict"] == "depends" and row["interval"] == "region"
    held = reg.x["x_mm"][status(statement_of(book, "p"), reg.outputs["p"], reg.n) == HOLDS]
    assert held.max() <= 0.3 and "x_mm" in row["note"]


def test_declaration_errors_name_the_key(tmp_path):
    book = _book({"id": "a", "form": "value", "ref": 1.0, "tol": 0.0})
    bad = {
        "constraints = ['nope']\n[inputs.x_mm]\nlow = 0\nhigh = 1\n": "constraints",
        "predictions = [1]\n[inputs.x_mm]\nlow = 0\nhigh = 1\n": "predictions",
        "[inputs.x_mm]\nlow = 0\nhigh = 1\nsize = 3\n": "inputs.x_mm.size",
        "[inputs.x]\nlow = 0\nhigh = 1\n": "inputs.x",
        "[explore]\nn = 1\n[inputs.x_mm]\nlow = 0\nhigh = 1\n": "explore.n",
    }
    for text, key in bad.items():
        p = tmp_path / "r.toml"
        p.write_text(text)
        with pytest.raises(ConfigError) as e:
            load_declaration(p, book)
        assert key in str(e.value)


@pytest.mark.parametrize("study", ["wolf", "salsig", "gridplate", "agnard"])
def test_each_paper_declares_its_region(study):
    """Every declared input has a unit and a reason, every constraint and prediction is a
    claim of the study's book with a printed number, and none is both."""
    import importlib

    claims = importlib.import_module(f"sim.studies.{study}.claims")
    book = claims.load_book()
    path = Path(claims.__file__).with_name("region.toml")
    dec = load_declaration(path, book)
    assert dec.inputs and all(i.why and i.low < i.high for i in dec.inputs)
    cons = {s.id for s in dec.statements}
    assert not cons & set(dec.predictions)
    for p in dec.predictions:  # an input echo decided over the region is kept, counted apart
        assert book.spec(p)["kind"] in ("prediction", "finding", "input")
        assert "ref" in book.spec(p)


def test_holm_adjusts_as_the_step_down_rule():
    from sim.claims.family import holm

    p = np.array([0.01, 0.04, 0.03, 0.005])
    # sorted 0.005, 0.01, 0.03, 0.04 times 4, 3, 2, 1, running maximum
    expect = {3: 0.02, 0: 0.03, 2: 0.06, 1: 0.06}
    adj = holm(p)
    for i, v in expect.items():
        assert math.isclose(adj[i], v)
    assert np.all(holm(np.array([0.9, 0.8])) <= 1.0)
