"""The shared pieces of the study code below the studies' own: the schema constructors
(sim.mc.schema_helpers) equal the Field they abbreviate and validate the same way, and the run
steps (sim.studies.run_steps) equal the runner call they stand for and replace exactly the
predictions' rows by their region verdicts."""

from __future__ import annotations

import numpy as np
import pytest

from sim.claims.book import ClaimBook
from sim.claims.inference import Input, explore
from sim.mc.config import ConfigError, Field, validate
from sim.mc.runner import run_chunks
from sim.mc.schema_helpers import count, counts, level, positive, real, reals, require
from sim.studies.run_steps import over_region, run_part, spread_note


def test_each_constructor_is_the_field_spelled_out():
    assert count(5, "d", lo=3, hi=15, input=True) == Field(5, "int", "d", lo=3, hi=15, input=True)
    assert real(1.0, "d", lo=0.0, hi=45.0, unit="deg") == Field(
        1.0, "float", "d", lo=0.0, hi=45.0, unit="deg"
    )
    assert real(2.0, "d", hi=5.0) == Field(2.0, "float", "d", hi=5.0)
    assert positive(1.5, "d", hi=50.0, unit="um", input=True) == Field(
        1.5, "float", "d", lo=0.0, lo_open=True, hi=50.0, input=True, unit="um"
    )
    assert level(0.05, "d") == Field(0.05, "float", "d", lo=0.0, lo_open=True, hi=0.5)
    assert reals([1.0], "d", lo=0.0, lo_open=True, unit="um") == Field(
        [1.0], "list[float]", "d", lo=0.0, lo_open=True, min_len=1, unit="um"
    )
    assert reals([], "d", min_len=0) == Field([], "list[float]", "d")
    assert counts([3, 4], "d", lo=2, hi=20) == Field(
        [3, 4], "list[int]", "d", lo=2, hi=20, min_len=1
    )


SCHEMA = {
    "a.n": count(5, "points", lo=3, hi=15),
    "a.sigma_um": positive(1.0, "sigma", hi=50.0, unit="um"),
    "a.alpha": level(0.05, "level"),
    "a.list_mm": reals([1.0, 2.0], "values", lo=0.0, hi=10.0, unit="mm"),
    "a.cells": counts([3], "cells", lo=2, hi=20),
}


@pytest.mark.parametrize(
    "key, value, words",
    [
        ("a.n", 2, ">= 3"),
        ("a.n", 16, "<= 15"),
        ("a.n", 4.5, "integer"),
        ("a.sigma_um", 0.0, "> 0"),
        ("a.sigma_um", 50.5, "<= 50"),
        ("a.alpha", 0.0, "> 0"),
        ("a.alpha", 0.6, "<= 0.5"),
        ("a.list_mm", [], "at least 1"),
        ("a.list_mm", [1.0, 11.0], "<= 10"),
        ("a.cells", [1], ">= 2"),
    ],
)
def test_a_value_out_of_its_kinds_range_is_refused_naming_the_key(key, value, words):
    with pytest.raises(ConfigError) as e:
        validate({key: value}, SCHEMA)
    assert str(e.value).startswith(key) and words in str(e.value)


def test_values_at_the_edges_of_each_kind_pass():
    cfg = validate(
        {"a.n": 15, "a.sigma_um": 1e-9, "a.alpha": 0.5, "a.list_mm": [0.0, 10.0], "a.cells": [20]},
        SCHEMA,
    )
    assert cfg["a.n"] == 15 and cfg["a.alpha"] == 0.5 and cfg["a.list_mm"] == [0.0, 10.0]


def test_require_is_one_line_naming_the_key_only_when_the_rule_fails():
    require(True, "a.n", "never raised")
    with pytest.raises(ConfigError, match=r"^a\.n: needs at least 4 points$"):
        require(2 > 3, "a.n", "needs at least 4 points")


def _fn(rng, n):
    return {"x": rng.normal(size=n), "n": np.full(n, n)}


def test_run_part_is_the_runner_with_the_configs_trials_seed_and_chunk():
    cfg = {"trials": 50, "seed": 11, "chunk": 10}
    got = run_part(cfg, None, _fn, part=3, label="t", quiet=True)
    want = run_chunks(_fn, 50, 11, 10, part=3, quiet=True)
    assert np.array_equal(got["x"], want["x"]) and got["x"].size == 50
    other = run_part(cfg, None, _fn, part=4, label="t", trials=30, quiet=True)
    assert other["x"].size == 30 and not np.array_equal(other["x"], got["x"][:30])
    # a part with its own chunk size is the runner at that chunk (its chunks' streams)
    small = run_part(cfg, None, _fn, part=3, label="t", quiet=True, chunk=5)
    assert np.array_equal(small["x"], run_chunks(_fn, 50, 11, 5, part=3, quiet=True)["x"])
    assert set(small["n"]) == {5} and not np.array_equal(small["x"], got["x"])


def test_over_region_replaces_the_predictions_rows_only_and_keeps_their_order():
    specs = [
        {"id": "p", "source": "s", "paper": "p", "kind": "prediction", "form": "upper"}
        | {"ref": 0.3, "tol": 0.0},
        {"id": "q", "source": "s", "paper": "q", "kind": "finding"},
    ]
    book = ClaimBook([dict(s) for s in specs], [], "<test>")
    rows = [book.score("q", 1.0, interval="exact"), book.score("p", 0.2, (0.1, 0.25))]
    reg = explore(
        [Input("x_mm", 0.0, 1.0)],
        [],
        lambda x: {"p": x["x_mm"]},
        np.random.default_rng(1),
        n=64,
        rounds=0,
    )
    new = over_region(book, reg, ["p"], rows, spread_note("calibrations"))
    assert [r["claim"] for r in new] == ["q", "p"]
    assert new[0] is rows[0]
    assert new[1]["interval"] == "region" and new[1]["verdict"] == "depends"
    assert "median 0.2, 95 % of calibrations 0.1-0.25" in new[1]["note"]
