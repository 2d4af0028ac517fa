"""A new user's first hour (doors38n): the mistakes people make following README.md from a
fresh clone, each through a real door, fixed; each test fails on the code before its fix:

* ``sim check brown_tabel1`` (or ``brown_table1``, ``studies/brown_tabel1``) typed from a
  directory inside the project (``docs/`` while reading docs/cli.md, ``studies/``,
  ``results/brown_table1/``) was "no such study file" with no guess, where the same words
  from the root name ``studies/brown_table1.toml``: the project's ``studies/`` is looked in
  from up to three levels below the root, and the guess is the path as typed from there
  (``../studies/brown_table1.toml``), a command that works when typed;
* a study file copied to a directory of one's own (``~/my.toml``) and named with its suffix
  mistyped (``sim check my.tom``, ``my.tml``) was "no such study file" with no guess (the
  name too short for the misspelt suffix to leave it near): a suffix near ``toml`` is read as
  ``.toml`` when the nearest name is looked for;
* ``sim show scratch/brown_table1-<hash>`` (the path ``sim run`` printed: "results in
  scratch/...") or ``sim show results/brown_table1`` typed from ``docs/`` was "DIR: ... does
  not exist", where ``sim show brown_table1`` from there reads the project's: a path under
  ``results/`` or ``scratch/`` is read under the project's root too, as a bare name is;
* a key typed with another unit than its own (``--set plate.spacing_um=45000``, the value in
  um) was "unknown key (did you mean plate.spacing_mm?)" alone, and the value moved to the mm
  key as typed was a spacing 1000 times the one meant: the guess says the unit its value is in
  (``its value is in mm, not um: convert it``);
* an option of another command (``sim show --trials 4 results/brown_table1``) was
  "unrecognized arguments: --trials results/brown_table1" (the 4 taken for DIR, the directory
  named as the bad argument), ``sim check x.toml --out d`` "(did you mean --set?)", and
  ``sim show --trials`` "sim show: unrecognized arguments": each names the option and the
  command it belongs to (``--trials: an option of sim run, not of sim show``).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from oneline import SIM_ERROR, one_line

import sim
from sim.cli import main

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize(
    ("where", "typed", "meant"),
    [
        ("docs", "brown_tabel1", "../studies/brown_table1.toml"),
        ("docs", "brown_table1", "../studies/brown_table1.toml"),
        ("docs", "studies/brown_tabel1.toml", "../studies/brown_table1.toml"),
        ("studies", "studies/brown_tabel1", "brown_table1.toml"),
        ("results/brown_table1", "brown_table1", "../../studies/brown_table1.toml"),
    ],
)
def test_a_study_name_typed_below_the_root_is_guessed(capsys, monkeypatch, where, typed, meant):
    monkeypatch.chdir(ROOT / where)
    want = f"{typed}: no such study file (did you mean {meant}?)"
    one_line(capsys, main(["check", typed]), prefix=SIM_ERROR + want)
    assert main(["check", meant]) == 0  # the guess works when typed
    capsys.readouterr()
    with pytest.raises(sim.ConfigError, match=re.escape(want)):
        sim.load(typed)


def test_the_path_a_run_printed_is_shown_from_docs(capsys, monkeypatch):
    monkeypatch.chdir(ROOT / "docs")
    assert main(["show", "results/brown_table1"]) == 0
    assert "brown.table1_closure.dof" in capsys.readouterr().out
    line = one_line(capsys, main(["show", "scratch/brown_tabel1-0"]), prefix=SIM_ERROR)
    assert line.endswith("(nor is there a directory ../scratch/brown_tabel1-0)"), line


@pytest.mark.parametrize(
    ("argv", "want"),
    [
        (["show", "--trials", "4", "results/brown_table1"], "--trials: an option of sim run, "),
        (["show", "--trials"], "--trials: an option of sim run, not of sim show"),
        (["check", "studies/brown_table1.toml", "--out", "d"], "--out: an option of sim run, "),
        (["show", "results/brown_table1", "--set", "a=1"], "--set: an option of sim run and sim "),
        (["report", "--markdown"], "--markdown: an option of sim show, not of sim report"),
    ],
)
def test_an_option_of_another_command_is_named_as_one(capsys, argv, want):
    line = one_line(capsys, main(argv), prefix=SIM_ERROR + want)
    assert want in line and "unrecognized" not in line and "did you mean" not in line, line


@pytest.mark.parametrize("typed", ["my.tom", "my.tml", "my.TOML"])
def test_a_mistyped_suffix_of_ones_own_study_file_is_guessed(tmp_path, capsys, monkeypatch, typed):
    (tmp_path / "my.toml").write_text((ROOT / "studies" / "brown_table1.toml").read_text())
    monkeypatch.chdir(tmp_path)
    want = f"{typed}: no such study file (did you mean my.toml?)"
    one_line(capsys, main(["check", typed]), prefix=SIM_ERROR + want)
    one_line(capsys, main(["check", "my.txt"]), prefix=SIM_ERROR + "my.txt: no such study file")


def test_a_key_in_another_unit_says_the_unit_to_convert_to(capsys):
    brown = str(ROOT / "studies" / "brown_table1.toml")
    want = (
        "plate.spacing_um: unknown key (did you mean plate.spacing_mm? its value is in mm, not um"
    )
    one_line(
        capsys, main(["check", brown, "--set", "plate.spacing_um=45000"]), prefix=SIM_ERROR + want
    )
    with pytest.raises(sim.ConfigError, match=re.escape(want)):
        sim.load(brown, **{"plate.spacing_um": 45000})
    line = one_line(capsys, main(["check", brown, "--set", "plate.spacing=45"]), prefix=SIM_ERROR)
    assert line.endswith("(did you mean plate.spacing_mm?)"), line  # no unit typed: none said
