"""A hostile reading of session 53's first merges and two left items (doors51s, brief R53);
each test fails on the code before its fix:

* ``sim --version extra`` printed the version and exited 0, the extra words ignored: refused
  in one line, exit 2 (``sim --version`` alone still prints it);
* ``make verify --trials N --set KEY=V`` with a key a study to re-run lacks was refused only
  by that study's re-run, after every study before it had re-run (hours): refused before any
  re-run, naming the key, the study and its file, as ``python -m sim.batch`` does;
* ``make verify`` with a directory where its record ``reproducibility.parquet`` goes re-ran
  every study and then failed writing it ("Is a directory"): refused before any re-run, as
  K52 refuses read-only results;
* a caller's object that raises while the API reads it (F52's class), its exception's own
  ``__str__`` raising too: the refusal's words raised it, a traceback; named by its type;
* a GNU Gama DOCTYPE declaring an assumed default and then another for the same attribute
  (XML binds the first, as gama-local reads it) was refused naming the second;
* the API's ``StudyHandle.estimate()`` of a sweep counted the cells the study refuses, which
  ``sim check`` leaves out since P52 (404 trials in 2 cells of a sweep that runs one of 400).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest
from oneline import one_line

import sim
import sim.report.verify.cli as verify_cli
import sim.report.verify.rerun as rerun_mod
from sim.cli import main as cli_main
from sim.mc.config import ConfigError

ROOT = Path(__file__).resolve().parents[1]


def test_version_with_extra_words_is_refused(capsys):
    """Class: extra words after ``--version``. Before: ``sim --version extra`` (and
    ``sim --version check x.toml``) printed the version and exited 0, the rest ignored; now one
    line naming the first extra word, exit 2; ``--version`` alone prints it, exit 0."""
    one_line(capsys, cli_main(["--version", "extra"]), "--version takes no other words", "'extra'")
    assert cli_main(["--version"]) == 0
    assert capsys.readouterr().out == f"sim {sim.__version__}\n"


def test_verify_set_key_a_study_lacks_is_refused_before_any_rerun(capsys, monkeypatch, tmp_path):
    """Class: ``make verify``'s ``--set`` with a key one of the studies to re-run does not have
    (``plate.format_mm``, Brown's, over wolf_polynomial's results). Before: the re-runs
    started, and the study lacking the key refused it in its own re-run, after those before it
    had re-run; now one line before any re-run naming the key and the study."""
    results = tmp_path / "res"
    shutil.copytree(ROOT / "results" / "wolf_polynomial", results / "wolf_polynomial")
    started = []

    def rerun(d, *args, **kwargs):
        started.append(d.name)
        return "not re-run in this test"

    monkeypatch.chdir(ROOT)  # studies/ of the project
    monkeypatch.setattr(rerun_mod, "rerun_study", rerun)
    argv = ["--results", str(results), "--scratch", str(tmp_path / "s"), "--no-record"]
    rc = verify_cli.main([*argv, "--trials", "400", "--set", "plate.format_mm=245"])
    one_line(capsys, rc, "--set", "wolf_polynomial", "plate.format_mm: unknown key")
    assert started == []


def test_verify_with_a_directory_as_its_record_is_refused_before_any_rerun(
    capsys, monkeypatch, tmp_path
):
    """Class: the neighbour of K52's read-only results: a directory where ``make verify``
    writes its record (``results/reproducibility.parquet/``). Before: every study was re-run,
    then "cannot write .../reproducibility.parquet: Is a directory", exit 2; now one line
    before any re-run naming it and --no-record."""
    results = tmp_path / "res"
    (results / "reproducibility.parquet").mkdir(parents=True)

    def rerun(*args, **kwargs):
        raise AssertionError("a re-run started")

    monkeypatch.setattr(verify_cli, "verify", rerun)
    rc = verify_cli.main(["--results", str(results), "--studies", str(tmp_path)])
    one_line(capsys, rc, "reproducibility.parquet is a directory", "--no-record")


class _Unsayable(Exception):
    """An exception of the caller's whose own ``__str__`` raises."""

    def __str__(self):
        raise RuntimeError("its __str__ raised")


class _BrokenPath(os.PathLike):
    def __fspath__(self):
        raise _Unsayable()


def test_api_object_raising_an_unsayable_exception_is_named_by_its_type():
    """Class: F52's neighbour: a caller's object that raises while read, with an exception
    whose own ``__str__`` raises. Before: the refusal's words (``str(e)``) raised that second
    exception, a ``RuntimeError`` traceback from ``sim.load`` (as a config value and as the
    study file); now one ``ConfigError`` naming the key and the exception's type."""
    for call, key in (
        (
            lambda: sim.load(
                str(ROOT / "studies" / "network_plate.toml"), **{"network.gama_xml": _BrokenPath()}
            ),
            "network.gama_xml",
        ),
        (lambda: sim.load(_BrokenPath()), "study_file"),
    ):
        with pytest.raises(ConfigError) as e:
            call()
        assert str(e.value).startswith(f"{key}: ") and "raised _Unsayable" in str(e.value)


def test_a_doctype_default_declared_twice_binds_its_first(tmp_path):
    """Class: J52's harmless DOCTYPE defaults, declared twice. XML binds an attribute's first
    declaration (gama-local 2.03 reads ``angles`` CDATA "left-handed" then "right-handed" on a
    ``<network>`` without ``angles`` as left-handed: its output equals the file's with
    ``angles="left-handed"``). Before: refused "gives <network> attribute 'angles' the default
    'right-handed'", a default no parser applies; now read. The reverse order, which does
    make it right-handed, is still refused."""
    import re

    from gama_triangle import triangle

    from sim.studies.network.gama_read import read_gama

    text = re.sub(r"<network[^>]*>", "<network>", triangle())
    left, right = (f'<!ATTLIST network angles CDATA "{h}-handed">' for h in ("left", "right"))
    p = tmp_path / "net.xml"
    p.write_text(text.replace("?>\n", f"?>\n<!DOCTYPE gama-local [{left}{right}]>\n", 1))
    assert [q["name"] for q in read_gama(p)["network.points"]] == ["A", "B", "C"]
    p.write_text(text.replace("?>\n", f"?>\n<!DOCTYPE gama-local [{right}{left}]>\n", 1))
    with pytest.raises(ConfigError, match="attribute 'angles' the default 'right-handed'"):
        read_gama(p)


def test_api_estimate_leaves_out_the_cells_the_study_refuses(tmp_path, capsys):
    """Class: P52's count at a neighbouring door. ``sim check`` of a sweep ``trials = [400,
    4]`` counts the one cell that runs (400 trials); the API's ``StudyHandle.estimate()`` of
    the same file counted the refused cell too (404 trials in 2 cells). Now both count 400."""
    from sim.cli import main

    study = tmp_path / "np.toml"
    study.write_text(
        (ROOT / "studies" / "network_plate.toml").read_text() + "\n[sweep]\ntrials = [400, 4]\n"
    )
    assert main(["check", str(study)]) == 0
    assert "# work: 400 trials," in capsys.readouterr().out
    est = sim.load(study).estimate()
    assert (est.trials, est.cells) == (400, 1)
