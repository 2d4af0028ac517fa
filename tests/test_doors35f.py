"""Fuzz, seeds 3501.. and the doors fuzzer's new seeds (brief F35), and F33's left items; one
case each, each failed on the code before its fix.

F33's left items:

* An empty key in a table, ``[plate] "" = 5``, was named ``plate.:`` (``plate.: unknown key``),
  a key no one wrote; a dotted key with an empty part is now named part by part, that part
  as ``""`` (``plate."": unknown key``) (:func:`sim.mc.message_text.key_text`).
* ``--set "trials\\u00a0=5"`` (a no-break space before the ``=``; or at the start of the key,
  an ideographic space) was read as ``trials``: the key was stripped of every white space
  Python knows, where TOML strips only spaces and tabs. Such a key is now unknown and named
  with its character (``"trials\\u00a0": unknown key (did you mean trials?)``); a value so
  padded (``trials=\\u00a05``) is refused as the text it is, as the same line in a file is.
* A key given twice in a study file was refused in tomllib's words, ``Cannot overwrite a
  value (at line 3, column 11)``, naming no key, or with a Python tuple, ``Cannot declare
  ('plate',) twice``. The key is now named (``trials is given twice (at line 3, column
  11)``), and when the two differ in kind, how (``plate is given twice (a value, then a
  table)``) (:mod:`sim.mc.toml_twice`).

Found with the fuzzer's new mutation kinds, EDGE values (tests/fuzz_edges.py) and SHAPE
(tests/fuzz_shapes.py):

* A float for an integer key from 2**53 on (``seed = 9007199254740993.0``; ``--seed``, the
  API) was taken as the integer the double holds, ``9007199254740992``: silently another
  seed. It is now refused (``seed: must be an integer (got 9007199254740992.0, a float: from
  2**53 = 9007199254740992 on, a float is not exact to the unit; ...)``).
* A Brown plate's grid spacing below 1e-9 mm (``plate.spacing_mm = 1e-12``, a subnormal) was
  refused as ``plate.grid: duplicate points``, naming the key not changed; it now names
  ``plate.spacing_mm``.
* A network grid's spacing near the largest double (``spacing_mm = 1.7976931348623157e308``)
  made its points inf - inf = NaN, which passed every check to ``LinAlgError: SVD did not
  converge`` (exit 2, no key); a random set's half extent so large was ``OverflowError: high
  - low range exceeds valid bounds``; a point's ``x_m = 1e306`` was "the network spans inf
  km". Each now names its key (``network.grids[0].spacing_mm: 1.79769e+308 mm puts points
  beyond the largest 64-bit float``).
* A study's name given as a table or an array (``study = { name = "brown_table1" }``,
  ``[study]``, ``[[study]]``) was ``study: missing: the file must say which study it is`` (the
  table flattened to ``study.name``), or ``unknown study [{'name': 'x'}]`` in Python's words;
  it is now ``study: must name the study as a string, study = "..." (got a table)``.
* A table header below an inline array (``[network.points.extra]`` after ``points = [ ... ]``)
  was tomllib's ``Cannot declare ('network', 'points', 'extra') twice``; it is now
  ``network.points is given twice (an array of tables, then a table)``.
* A network grid too large by its ``ny`` (``nx = 5, ny = 900000000``) was refused naming
  ``network.grids[0].nx``; it now names the larger side.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import sim
from sim.cli import main
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parent.parent
TABLE1 = str(ROOT / "studies" / "brown_table1.toml")
NET = """study = "network"
trials = 40
chunk = 2
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" },
           { name = "P", x_mm = 150.0, y_mm = 120.0 } ]
generate = [ { kind = "distance", from = ["A", "B"], to = "*", sigma_mm = 0.002 } ]
"""


def _check(tmp_path, capsys, text: str, *needles: str, argv=()) -> str:
    f = tmp_path / "s.toml"
    f.write_text(text)
    return one_line(capsys, main(["check", str(f), *argv]), *needles, prefix=SIM_ERROR)


@pytest.mark.parametrize(
    "text, shown",
    [
        ('[plate]\n"" = 5\n', 'plate."": unknown key (did you mean plate.grid?)'),
        ('plate."" = 5\n', 'plate."": unknown key'),
        ('[plate.""]\ngrid = 5\n', 'plate."".grid: unknown key'),
    ],
)
def test_an_empty_key_in_a_table_is_named_readably(tmp_path, capsys, text, shown):
    line = _check(tmp_path, capsys, 'study = "brown_table1"\n' + text)
    assert line.startswith(SIM_ERROR + shown), line
    with pytest.raises(sim.ConfigError) as e:
        sim.load(tmp_path / "s.toml")
    assert str(e.value).startswith(shown), e.value


@pytest.mark.parametrize(
    "text, needle",
    [
        ("trials\u00a0=40", '"trials\\u00a0": unknown key (did you mean trials?)'),
        ("\u3000trials=40", '"\\u3000trials": unknown key'),
        ("trials=\u00a040", "trials: must be an integer (got the text '\\xa040': write 40)"),
    ],
)
def test_a_set_with_a_no_break_space_is_not_read_as_the_key(capsys, text, needle):
    one_line(capsys, main(["check", TABLE1, "--set", text]), needle, prefix=SIM_ERROR)


@pytest.mark.parametrize(
    "text, needle",
    [
        ("trials = 40\ntrials = 60\n", "trials is given twice (at line 3, column 12)"),
        ("[plate]\ngrid = 5\n[plate]\ngrid = 6\n", "plate is given twice (at line 4,"),
        ("[plate]\ngrid = 5\ngrid = 6\n", "plate.grid is given twice (at line 4,"),
        ("[plate]\r\ngrid = 5\r\n[plate]\r\n", "plate is given twice (at line 4,"),
        ("plate = 5\n[plate]\ngrid = 5\n", "plate is given twice (a value, then a table)"),
        ("[[plate]]\ngrid = 5\n[plate]\n", "plate is given twice (an array of tables, then a"),
        ('"trials " = 1\n"trials " = 2\n', '"trials " is given twice'),
        ("plate = {grid = 5, grid = 6}\n", "plate.grid is given twice in an inline table"),
        ("trials = [\n 1,\n 2]\ntrials = [\n 3\n]\n", "trials is given twice (at line 7,"),
    ],
)
def test_a_key_given_twice_is_named(tmp_path, capsys, text, needle):
    line = _check(tmp_path, capsys, 'study = "brown_table1"\n' + text, "malformed TOML: ")
    assert needle in line and "Cannot" not in line and "('" not in line, line


def test_a_float_for_an_integer_key_from_2_53_on_is_refused(tmp_path, capsys):
    needle = "seed: must be an integer (got 9007199254740992.0, a float: from 2**53"
    _check(tmp_path, capsys, 'study = "brown_table1"\nseed = 9007199254740993.0\n', needle)
    rc = main(["run", TABLE1, "--out", str(tmp_path / "o"), "--seed", "9007199254740993.0"])
    one_line(capsys, rc, "argument --seed: must be an integer (got 9007199254740992.0")
    with pytest.raises(sim.ConfigError) as e:
        sim.load(TABLE1, seed=9007199254740993.0)
    assert str(e.value).startswith(needle), e.value
    assert sim.load(TABLE1, seed=1e15).config["seed"] == 10**15  # below 2**53: that integer


def test_a_brown_grid_spacing_that_merges_points_is_named(capsys):
    rc = main(["check", TABLE1, "--set", "plate.spacing_mm=1e-12"])
    needle = "plate.spacing_mm: 1e-12 mm puts points of the grid within 1e-09 mm of each other"
    one_line(capsys, rc, needle, prefix=SIM_ERROR)


@pytest.mark.parametrize(
    "old, new, needle",
    [
        (
            '"*", sigma_mm = 0.002 } ]\n',
            '"*", sigma_mm = 0.002 } ]\n'
            'grids = [ { prefix = "G", nx = 3, ny = 3, spacing_mm = 1.7976931348623157e308 } ]\n',
            "network.grids[0].spacing_mm: 1.79769e+308 mm puts points beyond the largest",
        ),
        (
            '"*", sigma_mm = 0.002 } ]\n',
            '"*", sigma_mm = 0.002 } ]\n'
            'random = [ { prefix = "R", n = 3, half_extent_mm = 1.7976931348623157e308 } ]\n',
            "network.random[0].half_extent_mm: 1.79769e+308 mm puts points beyond the largest",
        ),
        (
            "x_mm = 150.0, y_mm = 120.0",
            "x_m = 1e306, y_m = 0.12",
            "network.points[2].x_m: 1e+306 m is beyond the largest 64-bit float in millimetres",
        ),
        (
            '"*", sigma_mm = 0.002 } ]\n',
            '"*", sigma_mm = 0.002 } ]\n'
            'grids = [ { prefix = "G", nx = 5, ny = 900000000, spacing_mm = 1.0 } ]\n',
            "network.grids: a network of about 4,500,000,003 points",
        ),
    ],
)
def test_a_network_length_beyond_a_double_is_named(tmp_path, capsys, old, new, needle):
    assert old in NET
    _check(tmp_path, capsys, NET.replace(old, new), needle)


@pytest.mark.parametrize(
    "text, what",
    [
        ('study = { name = "brown_table1" }\n', "a table"),
        ("[study]\n", "a table"),
        ('[[study]]\nname = "x"\n', "an array"),
    ],
)
def test_a_study_name_given_as_a_table_is_named(tmp_path, capsys, text, what):
    needle = f'study: must name the study as a string, study = "..." (got {what})'
    _check(tmp_path, capsys, text, needle)


def test_a_header_below_an_inline_array_is_named(tmp_path, capsys):
    text = NET + "[network.points.extra]\nx = 1\n"
    line = _check(tmp_path, capsys, text, "network.points is given twice (an array of tables, then")
    assert "Cannot" not in line, line
