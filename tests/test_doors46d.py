"""Helper d46: the docs typed as written and a new user's first hour; one case per class found,
each failing on the code before its fix. README.md's and docs/cli.md's commands and quoted
messages (``--trials 1000.5``, ``--set comparator.beta=0``, ``sim show --trials 4 DIR``,
``sim rn``, the em-dash ``—trials``, ...) held as written; the slips that did not:

* An option of another tool typed by habit got a guess by its letters alone, of another
  meaning, or none: ``sim run x.toml --threads 2`` "did you mean --trials?" (which would run two
  trials), ``--force`` ``--workers``, ``--verbose`` and ``--iterations`` ``--version``,
  ``--config`` ``--no-figures``, ``--resume`` and ``--silent`` ``--set``; ``-o``, ``-j``,
  ``-q``, ``-f``, ``-t``, ``--output-dir``, ``--no-plots`` none. ``python -m sim.batch --out
  x`` answered ``--report`` and ``--workers 2`` (a run option, given before ``--``) nothing;
  ``make verify --out x`` answered ``--set``. Each is now answered by what it means here
  (:mod:`sim.option_words`), or, where nothing of ``sim`` means it, by what does its work
  (``--dry-run``: ``sim check STUDY.toml``; ``--resume``: the same command again).
* ``sim help``, ``sim help run`` and ``sim version`` (as git and cargo take them) were
  "invalid choice" with the commands and no guess: now ``did you mean sim run --help?``.
* ``--set trials 40`` (or ``--set trials = 40``) was "unrecognized arguments: 40" alone: now
  ``(--set takes KEY=VALUE as one word: --set trials=40)``.
* A switch given a value (``--overwrite=true``, ``--report=yes``) was argparse's "ignored
  explicit argument 'true'" alone: now ``(--overwrite takes no value: give --overwrite
  alone)``.
* Two overrides in one ``--set`` (``--set trials=40,seed=3``, ``--set "trials=40 seed=3"``)
  were "trials: must be an integer (got '40,seed=3')" alone: the line now ends ``(one
  KEY=VALUE a --set: --set trials=40 --set seed=3)``.
* ``sim report results/brown_table1`` (the directory given as an argument) was
  "unrecognized arguments" alone: it now says ``sim report takes --results DIR``; ``sim run
  x.toml -- --trials 40`` guessed ``--trials`` for ``--trials``: it now says that ``--`` ends
  the options; ``sim show DIR --json`` guessed ``--version``, ``sim check x.toml --list``
  ``--set``, ``--md`` nothing: now what gives the tables, the keys, ``--markdown``.
* ``sim check x.toml --trials 400`` (checking with the flags of the run to come) was "an
  option of sim run, not of sim check" alone: it now adds ``sim check --set trials=400 checks
  what sim run --trials 400 runs``.
* ``--set network.generate[1].sigma_arcsec=3`` (an item of a network's list, as a newcomer
  would name it) was "unknown key" alone: it now says the list's items have no keys of their
  own and to give the whole list (``--set 'network.generate=[...]'``) or edit the file.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from oneline import SIM_ERROR, VERIFY_ERROR, one_line

from sim import batch
from sim.cli import main
from sim.report.verify import cli as verify_cli

ROOT = Path(__file__).resolve().parents[1]
STUDY = "studies/brown_table1.toml"


@pytest.mark.parametrize(
    ("typed", "meant"),
    [
        (["--threads", "2"], "did you mean --workers?"),
        (["-j", "2"], "did you mean --workers?"),
        (["--jobs", "2"], "did you mean --workers?"),
        (["--force"], "did you mean --overwrite?"),
        (["-f"], "did you mean --overwrite?"),
        (["-o", "/tmp/x"], "did you mean --out?"),
        (["--output-dir", "/tmp/x"], "did you mean --out?"),
        (["-q"], "did you mean --quiet?"),
        (["--silent"], "did you mean --quiet?"),
        (["--iterations", "40"], "did you mean --trials?"),
        (["-t", "40"], "did you mean --trials?"),
        (["-s", "trials=40"], "did you mean --set?"),
        (["--no-plots"], "did you mean --no-figures?"),
        (["--verbose"], "no such option: sim prints its progress"),
        (["--dry-run"], "sim check STUDY.toml validates the file"),
        (["--resume"], "the same command again resumes"),
        (["--config", "y.toml"], "the study file is the command's argument"),
    ],
)
def test_an_option_of_another_tool_is_answered_by_its_meaning(capsys, typed, meant):
    """Class: a newcomer's option from another tool (make, pytest, git). Before: a guess by
    letters (``--threads``: ``--trials``; ``--force``: ``--workers``; ``--verbose``:
    ``--version``) or none (``-o``, ``-j``, ``-q``)."""
    line = one_line(capsys, main(["run", STUDY, *typed]), meant, prefix=SIM_ERROR)
    assert "--version" not in line and line.count("did you mean") <= 1


def test_a_near_spelling_keeps_its_guess(capsys):
    """The words of other tools come first; a typo of an option keeps its spelling guess."""
    one_line(capsys, main(["run", STUDY, "--tri", "4"]), "--trials? options are not abbreviated")
    one_line(capsys, main(["run", STUDY, "--nworkers", "2"]), "(did you mean --workers?)")
    one_line(capsys, main(["show", "results/x", "--trials", "4"]), "an option of sim run")


@pytest.mark.parametrize(
    ("typed", "meant"),
    [
        (["help"], "(did you mean sim --help? sim COMMAND --help"),
        (["help", "run"], "(did you mean sim run --help?)"),
        (["version"], "(did you mean sim --version?)"),
    ],
)
def test_help_or_version_typed_as_a_command_names_the_option(capsys, typed, meant):
    """Class: a command word of git or cargo (``sim help run``). Before: "invalid choice:
    'help'" with the commands and no guess."""
    one_line(capsys, main(typed), meant, prefix=SIM_ERROR)


@pytest.mark.parametrize(
    "value", [["trials", "40"], ["trials", "=", "40"], ["trials=", "40"], ["trials", "=40"]]
)
def test_a_set_value_apart_from_its_key_is_shown_joined(capsys, value):
    """Class: ``--set KEY VALUE`` with a space, as other tools take it. Before:
    "unrecognized arguments: 40" alone, the key and --set unnamed."""
    rc = main(["run", STUDY, "--set", *value])
    one_line(capsys, rc, "(--set takes KEY=VALUE as one word: --set trials=40)")


def test_a_switch_given_a_value_says_it_takes_none(capsys):
    """Class: ``--overwrite=true``. Before: argparse's "ignored explicit argument 'true'"."""
    rc = main(["run", STUDY, "--overwrite=true"])
    one_line(capsys, rc, "(--overwrite takes no value: give --overwrite alone)")


@pytest.mark.parametrize(
    ("typed", "meant"),
    [
        (["--out", "x"], "(did you mean --results?)"),
        (["-j", "2"], "(did you mean --jobs?)"),
        (["--threads", "2"], "(did you mean --jobs?)"),
        (["--workers", "2"], "give it after --, python -m sim.batch FILES -- --workers"),
        (["--force"], "give it after --, python -m sim.batch FILES -- --overwrite"),
        (["--report=yes"], "(--report takes no value"),
    ],
)
def test_batch_answers_an_option_by_its_meaning(capsys, typed, meant):
    """Class: a run option given to ``python -m sim.batch`` before ``--``, or ``--out`` for
    ``--results``. Before: ``--out``: "did you mean --report?"; ``--workers``, ``-j``: nothing."""
    one_line(capsys, batch.main([*typed, STUDY]), meant, prefix="sim.batch: ")


@pytest.mark.parametrize("typed", [["-o", "x"], ["--out", "x"]])
def test_batch_run_options_name_results_for_an_output(capsys, typed):
    """Class: an output directory among a batch's run options (after ``--``). Before: ``-o``
    got "did you mean --out?" (since the words of other tools), which the batch then refuses;
    ``--out`` was refused without the option that does it."""
    rc = batch.main(["--results", "unused", STUDY, "--", *typed])
    line = one_line(capsys, rc, "give --results DIR before --", prefix="sim.batch: ")
    assert "did you mean --out" not in line


@pytest.mark.parametrize(
    ("typed", "meant"),
    [(["--out", "x"], "(did you mean --scratch?)"), (["-j", "2"], "(did you mean --workers?)")],
)
def test_verify_answers_an_option_by_its_meaning(capsys, typed, meant):
    """Class: ``make verify VERIFY_FLAGS="--out x"``. Before: "did you mean --set?"."""
    line = one_line(capsys, verify_cli.main(typed), meant, prefix=VERIFY_ERROR)
    assert "--set" not in line


@pytest.mark.parametrize(
    ("value", "split"),
    [
        ("trials=40,seed=3", "--set trials=40 --set seed=3"),
        ("trials=40 seed=3", "--set trials=40 --set seed=3"),
        ("plate.grid=5; plate.spacing_mm=40", "--set plate.grid=5 --set plate.spacing_mm=40"),
    ],
)
def test_two_overrides_in_one_set_are_shown_apart(capsys, value, split):
    """Class: ``--set`` given two keys at once, as a list. Before: "must be an integer (got
    '40,seed=3')", the second key unnamed."""
    one_line(capsys, main(["check", STUDY, "--set", value]), f"(one KEY=VALUE a --set: {split})")


def test_a_list_value_with_commas_is_no_second_override(capsys):
    """A list's commas are not a second override: its own refusal stands, with no split."""
    line = one_line(capsys, main(["check", STUDY, "--set", "plate.grid=[3,5]"]), "plate.grid")
    assert "one KEY=VALUE" not in line


@pytest.mark.parametrize(
    ("typed", "meant"),
    [
        (["report", "results/brown_table1"], "sim report takes --results DIR"),
        (["run", STUDY, "--", "--trials", "40"], "(-- ends the options"),
        (["show", "results/brown_table1", "--json"], "the Parquet files of its results"),
        (["check", STUDY, "--list"], "sim check STUDY.toml lists every key"),
        (["show", "results/brown_table1", "--md"], "(did you mean --markdown?)"),
    ],
)
def test_a_command_given_what_another_takes_says_what_to_type(capsys, typed, meant):
    """Class: an argument in the wrong place or of another tool's habit. Before: "unrecognized
    arguments" alone, or a guess of another meaning (``--json``: ``--version``; ``--list``:
    ``--set``; ``-- --trials``: ``--trials``)."""
    line = one_line(capsys, main(typed), meant, prefix=SIM_ERROR)
    assert "--version" not in line and "did you mean --set" not in line


@pytest.mark.parametrize(
    ("typed", "meant"), [(["--trials", "400"], "trials=400"), (["--seed=7"], "seed=7")]
)
def test_check_given_a_run_option_names_its_set_form(capsys, typed, meant):
    """Class: ``sim check`` typed with ``sim run``'s flags. Before: "an option of sim run, not
    of sim check" alone, not how sim check takes it."""
    line = one_line(capsys, main(["check", STUDY, *typed]), f"sim check --set {meant} checks")
    assert line.startswith(f"{SIM_ERROR}{typed[0].split('=')[0]}: an option of sim run")


NETWORK = """study = "network"
trials = 40
chunk = 2
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" },
           { name = "P", x_mm = 150.0, y_mm = 120.0 } ]
generate = [ { kind = "distance", from = ["A", "B"], to = "P", sigma_mm = 0.002 } ]
"""


@pytest.mark.parametrize("key", ["network.generate[0].sigma_mm", "network.generate.0.sigma_mm"])
def test_a_list_items_field_set_by_index_says_to_give_the_list(tmp_path, capsys, key):
    """Class: ``--set`` of one item of a network's list by its index. Before: "unknown key"
    alone, with no word of how to change it."""
    (f := tmp_path / "net.toml").write_text(NETWORK, encoding="utf-8")
    rc = main(["check", str(f), "--set", f"{key}=0.003"])
    one_line(capsys, rc, "network.generate is a list", "--set 'network.generate=[...]'")
    rc = main(["check", str(f), "--set", "network.generat=[]"])  # no item: as before
    assert "is a list" not in one_line(capsys, rc, "unknown key")


def test_the_cli_page_says_what_another_tools_option_gets():
    """The page states the answer to another tool's option (docs/cli.md, *Bad input*)."""
    text = " ".join((ROOT / "docs" / "cli.md").read_text(encoding="utf-8").split())
    assert re.search(r"`--threads 2`: `did you mean --workers\?`", text)
    assert "`sim help run`: `did you mean sim run --help?`" in text
    assert "`--set trials=40,seed=3`: `one KEY=VALUE a --set" in text
    assert "`--set network.generate[1].sigma_arcsec=3`" in text
