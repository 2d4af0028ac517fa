"""The classes of the eleventh sweep of bad inputs (issue 26, doors12: the environment and
a new user's first hour), one case each; each failed on the code before its fix.

* ``python -OO`` (docstrings stripped): ``sim`` ended in "internal error: AttributeError"
  and ``python -m sim.batch`` in a traceback, since their usage text is their docstring;
  it is now read from the source (:func:`sim.cli_args.module_doc`);
* ``MPLBACKEND`` naming a backend matplotlib does not know: a run computed every trial,
  then failed at its first figure; the suite draws PNG files through Agg only, so the
  variable is set aside while matplotlib loads (:mod:`sim.report.mpl`);
* a study file saved by a Windows editor with a UTF-8 signature (BOM) was "malformed TOML
  at line 1, column 1"; it is read (the signature is no part of the text), and a UTF-16
  file says it is not UTF-8 (:func:`sim.mc.config.read_toml`);
* standard output that cannot be written (``> /dev/full``): ``sim`` said only "No space
  left on device", and ``python -m sim.batch`` ended in a traceback from a run's thread; now
  one line naming standard output, exit 2 (:func:`sim.cli_errors.from_stdout`,
  :class:`sim.batch._Stdout`);
* a results directory copied into another study's results (a user's copy): re-running
  that study kept the copy but dropped its ``run.json``, so the copy was no longer results
  (``sim.mc.publish._foreign`` took every ``run.json`` for the run's own);
* ``python -m sim.report.verify --results DIR`` from a directory without ``studies/``
  reported every study as FAILED (exit 1, and recorded so): now one line, exit 2;
* ``--out`` naming another study's results said "holds results of a different config; use
  --overwrite", and --overwrite then replaced brown_table1's results with a network's: the
  message names the other study (:func:`sim.mc.outputs._differs`);
* a name the figure font cannot draw (``network.name = "日本"``): matplotlib printed two
  warning lines per character and draw; now one note naming the figure and the characters
  (:func:`sim.report.plotting.save`);
* ``SOURCE_DATE_EPOCH`` that is not an integer: every entry point ended in a traceback from
  ``numpy.f2py`` while loading SciPy; now one line naming the variable, exit 2
  (:func:`sim.threads.refuse_bad_environment`);
* ``--out=~/x`` (the shell expands no ``~`` after ``=``) made a directory named ``~`` in
  the working directory and said "results in ~/x/"; such a path is refused, naming why
  (:func:`sim.mc.outputs.name_problem`);
* a study file given as a directory or a pipe (``cat x.toml | sim check /dev/stdin``) was
  "no such study file"; it is named for what it is (:func:`sim.mc.config.read_toml`);
* a key in another case (``--set TRIALS=40``) was "unknown key" with no guess
  (:func:`sim.mc.config.did_you_mean`).
"""

import contextlib
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from sim import batch, cli
from sim.cli_args import module_doc
from sim.mc.config import ConfigError, read_toml
from sim.report.mpl import pyplot as plt
from sim.report.plotting import save
from sim.report.verify import main as verify_main

STUDY = Path(__file__).resolve().parent.parent / "studies" / "network_plate.toml"


def _python(*args, env=None):
    return subprocess.run(
        [sys.executable, *args],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, **(env or {})},
    )


@pytest.mark.long
def test_python_OO_keeps_the_usage_text():
    assert module_doc(None, cli.__file__) == cli.__doc__ == cli.DOC
    assert module_doc(None, batch.__file__) == batch.__doc__
    p = _python("-OO", "-m", "sim.batch", "--help")
    assert p.returncode == 0 and "Traceback" not in p.stderr, p.stderr
    assert "python -m sim.batch" in p.stdout and "--stale-only" in p.stdout


def test_an_unknown_MPLBACKEND_does_not_stop_the_figures():
    code = (
        "import os\n"
        "from sim.report import mpl\n"
        "fig = mpl.pyplot.figure()\n"
        "print(type(fig.canvas).__name__, os.environ['MPLBACKEND'])\n"
    )
    p = _python("-c", code, env={"MPLBACKEND": "nosuch"})
    assert p.returncode == 0, p.stderr
    # drawn through an Agg canvas of the suite's own; the variable put back
    assert p.stdout.split() == ["FigureCanvasAgg", "nosuch"]


def test_a_study_file_with_a_byte_order_mark_is_read(tmp_path):
    text = STUDY.read_text(encoding="utf-8")
    (tmp_path / "bom.toml").write_bytes(b"\xef\xbb\xbf" + text.encode())
    (tmp_path / "u16.toml").write_bytes(text.encode("utf-16"))
    assert read_toml(tmp_path / "bom.toml") == read_toml(STUDY)
    with pytest.raises(ConfigError, match=r"u16.toml: not UTF-8 text \(.*UTF-16"):
        read_toml(tmp_path / "u16.toml")


@contextlib.contextmanager
def full_stdout():
    """Standard output on /dev/full (set inside the test: capsys replaces sys.stdout)."""
    full = open("/dev/full", "w", buffering=1)  # noqa: SIM115 - closed below
    try:
        with pytest.MonkeyPatch.context() as m:
            m.setattr(sys, "stdout", full)
            yield
    finally:
        with contextlib.suppress(OSError):  # what is left fails to flush, as it should
            full.close()


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_a_full_standard_output_is_named(capsys):
    with full_stdout():
        assert cli.main(["check", str(STUDY)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "sim: error: No space left on device: standard output", err


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_a_full_standard_output_ends_a_batch_in_one_line(capsys, monkeypatch):
    def run_all(files, results, jobs, run_args, stale_only, log, **_):
        log("network_plate: results in ...")
        return {"network_plate": (0, 1.0, 0.0)}

    monkeypatch.setattr(batch, "run_all", run_all)
    with full_stdout():
        assert batch.main([str(STUDY), "--results", "/nonexistent/r"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "sim.batch: standard output: No space left on device", err


def test_a_results_copy_inside_results_keeps_its_run_json(tmp_path, capsys):
    out = tmp_path / "r"
    run = ["run", str(STUDY), "--trials", "40", "--quiet", "--no-figures", "--out", str(out)]
    assert cli.main(run) == 0
    shutil.copytree(out, tmp_path / "copy")
    shutil.move(tmp_path / "copy", out / "copy")  # the user's copy of results, inside results
    before = sorted(p.relative_to(out / "copy") for p in (out / "copy").rglob("*"))
    assert cli.main([*run, "--overwrite", "--seed", "2"]) == 0, capsys.readouterr().err
    assert sorted(p.relative_to(out / "copy") for p in (out / "copy").rglob("*")) == before


def test_verify_outside_the_project_is_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert verify_main(["--results", str(tmp_path), "--no-record"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "no studies/ directory" in err, err


def test_another_studys_results_are_named_as_such(tmp_path, capsys):
    out = tmp_path / "r"
    out.mkdir()
    shutil.copy(STUDY.parent.parent / "results" / "brown_table1" / "run.json", out / "run.json")
    assert cli.main(["run", str(STUDY), "--trials", "40", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "holds results of another study ('brown_table1'; this run is 'network')" in err, err
    assert "\n" not in err


def test_characters_the_font_lacks_are_one_note(tmp_path, capsys):
    fig = plt.figure()
    fig.suptitle("日本 plate")
    save(fig, tmp_path / "f.png")
    err = capsys.readouterr().err.strip()
    assert err == "sim: note: f.png: its font has no glyph for '日本' (drawn as boxes)", err
    assert (tmp_path / "f.png").stat().st_size > 0


@pytest.mark.parametrize("module", ["sim", "sim.batch", "sim.report.verify", "benchmarks"])
def test_a_source_date_epoch_numpy_cannot_read_is_one_line(module):
    p = _python("-m", module, "--help", env={"SOURCE_DATE_EPOCH": "garbage"})
    err = p.stderr.strip()
    assert p.returncode == 2 and "\n" not in err and "SOURCE_DATE_EPOCH" in err, err


def test_an_unexpanded_tilde_is_refused(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["run", str(STUDY), "--trials", "40", "--out=~/x"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("sim: error: --out: starts with '~'") and "\n" not in err, err
    assert batch.main([str(STUDY), "--results=~/r"]) == 2
    assert "--results: starts with '~'" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_a_study_file_that_is_a_directory_or_a_pipe_is_named(tmp_path):
    with pytest.raises(ConfigError, match="is a directory, not a study file"):
        read_toml(tmp_path)
    os.mkfifo(tmp_path / "fifo.toml")
    with pytest.raises(ConfigError, match="not a regular file"):
        read_toml(tmp_path / "fifo.toml")


def test_a_key_in_another_case_gets_its_guess(capsys):
    assert cli.main(["check", str(STUDY), "--set", "TRIALS=40"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "sim: error: TRIALS: unknown key (did you mean trials?)", err
