"""Helper d45: a new user's first hour, README.md and docs/ typed as written on a fresh clone;
one case per class found, each failing on the code before its fix. The commands of the pages
(``sim run``, ``sim show``, ``sim check``, the README's network and Python snippets, ``make
verify STUDY=x``, ``sim`` alone and each ``--help``) were typed in a scratch clone.

* ``sim show`` given a results directory the way a new user names it was "does not exist"
  (or "is not a directory") with no guess, where ``sim run`` and ``sim check`` guess a study
  file's name: its study file (``sim show brown_table1.toml``, ``sim show
  studies/brown_table1.toml``), a typo (``brown_tabel1``), or the scratch directory its run
  went to without the config hash (``sim show scratch/brown_table1`` for
  ``scratch/brown_table1-353c12b0``), or a file of it (``results/brown_table1/README.md``:
  ``sim show results/brown_table1 --markdown``). The line now ends ``did you mean sim show
  results/brown_table1?`` (:func:`sim.cli_read._show_guess`).
* ``sim run brown_table1`` (or ``sim check``) from a directory of the user's outside the
  project was "no such study file" with no guess (the guess looked only in ``studies/`` here
  and in the project's from a directory inside it): it now names the project's study file by
  its absolute path (:func:`sim.mc.study_file._studies_dirs`).
* ``make verify VERIFY_FLAGS="--study brown_table1.toml"`` (the study's file, as ``sim run``
  takes it) was "no results of 'brown_table1.toml'" with the list of names: it now says
  ``did you mean --study brown_table1? a study's name, not its file``.
* ``sim studies/brown_table1.toml`` (the command left out) was argparse's "invalid choice"
  with the commands and no guess: it now ends ``(a study file: did you mean sim run
  studies/brown_table1.toml?)`` (:meth:`sim.mc.argv.BoundedParser.explain`).
* README.md and docs/verdicts.md said REPORT.md's first screen gives each paper "three
  headline claims": it gives up to three, those its claim books mark (Wolf's row one, Salsig's
  two: :func:`sim.report.glance._headline_pick`). Both now say "up to three".
"""

from __future__ import annotations

from pathlib import Path

import pytest
from oneline import one_line

from sim.cli import main
from sim.report.verify.rerun import study_dirs
from sim.report.verify.rules import VerifyError

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize(
    ("typed", "meant"),
    [
        ("brown_table1.toml", "results/brown_table1"),
        ("studies/brown_table1.toml", "results/brown_table1"),
        ("brown_tabel1", "results/brown_table1"),
        ("scratch/brown_table1", "scratch/brown_table1-353c12b0"),
        ("results/brown_table1/README.md", "results/brown_table1 --markdown"),
    ],
)
def test_show_of_a_study_file_or_a_near_name_guesses_the_results(
    tmp_path, monkeypatch, capsys, typed, meant
):
    for d in ("results/brown_table1", "scratch/brown_table1-353c12b0", "studies"):
        (tmp_path / d).mkdir(parents=True)
    (tmp_path / "studies" / "brown_table1.toml").write_text('study = "brown_table1"\n')
    for d in ("results/brown_table1", "scratch/brown_table1-353c12b0"):
        (tmp_path / d / "run.json").write_text("{}")
    (tmp_path / "results" / "brown_table1" / "README.md").write_text("# a run\n")
    monkeypatch.chdir(tmp_path)
    one_line(capsys, main(["show", typed]), f"did you mean sim show {meant}?")
    one_line(capsys, main(["show", "nothing_like_it"]), "does not exist")  # no guess: none


def test_a_project_study_named_from_outside_the_project_is_guessed(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    meant = ROOT / "studies" / "brown_table1.toml"
    for typed in ("brown_table1", "brown_table1.toml", "brown_tabel1"):
        one_line(capsys, main(["check", typed]), f"(did you mean {meant}?)")


def test_verify_study_given_as_its_file_names_the_study():
    with pytest.raises(VerifyError, match=r"did you mean --study brown_table1\? a study's name"):
        study_dirs(ROOT / "results", ["studies/brown_table1.toml"])


@pytest.mark.parametrize("typed", ["studies/brown_table1.toml", "mine.TOML"])
def test_a_study_file_given_without_a_command_is_guessed_as_sim_run(capsys, typed):
    one_line(capsys, main([typed]), f"(a study file: did you mean sim run {typed}?)")
    line = one_line(capsys, main(["rn"]), "(did you mean run?)")  # a command's typo as before
    assert "a study file" not in line


def test_the_pages_say_the_first_screen_gives_up_to_three_headline_claims():
    for page in (ROOT / "README.md", ROOT / "docs" / "verdicts.md"):
        text = " ".join(page.read_text(encoding="utf-8").split())
        assert "three headline" in text and text.count("three headline") == text.count(
            "up to three headline"
        ), page
