"""Doors of issue 26 read as an attacker after the merges of session 46 (R47).

* The mark of a report due (``<results>/.report-due``, :mod:`sim.report_due`), set by
  ``python -m sim.batch --report`` before its ``sim report``: a ``.report-due`` that is a
  symbolic or hard link had the batch's pid written over the file it names (a user's file
  changed), and one that is a FIFO made the batch wait for a reader after its runs (a hang).
* ``sim check``'s advice for ``--trials``/``--seed``/``--chunk`` (``sim check --set
  trials=N``) took its value from argparse's leftovers: the study file (``sim check --trials 5
  x.toml``: "--set trials=x.toml"), the next option, or the hint's own words (``--seed=``:
  "--set seed=(did checks what sim run --seed (did runs").
* ``sim``'s own option after a command (``sim run x.toml --version``) was guessed as itself,
  "(did you mean --version?)"; a slip of it (``-V``, ``--verison``) as ``--version``, which is
  refused again where it was typed: both now name ``sim --version``.
* An unknown key naming an item (``--set plate.grid[0]=3``, ``errors.1``) was answered "plate.grid
  is a list: ... give the whole list" whatever the key is (an integer, a table, no key of the
  study, a sweep's values, which ``--set`` refuses): now only for a key the study reads as a list.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from sim.cli import main
from sim.report_due import DUE, due_words, mark_due
from tests.oneline import SIM_ERROR, one_line

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STUDY = os.path.join(ROOT, "studies", "brown_table1.toml")


@pytest.mark.parametrize("kind", ["symlink", "hardlink"])
def test_a_report_due_mark_that_is_a_link_leaves_the_file_it_names(tmp_path, kind):
    """A results directory touched by hand: ``.report-due`` a link to a user's file. Before,
    the batch's mark wrote its pid over that file."""
    res, notes = tmp_path / "res", tmp_path / "notes.txt"
    res.mkdir()
    notes.write_text("my notes\n")
    (os.symlink if kind == "symlink" else os.link)(notes, res / DUE)
    mark_due(res)
    assert notes.read_text() == "my notes\n"


def test_a_report_due_mark_that_is_a_fifo_does_not_hang_the_batch(tmp_path):
    """A results directory touched by hand: ``.report-due`` a FIFO nobody reads. Before,
    setting the mark waited for a reader for ever (the batch's report step hung)."""
    res = tmp_path / "res"
    res.mkdir()
    os.mkfifo(res / DUE)
    code = "import sys; from pathlib import Path; from sim.report_due import mark_due; "
    code += "mark_due(Path(sys.argv[1]))"
    done = subprocess.run([sys.executable, "-c", code, str(res)], cwd=ROOT, timeout=60)
    assert done.returncode == 0
    assert due_words(res) is None  # (a FIFO is not the suite's mark)


def test_the_report_due_mark_is_still_set_and_read(tmp_path):
    """The mark as a regular file, set afresh over an old one of its own: still said."""
    res = tmp_path / "res"
    res.mkdir()
    (res / DUE).write_text("123456789\n")
    mark_due(res)
    assert (res / DUE).read_text() == f"{os.getpid()}\n"
    assert "was not rebuilt" in due_words(res)


@pytest.mark.parametrize(
    "argv, value",
    [
        (["check", "--trials", "5", STUDY], "trials=5"),
        (["check", STUDY, "--seed="], "seed=N"),
        (["check", STUDY, "--trials", "--seed", "3"], "trials=N"),
        (["check", STUDY, "--chunk", "7"], "chunk=7"),
    ],
)
def test_sim_checks_advice_for_a_run_option_gives_its_value(capsys, argv, value):
    """A run option given to ``sim check`` (a careless user): the advice's value is the one
    given after it, else N. Before: the study file, the next option or "(did"."""
    line = one_line(capsys, main(argv), f"sim check --set {value} checks", prefix=SIM_ERROR)
    assert ".toml checks" not in line and "(did" not in line.split("checks")[0]


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["run", STUDY, "--version"], "--version is an option of sim itself, not of sim run"),
        (["check", STUDY, "--version=1"], "--version is an option of sim itself"),
        (["run", STUDY, "-V"], "(did you mean sim --version?)"),
        (["run", STUDY, "--verison"], "(did you mean sim --version?)"),
    ],
)
def test_sims_own_option_after_a_command_is_not_guessed_as_itself(capsys, argv, needle):
    """``sim``'s own option (``--version``) typed after a command, or a slip of it: before,
    "unrecognized arguments: --version (did you mean --version?)", a guess that is the word
    itself, and for ``-V`` or ``--verison`` a guess refused again where it was typed."""
    line = one_line(capsys, main(argv), needle, prefix=SIM_ERROR)
    assert "(did you mean --version?)" not in line


def test_a_slip_of_a_commands_own_option_keeps_its_guess(capsys):
    """The guess of the command's own option is unchanged (a control of the above)."""
    one_line(capsys, main(["run", STUDY, "--trails", "3"]), "(did you mean --trials?)")


NETWORK = os.path.join(ROOT, "studies", "network_plate.toml")


@pytest.mark.parametrize(
    "argv",
    [
        ["check", STUDY, "--set", "plate.grid[0]=3"],  # an integer
        ["check", STUDY, "--set", "errors.1=3"],  # a table of keys
        ["check", STUDY, "--set", "version2.0=1"],  # no key of the study
        ["check", STUDY, "--set", "sweep.plate.grid.0=3"],  # a sweep's, which --set refuses
    ],
)
def test_a_key_of_an_item_is_called_a_list_only_when_it_is_one(capsys, argv):
    """A careless ``--set`` of an item of something that is no list: before, "(plate.grid is
    a list: ... give the whole list, --set 'plate.grid=[...]')" for any key of that form."""
    line = one_line(capsys, main(argv), "unknown key", prefix=SIM_ERROR)
    assert "is a list" not in line


def test_a_key_of_an_item_of_a_list_still_says_to_give_the_list(capsys):
    """The hint where it is true (a control of the above): network.generate is a list."""
    argv = ["check", NETWORK, "--set", "network.generate[0].sigma_arcsec=3"]
    one_line(capsys, main(argv), "network.generate is a list", prefix=SIM_ERROR)
