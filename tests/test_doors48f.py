"""Issue 26, helper F48: what the fresh fuzz seeds and the sweep-level fuzzer
(tests/fuzz_sweep.py) found.

* An EMPTY TABLE among a sweep's keys (``"datum.kind" = {}`` beside a swept key, or an empty
  ``[sweep.datum]``) was dropped without a word: the sweep ran its other keys' cells as if the
  user had not asked to sweep that key (alone, it was "sweep: is empty", naming no key).
"""

from __future__ import annotations

import pytest
from conftest import TRIANGLE_NETWORK

from sim.cli import main


@pytest.mark.parametrize(
    "table, named",
    [
        ('"reliability.power" = [0.8, 0.9]\n"datum.kind" = {}\n', "sweep.datum.kind"),
        ('"reliability.power" = [0.8, 0.9]\n[sweep.datum]\n', "sweep.datum"),
    ],
)
def test_an_empty_table_in_a_sweep_is_refused_naming_it(tmp_path, capsys, table, named):
    """EMPTY sweep levels: an empty table where a key's levels go was dropped, exit 0 and
    a sweep of the other key only; now one line naming the key, exit 2."""
    f = tmp_path / "s.toml"
    f.write_text(TRIANGLE_NETWORK + "[sweep]\n" + table)
    assert main(["check", str(f)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"sim: error: {named}: is an empty table") and "\n" not in err


RANDOM_NETWORK = """\
study = "network"
trials = 40
chunk = 2
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 1000.0, y_mm = 0.0, role = "fixed" } ]
random = [ { prefix = "R", n = 3, half_extent_mm = 500.0 } ]
generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 0.01 } ]
[sweep]
"""


@pytest.mark.parametrize(
    "levels, cells",
    [
        ("[9007199254740992, 9007199254740993]", [2**53, 2**53 + 1]),
        (
            "{start = 4611686018427387904, stop = 9223372036854775807, step = 2305843009213693952}",
            [2**62, 2**62 + 2**61],
        ),
    ],
)
def test_large_integer_levels_are_read_exactly(tmp_path, capsys, levels, cells):
    """LARGE INTEGER levels of a key that takes them (``network.layout_seed``, up to 2**63 - 1):
    two seeds 2**53 and 2**53 + 1 were refused as "one value twice" (compared as floats), and
    an integer range near 2**63 was made in NumPy's int64, which wrapped its last level
    (beyond ``stop``, as the float count rounded up) to -2**63: refused naming a value the
    user never wrote. Now the levels are the integers written, exactly, and the sweep runs."""
    from sim.mc.sweep import expand, read_sweep
    from sim.studies import load_study

    f = tmp_path / "s.toml"
    f.write_text(RANDOM_NETWORK + f'"network.layout_seed" = {levels}\n')
    assert main(["check", str(f)]) == 0, capsys.readouterr().err
    schema = load_study(f)[0].schema
    got = [c["network.layout_seed"] for c in expand(read_sweep(f, schema), schema)[1]]
    assert got == cells and all(type(x) is int for x in got)
