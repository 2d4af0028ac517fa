"""A fresh reading of session 36's merges (sweep doors36r): each class was found through a
real door and fixed; each test fails on the code before its fix:

* the memory check of a network before it is built (``fits_estimate``, new this session)
  counted a grid's ``nx = "3000"`` (text, not a number) as 3000 and, the estimate over the
  limit, named the key of the most points by multiplying the raw values: ``"3000" * 3000`` a
  string, summed with 0, a TypeError ("sim: internal error", exit 3) in ``sim check``,
  ``sim run`` and ``sim.load``; a random set's ``n = "90000000"`` the same. The estimate is
  now left to the build when a count is no number, which names the field ("must be a
  finite number (got '3000')"). A grid of ``nx = -3000, ny = -3000`` was refused as "a
  network of about 9,000,000 points" (the product of two negative sides): it is now "nx:
  must be >= 1".
* a study file giving a key twice names it ("trials is given twice (at line 4, column 13)",
  toml_twice, new this session), except when the second is the file's last line with no line
  break after it (an editor that writes none): tomllib says "(at end of document)", which the
  reading did not match, and the line was tomllib's "Cannot overwrite a value (at end of
  document)", no key named. It is named now, with its line.
"""

from __future__ import annotations

import pytest
from oneline import SIM_ERROR, one_line

import sim
from sim.cli import main

#: a network whose declared size is far over the 8 GiB default limit, a count given as text
BIG = """study = "network"
trials = 1000
chunk = 50
seed = 1

[network]
name = "big"
{records}
generate = [ {{ kind = "dx", from = "G*", to = "G*", nearest = 4, sigma_mm = 0.002 }} ]

[datum]
kind = "fixed"
"""
GRID = 'grids = [ { prefix = "G", nx = "3000", ny = 3000, spacing_mm = 10.0, role = "observed", sigma_mm = 0.0012 } ]'
NEGATIVE = GRID.replace('nx = "3000", ny = 3000', "nx = -3000, ny = -3000")
RANDOM = 'random = [ { prefix = "G", n = "90000000", half_extent_mm = 100.0, role = "observed", sigma_mm = 0.0012 } ]'


@pytest.mark.parametrize(
    ("records", "field", "why"),
    [
        (GRID, "network.grids[0].nx", "number"),
        (RANDOM, "network.random[0].n", "number"),
        (NEGATIVE, "network.grids[0].nx", ">= 1"),
    ],
)
def test_a_count_given_as_text_in_a_large_network_is_named(
    capsys, tmp_path, monkeypatch, records, field, why
):
    monkeypatch.delenv("SIM_MAX_MEMORY_GB", raising=False)
    path = tmp_path / "big.toml"
    path.write_text(BIG.format(records=records), encoding="utf-8")
    one_line(capsys, main(["check", str(path)]), field, why, prefix=SIM_ERROR)
    with pytest.raises(sim.ConfigError, match=field.replace("[", r"\[").replace("]", r"\]")):
        sim.load(path)


def test_a_key_given_twice_on_the_last_line_without_a_line_break_is_named(capsys, tmp_path):
    path = tmp_path / "twice.toml"
    path.write_text('study = "brown"\ntrials = 400\nseed = 3\ntrials = 500', encoding="utf-8")
    one_line(
        capsys, main(["check", str(path)]), "trials is given twice (at line 4", prefix=SIM_ERROR
    )
    with pytest.raises(sim.ConfigError, match="trials is given twice"):
        sim.load(path)
