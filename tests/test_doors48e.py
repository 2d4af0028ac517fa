"""Doors sweep 48e: the environment a user brings (the locale and the output's encoding, HOME,
XDG and TMPDIR, the umask, awkward paths, the interpreter's flags, the clocks), one case per
class found; each failed on the code before its fix.

* a path or a name of the user's that standard output's encoding cannot show
  (``PYTHONIOENCODING=ascii`` or ``latin-1``, a Latin-1 locale, ``LC_ALL=C`` with
  ``PYTHONUTF8=0``): ``sim run --out 'dΩ'`` computed and published every trial, then ended with
  exit 2 on its closing line "results in ..." (a batch or a script took the published run for a
  failed one); ``sim report`` wrote REPORT.md, then exit 2 printing its path; ``python -m
  sim.batch`` of ``ñet.toml`` ran the study, then ended in a ``UnicodeEncodeError`` traceback
  (exit 1, no report) printing its summary; ``make verify`` of results holding ``ñet`` re-ran it,
  then a traceback printing "ñet: ...", its record unwritten. Each is now refused before any work,
  one line naming the character and the path (:func:`sim.ends.unshown`).
* a directory of tables whose path is not ASCII under a locale whose file names are not UTF-8
  (``LC_ALL=de_DE.ISO-8859-1``, or ``LC_ALL=C`` with ``PYTHONUTF8=0 PYTHONCOERCECLOCALE=0``):
  Python gives the name to the system in the locale's encoding, Arrow in UTF-8, so they name
  different files. ``sim run --out dé`` failed at its first chunk on "No such file or directory:
  .../.dé.partial/trials/part-0/chunk-000000.parquet"; ``sim show`` and ``sim report`` said a
  ``claims.parquet`` that is there could not be found; the API raised Arrow's
  ``FileNotFoundError`` (Python's ``UnicodeEncodeError`` under ASCII) with a traceback. Each of
  ``--out``, ``DIR``, ``--results``, ``--scratch`` and ``out=`` is now refused in one line
  naming the locale's encoding (:func:`sim.api_paths.arrow_name`).
"""

from __future__ import annotations

import io
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import TRIANGLE_NETWORK
from oneline import one_line

import sim.batch
import sim.cli
import sim.report.verify.cli as verify_cli

ROOT = Path(__file__).resolve().parents[1]


def ascii_stdout(monkeypatch) -> None:
    """Standard output in ASCII (``PYTHONIOENCODING=ascii``); called in the test (capsys takes
    the streams when the test starts, after its fixtures)."""
    monkeypatch.setattr(sys, "stdout", io.TextIOWrapper(io.BytesIO(), encoding="ascii"))


@pytest.fixture(scope="module")
def triangle_results(tmp_path_factory) -> Path:
    """One small network run's results directory (no figures), made once."""
    d = tmp_path_factory.mktemp("tri")
    (d / "tri.toml").write_text(TRIANGLE_NETWORK, encoding="utf-8")
    rc = sim.cli.main(["run", str(d / "tri.toml"), "--out", str(d / "res" / "tri"), "--quiet"])
    assert rc == 0
    return d / "res" / "tri"


def test_an_out_the_output_cannot_show_is_refused_before_the_run(tmp_path, monkeypatch, capsys):
    """``sim run --out 'dΩ'`` under an ASCII output: before, every trial was computed and the
    results published, then exit 2 on the closing "results in ..." line."""
    ascii_stdout(monkeypatch)
    (tmp_path / "tri.toml").write_text(TRIANGLE_NETWORK, encoding="utf-8")
    out = tmp_path / "d\u03a9"
    rc = sim.cli.main(["run", str(tmp_path / "tri.toml"), "--out", str(out), "--no-figures"])
    line = one_line(capsys, rc, "--out: the output (encoding ascii) cannot show '\\u03a9' of ")
    assert "PYTHONIOENCODING=utf-8" in line and not out.exists(), line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tri.toml"]  # no staging left


def test_a_results_path_the_output_cannot_show_gets_no_report(
    triangle_results, tmp_path, monkeypatch, capsys
):
    """``sim report --results 'dΩ'``: before, REPORT.md was written, then exit 2 printing its
    path (held: the directory's names inside the report are not printed)."""
    ascii_stdout(monkeypatch)
    res = tmp_path / "d\u03a9"
    shutil.copytree(triangle_results, res / "tri")
    rc = sim.cli.main(["report", "--results", str(res)])
    one_line(capsys, rc, "--results: the output (encoding ascii) cannot show '\\u03a9'")
    assert not (res / "REPORT.md").exists()


def test_a_batch_of_a_file_the_output_cannot_name_runs_nothing(tmp_path, monkeypatch, capsys):
    """``python -m sim.batch ñet.toml``: before, the study ran and published, then the
    summary's print ended in a ``UnicodeEncodeError`` traceback (exit 1, no ``--report``)."""
    ascii_stdout(monkeypatch)
    (tmp_path / "\u00f1et.toml").write_text(TRIANGLE_NETWORK, encoding="utf-8")
    res = tmp_path / "res"
    rc = sim.batch.main(["--results", str(res), str(tmp_path / "\u00f1et.toml")])
    one_line(capsys, rc, "sim.batch: ", "cannot show '\\xf1' of '\\xf1et.toml'")
    assert not res.exists()


def test_verify_of_a_study_the_output_cannot_name_reruns_nothing(
    triangle_results, tmp_path, monkeypatch, capsys
):
    """``make verify`` of results holding ``ñet``: before, it was re-run, then "ñet: ..."
    ended in a ``UnicodeEncodeError`` traceback (exit 1), nothing recorded."""
    ascii_stdout(monkeypatch)
    res, studies, scratch = tmp_path / "res", tmp_path / "studies", tmp_path / "scratch"
    shutil.copytree(triangle_results, res / "\u00f1et")
    studies.mkdir()
    (studies / "\u00f1et.toml").write_text(TRIANGLE_NETWORK, encoding="utf-8")
    argv = ["--results", str(res), "--studies", str(studies), "--scratch", str(scratch)]
    rc = verify_cli.main(argv)
    one_line(capsys, rc, "sim verify: error: ", "cannot show '\\xf1' of ")
    assert not scratch.exists() and not (res / "reproducibility.parquet").exists()


def test_a_table_directory_not_ascii_under_a_non_utf8_locale_is_refused(
    triangle_results, tmp_path, monkeypatch, capsys
):
    """``sim show dé`` under a Latin-1 locale: before, "claims.parquet cannot be read: ... No
    such file or directory" of a file that is there (Arrow names it in UTF-8)."""
    d = tmp_path / "d\u00e9"
    shutil.copytree(triangle_results, d)
    monkeypatch.setattr(sys, "getfilesystemencoding", lambda: "iso8859-1")
    rc = sim.cli.main(["show", str(d)])
    one_line(capsys, rc, "sim: error: DIR: ", "this locale's file names are iso8859-1, not UTF-8")


def test_an_api_out_not_ascii_under_an_ascii_locale_is_a_config_error(tmp_path):
    """``sim.load(...).run(out="dé")`` under ``LC_ALL=C PYTHONUTF8=0``: before, Python's
    ``UnicodeEncodeError`` traceback from the first directory made."""
    (tmp_path / "tri.toml").write_text(TRIANGLE_NETWORK, encoding="utf-8")
    code = (
        "import sim\ntry:\n"
        f"    sim.load({str(tmp_path / 'tri.toml')!r}).run(out={str(tmp_path)!r} + '/d\\xe9')\n"
        "except sim.ConfigError as e:\n    print(ascii(str(e)))\n"
    )
    env = {**os.environ, "LC_ALL": "C", "PYTHONUTF8": "0", "PYTHONCOERCECLOCALE": "0"}
    p = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120
    )
    assert p.returncode == 0 and "Traceback" not in p.stderr, p.stderr
    assert p.stdout[1:].startswith("out: ") and "file names are ascii, not UTF-8" in p.stdout, p
    assert sorted(x.name for x in tmp_path.iterdir()) == ["tri.toml"]
