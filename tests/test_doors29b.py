"""The classes of the sweep doors29b (brief D29b: the command line as argparse parses it, in
``sim``, ``python -m sim.batch``, ``make verify`` and ``python -m benchmarks``):

* an abbreviated option (``--tri 40`` for ``--trials``, ``--no-fig``, ``--stale`` for
  ``--stale-only``, ``sim --vers``) was taken without a word: a command line of a script or a
  Makefile that breaks the day an option of the same prefix is added (``--o`` already matches
  ``--out`` and ``--overwrite``); now one line naming the option it abbreviates;
* a mistyped command or choice (``sim rn``, ``--executor daks``) or option (``--trails``) was
  named with no guess at what was meant;
* ``make verify`` (``python -m sim.report.verify``) took ``--trials 400 --trials 800``,
  ``--scratch A --scratch B`` and ``--studies A --studies B`` with the last value, as ``sim``
  did before the ``ONCE`` options; a key given twice by its ``--set`` went to every re-run,
  each of which refused it in turn (a "FAILED" study for each) instead of one line at once;
* a variable on make's command line that the Makefile does not read, named like one it does
  (``make verify STUDY=brown_table1``, ``make reproduce JOBS=4``, ``make test PYTEST_ARGS=-x``),
  was dropped: every study re-run, 2 at a time, every test; now one line naming what to write.
"""

from __future__ import annotations

import argparse
import re

import pytest
from conftest import ROOT
from oneline import SIM_ERROR, VERIFY_ERROR, one_line
from test_doors18c import MAKE, fake_project, run_make

import sim.batch
from benchmarks import cli as bench_cli
from sim.cli import DOC, main
from sim.cli_args import parser
from sim.report.verify.cli import _parser as verify_parser
from sim.report.verify.cli import main as verify_main

BROWN = str(ROOT / "studies" / "brown_table1.toml")


def _bench(argv: list[str]) -> int:
    try:
        return bench_cli.main(argv)
    except SystemExit as e:
        return e.code


@pytest.mark.parametrize(
    "program, argv, meant",
    [
        (main, ["run", BROWN, "--tri", "40", "--quiet", "--no-figures"], "--trials"),
        (main, ["run", BROWN, "--trials", "40", "--quiet", "--no-fig"], "--no-figures"),
        (main, ["run", BROWN, "--o", "OUT"], "--out or --overwrite"),
        (main, ["check", BROWN, "--se", "seed=1"], "--set"),
        (main, ["--vers"], "--version"),
        (sim.batch.main, ["--stale", BROWN], "--stale-only"),
        (sim.batch.main, [BROWN, "--", "--trials", "40", "--no-fig"], "--no-figures"),
        (verify_main, ["--stu", "brown_table1"], "--studies or --study"),
        (_bench, ["--qui"], "--quick"),
    ],
)
def test_an_abbreviated_option_is_refused_naming_the_option(tmp_path, capsys, program, argv, meant):
    argv = [a.replace("OUT", str(tmp_path / "o")) for a in argv]
    if program is sim.batch.main:
        argv = ["--results", str(tmp_path / "r"), *argv]
    if program is main and argv[0] == "run" and "--o" not in argv:
        argv += ["--out", str(tmp_path / "o")]
    line = one_line(capsys, program(argv), f"did you mean {meant}?", "not abbreviated")
    assert "unrecognized arguments" in line, line
    assert list(tmp_path.iterdir()) == []  # nothing was run


def test_an_option_by_its_whole_name_with_equals_is_still_read():
    a = parser(DOC).parse_args(["run", BROWN, "--out=X", "--trials=40", "--set=seed=1"])
    assert (a.out, a.trials, a.set) == ("X", 40, ["seed=1"])
    v = verify_parser().parse_args(["--results=R", "--study=brown_table1", "--trials=400"])
    assert (v.results, v.study, v.trials) == ("R", ["brown_table1"], 400)


@pytest.mark.parametrize(
    "argv, guess",
    [
        (["rn", BROWN], "did you mean run?"),
        (["chek", BROWN], "did you mean check?"),
        (["run", BROWN, "--executor", "daks"], "did you mean dask?"),
        (["run", BROWN, "--trails", "40"], "did you mean --trials?"),
        (["--verison"], "did you mean --version?"),
    ],
)
def test_a_mistyped_command_choice_or_option_gets_a_guess(capsys, argv, guess):
    line = one_line(capsys, main(argv), guess, prefix=SIM_ERROR)
    assert "not abbreviated" not in line  # a typo, not a prefix


def test_a_word_like_no_command_gets_no_guess(capsys):
    line = one_line(capsys, main(["zzzz"]), "invalid choice: 'zzzz'", prefix=SIM_ERROR)
    assert "did you mean" not in line


@pytest.mark.parametrize(
    "argv, opt",
    [
        (["--trials", "400", "--trials", "800"], "--trials"),
        (["--scratch", "A", "--scratch", "B"], "--scratch"),
        (["--studies", "A", "--studies", "B"], "--studies"),
    ],
)
def test_verify_refuses_an_option_given_twice(tmp_path, capsys, argv, opt):
    argv = [str(tmp_path / a) if a in "AB" else a for a in argv]
    one_line(capsys, verify_main(argv), f"argument {opt}: given twice", prefix=VERIFY_ERROR)
    assert list(tmp_path.iterdir()) == []


def test_verify_refuses_a_key_given_twice_by_set_before_any_rerun(tmp_path, capsys):
    scratch = tmp_path / "s"
    argv = ["--scratch", str(scratch), "--study", "brown_table1", "--trials", "400"]
    argv += ["--set", "seed=1", "--set", "seed = 2"]
    one_line(capsys, verify_main(argv), "seed: given twice by --set", prefix=VERIFY_ERROR)
    assert not scratch.exists()  # refused before the re-run, not by it


def test_verify_results_may_be_given_again_as_make_verify_does():
    # the Makefile runs `python -m sim.report.verify --results results ... $(VERIFY_FLAGS)`
    a = verify_parser().parse_args(["--results", "results", "--workers", "2", "--results", "R"])
    assert a.results == "R"


@pytest.mark.skipif(MAKE is None, reason="no make on this machine")
@pytest.mark.parametrize(
    "target, setting, instead",
    [
        ("verify", "STUDY=brown_table1", 'VERIFY_FLAGS="--study NAME"'),
        ("verify", "STUDIES=brown_table1", 'VERIFY_FLAGS="--study NAME --study NAME2"'),
        ("reproduce", "JOBS=4", "RUN_JOBS=N"),
        ("test", "WORKERS=1", "TEST_WORKERS=N"),
        ("reproduce", "TRIALS=40", 'RUN_FLAGS="--trials N"'),
        ("reproduce", "SEED=7", 'RUN_FLAGS="--seed N"'),
        ("verify", "FLAGS=--study x", "VERIFY_FLAGS"),
        ("test", "PYTEST_ARGS=-x", "PYTEST_ADDOPTS"),
        # left15: other spellings of the documented settings (see test_left15)
        ("reproduce", "jobs=4", "RUN_JOBS=N"),
        ("reproduce", "RUN_JOB=4", "RUN_JOBS=N"),
        ("test", "test_workers=1", "TEST_WORKERS=N"),
        ("bench", "OUT=/tmp/x", "BENCH_OUT=DIR"),
        ("fuzz", "FUZZ_CASE=5", "FUZZ_CASES=N"),
        ("verify", "VERIFY_ARGS=--study x", 'VERIFY_FLAGS="..."'),
        ("venv", "PY=python3", "PYTHON=python3.X"),
    ],
)
def test_make_names_a_setting_it_does_not_read_before_any_command(
    tmp_path, target, setting, instead
):
    log, fake = tmp_path / "calls.log", tmp_path / "python"
    fake.write_text(f'#!/bin/sh\necho "$*" >> {log}\n', encoding="utf-8")
    fake.chmod(0o755)
    d = fake_project(tmp_path, str(fake))
    p = run_make(d, target, setting)
    err = p.stderr.removesuffix("\n")
    name = setting.split("=")[0]
    assert p.returncode == 2 and "\n" not in err, p.stderr
    assert f"{name} is not a setting of this Makefile; " in err and instead in err, err
    assert not log.exists()  # nothing ran


@pytest.mark.skipif(MAKE is None, reason="no make on this machine")
def test_make_leaves_such_a_name_in_the_environment_alone(tmp_path, monkeypatch):
    log, fake = tmp_path / "calls.log", tmp_path / "python"
    fake.write_text(f'#!/bin/sh\necho "$*" >> {log}\n', encoding="utf-8")
    fake.chmod(0o755)
    d = fake_project(tmp_path, str(fake))
    monkeypatch.setenv("JOBS", "4")  # a shell's own JOBS, not meant for make
    p = run_make(d, "report")
    assert p.returncode == 0 and "-m sim report --results results" in log.read_text(), p.stderr


def _options(p: argparse.ArgumentParser) -> list[tuple[str, ...]]:
    """The long options of ``p`` and of its commands that ``--help`` shows, each with its
    other names (``--rerun``/``--no-rerun``)."""
    found = []
    for a in p._actions:
        if isinstance(a, argparse._SubParsersAction):
            for sub in a.choices.values():
                found += _options(sub)
        elif a.help != argparse.SUPPRESS and "--help" not in a.option_strings:
            found.append(tuple(o for o in a.option_strings if o.startswith("--")))
    return found


def test_every_option_of_every_command_line_is_named_in_the_docs(monkeypatch):
    """``make verify``'s ``--no-record`` was named by its ``--help`` alone."""
    seen = {}
    for program in (sim.batch.main, bench_cli.main):  # their parsers are built in main
        monkeypatch.setattr(
            argparse.ArgumentParser,
            "parse_args",
            lambda self, *a, program=program, **k: seen.setdefault(program, self) and 1 / 0,
        )
        with pytest.raises(ZeroDivisionError):
            program(["x"])
    parsers = [parser(DOC), verify_parser(), *seen.values()]
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    text = "\n".join(p.read_text(encoding="utf-8") for p in pages)
    named = set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", text))
    missing = sorted(o for p in parsers for o in _options(p) if o and not named & set(o))
    assert len(parsers) == 4 and not missing, missing


def test_a_batch_with_its_study_files_after_the_separator_says_so(capsys):
    """``python -m sim.batch --results X -- a.toml`` said only "the following arguments are
    required: files": what follows ``--`` is sim run's options, so the file was never seen."""
    rc = sim.batch.main(["--results", "X", "--", BROWN])
    one_line(capsys, rc, "required: files", "study files come before --", "brown_table1.toml")
