"""Fuzz, seeds 3301.. and the doors fuzzer's new seeds (brief F33), and F32's left items; one
case each, each failed on the code before its fix.

* A TOML date or time where a key wants a number, a string or a list (``trials =
  1979-05-27``, ``network.name = 07:32:00``, an element of a list, a ``--set`` value, a sweep
  value, a network record's field, the study name) was quoted by Python's ``repr``: ``got
  datetime.date(1979, 5, 27)``, or cut at 60 characters to ``datetime.datetime(1979, 5, 27, 7,
  32, tzinfo=datetime.timezo``. It is now quoted as TOML wrote it (``got 1979-05-27``,
  ``1979-05-27T07:32:00Z``): every date and time a study file or ``--set`` holds is given a
  ``repr`` that is its TOML text when read (:func:`sim.mc.toml_dates.as_written`); an API
  value (``sim.load(..., trials=datetime.date(2020, 1, 1))``) too.
* A quoted key with white space or a character that does not print (``"trials " = 5``, a tab,
  a zero-width space, ``--set "tri als=5"``) was named bare, ``trials : unknown key (did you
  mean trials?)``, the space easy to miss and a zero-width space not seen at all; and the empty
  key ``"" = 5`` was refused as ``unknown key``, naming no key. Such a key is now named in
  double quotes with TOML's escapes (``"trials ": unknown key``, ``"tri\\u200bals"``, ``""``)
  (:func:`sim.mc.message_text.key_text`); ``python -m sim.batch``'s own check of a run
  option's ``--set`` key too.

Found with the fuzzer's new mutation kind, KEY spelling (tests/fuzz_keys.py):

* ``Study = "brown_table1"`` (or ``"study "``, a zero-width space, a Cyrillic letter) was
  refused as ``study: missing: the file must say which study it is``, as if the file had no
  such line (beside a ``study`` line: ``Study: unknown key``, no guess); ``[Sweep]`` (or
  ``SWEEP.trials``) as ``Sweep.trials: unknown key (did you mean trials?)``, a guess that
  sweeps nothing. Each is now named as not that word (``Study: is not study (a study file
  names its study by study = "...", spelt so)``); and ``[sweep] Replicates = 2`` (no guess)
  is answered "did you mean sweep.replicates?".
* A key with a lookalike letter in its table's name (``papеr.positions``, a Cyrillic е) was
  answered "did you mean design.positions or paper.positions?", the key of another table
  first (the same last part); a key that looks the same (another case, white space, a
  lookalike) now comes first (:func:`sim.mc.lookalike.looks`).
* A network record's field spelt in another case or with ``-`` (``Name``, ``x-mm``, ``"name "``)
  was refused as ``network.points[3].Name: unknown field``, alone: the fields are nowhere
  else on that line; it is now answered as an unknown key is ("did you mean name?").
* An option typed with a word processor's dash (``—trials 40``, an em dash for ``--``; an en
  dash, a minus sign) or in capitals with its value (``--TRIALS=40``) was "unrecognized
  arguments" without the guess ``--Trials 40`` gets; it now gets it, naming the dash
  (``did you mean --trials? U+2014 EM DASH is no hyphen``).
* A datum constraint written with a bare dotted key, ``constraints = [ { P.x = 1.0 } ]``
  (TOML reads it as a table ``P`` holding ``x``), was refused as ``'P' is not <point>.x or
  <point>.y of a network point``, naming the point the user wrote with its axis; it now says
  the key needs quotes (``write "P.x" = ... in quotes``). A constraint's key whose axis is
  a lookalike (``"B.у"``, a Cyrillic у) or whose point is (``"А.x"``) was "is not <point>.x
  or <point>.y of a network point", as if it were not written so; it now names the axis
  (and its character) or the point (and the point that looks the same).
"""

from __future__ import annotations

import datetime
from pathlib import Path

import pytest

import sim
from sim.batch import main as batch_main
from sim.cli import main
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parent.parent
NET = """study = "network"
trials = 40
chunk = 2
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" },
           { name = "P", x_mm = 150.0, y_mm = 120.0 } ]
generate = [ { kind = "distance", from = ["A", "B"], to = "P", sigma_mm = 0.002 } ]
"""


@pytest.mark.parametrize(
    "text, argv, needle",
    [
        (
            'study = "brown_table1"\ntrials = 1979-05-27\n',
            [],
            "trials: must be an integer (got 1979-05-27)",
        ),
        (
            'study = "brown_table1"\ntrials = 1979-05-27T07:32:00Z\n',
            [],
            "(got 1979-05-27T07:32:00Z)",
        ),
        (
            'study = "brown_dilution"\n[dilution]\ngrids = [3, 1979-05-27 07:32:00.5]\n',
            [],
            "dilution.grids[1]: must be an integer (got 1979-05-27T07:32:00.500000)",
        ),
        ('study = "brown_table1"\n', ["--set", "trials=07:32:00"], "(got 07:32:00)"),
        (
            'study = "brown_table1"\n[sweep]\ntrials = [1979-05-27T07:32:00-07:00, 40]\n',
            [],
            "(got 1979-05-27T07:32:00-07:00)",
        ),
        (
            NET.replace("x_mm = 150.0", "x_mm = 1979-05-27"),
            [],
            "x_mm: must be a finite number (got 1979-05-27)",
        ),
        ("study = 1979-05-27\n", [], "unknown study 1979-05-27;"),
    ],
)
def test_a_toml_date_is_quoted_as_toml_wrote_it(tmp_path, capsys, text, argv, needle):
    f = tmp_path / "s.toml"
    f.write_text(text)
    rc = main(["check", str(f), *argv])
    line = one_line(capsys, rc, needle, prefix=SIM_ERROR)
    assert "datetime" not in line, line
    if not argv:  # the API reads the file the same way
        with pytest.raises(sim.ConfigError) as e:
            sim.load(f)
        assert needle in str(e.value) and "datetime" not in str(e.value), e.value


def test_an_api_date_is_quoted_as_toml_writes_it():
    with pytest.raises(sim.ConfigError) as e:
        sim.load(ROOT / "studies" / "brown_table1.toml", trials=datetime.date(2020, 1, 1))
    assert "trials: must be an integer (got 2020-01-01)" in str(e.value), e.value


@pytest.mark.parametrize(
    "key, shown",
    [
        ('"trials "', '"trials ": unknown key (did you mean trials?)'),
        ('"trials\\t"', '"trials\\t": unknown key'),
        ('"tri\\u200bals"', '"tri\\u200bals": unknown key'),
        ('""', '"": unknown key'),
        ('plate."grid "', '"plate.grid ": unknown key (did you mean plate.grid?)'),
    ],
)
def test_a_key_with_white_space_is_named_in_quotes(tmp_path, capsys, key, shown):
    f = tmp_path / "s.toml"
    f.write_text(f'study = "brown_table1"\n{key} = 5\n')
    line = one_line(capsys, main(["check", str(f)]), prefix=SIM_ERROR)
    assert line == SIM_ERROR + shown or line.startswith(SIM_ERROR + shown), line
    with pytest.raises(sim.ConfigError) as e:
        sim.load(f)
    assert str(e.value).startswith(shown), e.value


def test_a_set_key_with_white_space_is_named_in_quotes(tmp_path, capsys):
    study = str(ROOT / "studies" / "brown_table1.toml")
    line = one_line(capsys, main(["check", study, "--set", "tri als=5"]), prefix=SIM_ERROR)
    assert line.startswith(SIM_ERROR + '"tri als": unknown key'), line
    rc = batch_main(["--results", str(tmp_path / "r"), study, "--", "--set", "tri\u200bals=5"])
    line = one_line(capsys, rc, "sim.batch: ")
    assert '--set "tri\\u200bals": unknown key' in line, line


@pytest.mark.parametrize(
    "text, needle",
    [
        ('Study = "brown_table1"\n', "Study: is not study (a study file names its study by"),
        ('study = "brown_table1"\n"study " = "x"\n', '"study ": is not study'),
        ('"stu\\u200bdy" = "brown_table1"\n', '"stu\\u200bdy": is not study'),
        ('"ѕtudy" = "brown_table1"\n', "ѕtudy: is not study"),
        ('study = "brown_table1"\n[Sweep]\ntrials = [40, 60]\n', "Sweep: is not sweep (the"),
        ('study = "brown_table1"\nSWEEP.trials = [40, 60]\n', "SWEEP: is not sweep"),
        (
            'study = "brown_table1"\n[sweep]\nReplicates = 2\ntrials = [4000, 6000]\n',
            "sweep.Replicates: unknown key (did you mean sweep.replicates?)",
        ),
    ],
)
def test_study_and_sweep_misspelt_are_named(tmp_path, capsys, text, needle):
    f = tmp_path / "s.toml"
    f.write_text(text)
    one_line(capsys, main(["check", str(f)]), SIM_ERROR + needle, prefix=SIM_ERROR)


def test_a_lookalike_table_name_is_answered_with_its_own_key(tmp_path, capsys):
    f = tmp_path / "s.toml"
    f.write_text('study = "brown_design"\n"papеr".positions = [4]\n')
    line = one_line(capsys, main(["check", str(f)]), prefix=SIM_ERROR)
    assert "(did you mean paper.positions" in line, line


def test_a_bare_dotted_datum_constraint_says_to_quote_it(tmp_path, capsys):
    f = tmp_path / "s.toml"
    f.write_text(NET + '[datum]\nkind = "constraints"\nconstraints = [ { P.x = 1.0 } ]\n')
    line = one_line(capsys, main(["check", str(f)]), "datum.constraints[0]", prefix=SIM_ERROR)
    assert 'write "P.x" = ... in quotes' in line and "'P' is not" not in line, line


@pytest.mark.parametrize(
    "old, new, needle",
    [
        ('name = "P"', 'Name = "P"', "points[2].Name: unknown field (did you mean name?)"),
        ("x_mm = 150.0", "x-mm = 150.0", "points[2].x-mm: unknown field (did you mean x_mm?)"),
        ('kind = "distance"', 'knd = "distance"', "(did you mean kind?)"),
    ],
)
def test_a_misspelt_network_field_gets_a_guess(tmp_path, capsys, old, new, needle):
    f = tmp_path / "s.toml"
    f.write_text(NET.replace(old, new, 1))
    one_line(capsys, main(["check", str(f)]), needle, prefix=SIM_ERROR)


@pytest.mark.parametrize(
    "spelt, needle",
    [
        ('"B.\\u0443"', "'B.у': the axis after its last dot must be x or y ('у', U+0443 CYRILLIC"),
        (
            '"\\u0410.x"',
            "'А.x': 'А' is no point of the network (declared is 'A', which looks the same",
        ),
    ],
)
def test_a_lookalike_in_a_constraint_key_is_named(tmp_path, capsys, spelt, needle):
    f = tmp_path / "s.toml"
    f.write_text(NET + f'[datum]\nkind = "constraints"\nconstraints = [ {{ {spelt} = 1.0 }} ]\n')
    one_line(capsys, main(["check", str(f)]), f"datum.constraints[0]: {needle}", prefix=SIM_ERROR)


@pytest.mark.parametrize(
    "option, needle",
    [
        ("—trials", "(did you mean --trials? U+2014 EM DASH is no hyphen: type -)"),
        ("–seed", "(did you mean --seed? U+2013 EN DASH is no hyphen: type -)"),
        ("--TRIALS=40", "(did you mean --trials?)"),
    ],
)
def test_an_option_with_a_typographic_dash_or_in_capitals_gets_a_guess(
    tmp_path, capsys, option, needle
):
    study = str(ROOT / "studies" / "brown_table1.toml")
    rc = main(["run", study, "--out", str(tmp_path / "o"), option, *(["40"] * ("=" not in option))])
    one_line(capsys, rc, "unrecognized arguments", needle, prefix=SIM_ERROR)
    assert not (tmp_path / "o").exists()
