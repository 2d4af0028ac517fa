"""`sim check` lists a study's resolved config as TOML a user can copy into a study file
(sim/mc/toml_text.py): it wrote Python's repr (``False``, ``[{'name': 'A', ...}]``), which
TOML refuses. Every shipped study's listing parses, and run through `sim check` again as a
study file gives the same listing (every value came back as it was)."""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from sim.cli import main
from sim.mc.toml_text import toml_value

ROOT = Path(__file__).resolve().parents[1]
STUDIES = sorted((ROOT / "studies").glob("*.toml"))


@pytest.mark.parametrize("study", STUDIES, ids=lambda p: p.stem)
def test_the_check_listing_is_toml_that_gives_the_same_config_back(study, tmp_path, capsys):
    assert main(["check", str(study)]) == 0
    listing = capsys.readouterr().out
    tomllib.loads(listing)  # raises on Python's False or {'k': v}
    again = tmp_path / study.name
    again.write_text(listing)
    assert main(["check", str(again)]) == 0
    assert capsys.readouterr().out == listing


@pytest.mark.parametrize(
    "value",
    [
        True,
        False,
        0,
        -(2**63),
        1.5,
        -0.0,
        1e300,
        5e-324,
        math.inf,
        -math.inf,
        "plain",
        "quote \" apostrophe ' backslash \\ newline \n tab \t bell \x07 del \x7f é",
        [],
        [1, 2.0, "a"],
        [{"S1.x": 1.0}, {"a b": [1, {"c": True}]}, {}],
    ],
)
def test_a_value_comes_back_from_its_toml_text(value):
    back = tomllib.loads(f"k = {toml_value(value)}")["k"]
    assert back == value and type(back) is type(value)
    if isinstance(value, float):
        assert math.copysign(1, back) == math.copysign(1, value)


def test_numpy_values_are_written_as_the_numbers_they_hold():
    v = {"f": np.float64(1.5), "i": np.int64(-3), "b": np.bool_(True), "a": np.arange(3.0)}
    assert tomllib.loads(f"k = {toml_value(v)}")["k"] == {
        "f": 1.5,
        "i": -3,
        "b": True,
        "a": [0.0, 1.0, 2.0],
    }


def test_nan_and_a_tuple_and_what_toml_cannot_hold():
    assert math.isnan(tomllib.loads(f"k = {toml_value(math.nan)}")["k"])
    assert tomllib.loads(f"k = {toml_value((1, 2))}")["k"] == [1, 2]
    with pytest.raises(TypeError, match="NoneType"):
        toml_value(None)
