"""The failure classes of the fifth sweep of bad inputs (issue 26, part B: the command line,
``sim.batch``, ``make verify``, ``sim report`` and signals), one case per class: each is
refused with exit 2 and one line naming the key or the argument, nothing is written, and a
signal ends every process a command started.

* ``sim check`` with a bad ``SIM_MAX_MEMORY_GB`` exited 0 (``sim run`` refuses it): it now
  applies the limits of the run (``check_limits``) to its estimate;
* an empty path (``--timings ''``, a study file ``''``) was taken for the working directory or
  for no option at all;
* SIGTERM or SIGHUP to ``python -m sim.batch`` or ``python -m sim.report.verify`` left their
  ``sim run`` processes running (the batch waited for them to finish, verify died at once).

Found by the fresh set (``/tmp/doors6b``, outside the project):

* a path of bytes that are not UTF-8 (a Latin-1 name; any non-ASCII name in a C locale
  without UTF-8 mode) was refused as "a control character", or, as a study file's ``--out``,
  failed at the end of the run (UnicodeEncodeError writing its provenance);
* ``sim report`` on a results directory missing a table printed the bare path (pyarrow's
  ``FileNotFoundError(path)`` has no reason);
* a HOME or MPLCONFIGDIR that is not writable: matplotlib's two warning lines on every run;
* run options of ``sim.batch`` read only by each run: ``-- --ou DIR`` (``--out`` abbreviated)
  sent every study into one directory, each replacing the last (``--overwrite``); ``--help``
  made every "run" exit 0 without running; a bad value gave one line per study;
* a study file named ``...toml`` (stem ``..``) wrote its results over ``<results>/..``;
* ``make verify --workers 100000`` (or a ``--scratch`` under a file) recorded a failed
  comparison over the committed record instead of naming the option;
* a symlink loop as ``--timings`` or ``--scratch``, and a ``run.json`` nested deeper than
  the recursion limit: tracebacks;
* SIGTERM to ``sim report`` (or ``check``, ``show``) killed it at once, leaving the temporary
  file of a README.md being written; it now cleans up and says one line, as ``sim run``;
* SIGTERM to a Dask run (``--executor dask``) printed, about one time in seven, tornado's
  "Exception in callback" traceback of a worker heartbeat's closed connection: the loggers
  of the closing connections (each child logger, whatever level dask's config gave it) are
  silenced before an interrupted run closes its client.
"""

import logging
import os
import shutil
import signal
import stat
import sys
import threading
import time
from pathlib import Path

import pytest
from oneline import one_line

import sim.__main__  # noqa: F401 - the sim command's set-up (its log filter)
from sim import batch, cli_read, execute
from sim.cli import main
from sim.mc.storage import write_record, write_table
from sim.report.verify import main as verify_main

ROOT = Path(__file__).resolve().parent.parent
BROWN = ROOT / "studies" / "brown_table1.toml"


@pytest.mark.parametrize(
    "env, value", [("SIM_MAX_MEMORY_GB", "abc"), ("SIM_MAX_ADJUSTMENTS", "inf")]
)
def test_check_applies_the_limits_of_the_run(capsys, monkeypatch, env, value):
    monkeypatch.setenv(env, value)
    one_line(capsys, main(["check", str(BROWN)]), env, prefix="sim: error: ")
    assert capsys.readouterr().out == ""


def test_an_empty_path_is_named(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    one_line(capsys, batch.main(["--timings", "", str(BROWN)]), "--timings", prefix="sim.batch: ")
    one_line(capsys, batch.main(["", str(BROWN)]), "FILE", "''", prefix="sim.batch: ")
    one_line(capsys, main(["check", ""]), "STUDY", "''", prefix="sim: error: ")
    assert list(tmp_path.iterdir()) == []


def _fake_python(tmp_path: Path) -> Path:
    """An "interpreter" that records its pid and sleeps: the run a signal must end."""
    exe = tmp_path / "python"
    exe.write_text(f"#!/bin/sh\necho $$ >> {tmp_path}/pids\nexec sleep 30\n")
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR)
    return exe


def _signal_soon(tmp_path: Path, sig: int) -> None:
    """Send ``sig`` to this process once a run has started (its pid recorded)."""

    def send():
        for _ in range(200):
            if (tmp_path / "pids").is_file():
                break
            time.sleep(0.01)
        time.sleep(0.05)
        os.kill(os.getpid(), sig)

    threading.Thread(target=send, daemon=True).start()


def _all_ended(tmp_path: Path) -> None:
    for pid in map(int, (tmp_path / "pids").read_text().split()):
        with pytest.raises(ProcessLookupError):  # ended and reaped
            os.kill(pid, 0)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_to_batch_ends_its_runs(tmp_path, capsys, monkeypatch, sig):
    monkeypatch.setattr(sys, "executable", str(_fake_python(tmp_path)))
    before = signal.getsignal(sig)
    _signal_soon(tmp_path, sig)
    t = time.monotonic()
    code = batch.main(
        ["--results", str(tmp_path / "r"), str(BROWN), str(ROOT / "studies/wolf_polynomial.toml")]
    )
    assert time.monotonic() - t < 10
    one_line(capsys, code, prefix="sim.batch: interrupted", code=130)
    _all_ended(tmp_path)
    assert signal.getsignal(sig) is before  # the caller's handler is back


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_to_verify_ends_its_rerun(tmp_path, capsys, monkeypatch, sig):
    d = tmp_path / "res" / "brown_table1"
    d.mkdir(parents=True)
    run = {"config": {"study": "brown_table1"}, "code_hash": "0" * 16}  # its run's record
    write_record(d, run)  # (a directory without one is refused: doors47k)
    write_table(
        d / "claims.parquet",
        {"claim": ["x"], "verdict": ["holds"]},
        {"study": "brown_table1", **run},
    )
    monkeypatch.chdir(ROOT)  # the re-run reads studies/<study>.toml
    monkeypatch.setattr(sys, "executable", str(_fake_python(tmp_path)))
    before = signal.getsignal(sig)
    _signal_soon(tmp_path, sig)
    t = time.monotonic()
    code = verify_main(["--results", str(d.parent), "--scratch", str(tmp_path / "s")])
    assert code == 130 and time.monotonic() - t < 10
    err = capsys.readouterr().err.strip().splitlines()
    assert "interrupted" in err[-1] and not any("Traceback" in e for e in err), err
    _all_ended(tmp_path)
    assert signal.getsignal(sig) is before
    assert sorted(p.name for p in d.parent.iterdir()) == ["brown_table1"]  # no record


@pytest.mark.parametrize("cmd", [["run", str(BROWN), "--out"], ["show"], ["check"]])
def test_a_path_that_is_not_utf8_is_named(tmp_path, capsys, cmd):
    name = str(tmp_path / "caf\udce9")  # b"caf\xe9" as Python keeps it
    one_line(capsys, main([*cmd, name]), "UTF-8", prefix="sim: error: ")
    assert list(tmp_path.iterdir()) == []


def test_report_names_a_missing_table_and_why(tmp_path, capsys):
    d = tmp_path / "r" / "network_testfield"
    shutil.copytree(ROOT / "results" / "network_testfield", d)
    gone = next(p for p in sorted(d.glob("*.parquet")) if p.name != "claims.parquet")
    gone.unlink()
    one_line(capsys, main(["report", "--results", str(d.parent)]), "No such", prefix="sim: error: ")
    assert not (d.parent / "REPORT.md").exists()


def test_an_unwritable_matplotlib_config_directory_is_not_reported():
    """The ``sim`` command (sim.__main__) drops matplotlib's warnings that its config
    directory is not writable (it then uses a temporary one), and no other warning."""
    log = logging.getLogger("matplotlib")
    for msg, shown in [
        ("mkdir -p failed for path %s: %s", False),
        ("%s is not a writable directory", False),
        ("Matplotlib created a temporary cache directory at %s because ...", False),
        ("Duplicate key in file %r, line %d (%r)", True),
    ]:
        rec = log.makeRecord("matplotlib", logging.WARNING, __file__, 1, msg, (), None)
        assert bool(log.filter(rec)) is shown, msg


@pytest.mark.parametrize(
    "opts, words",
    [
        (["--ou", "X"], "--out"),
        (["--help"], "help"),
        (["--workers", "0"], "--workers"),
        (["--trials", "1000.5"], "--trials"),  # 1e3 is 1000 (left15), as --set reads it
    ],
)
def test_batch_reads_the_run_options_before_any_run(tmp_path, capsys, opts, words):
    argv = ["--results", str(tmp_path / "r"), str(BROWN), "--", *opts]
    one_line(capsys, batch.main(argv), words, prefix="sim.batch: run options: ")
    assert list(tmp_path.iterdir()) == []


def test_batch_refuses_a_study_file_named_dot_dot(tmp_path, capsys):
    f = tmp_path / "...toml"
    shutil.copy(BROWN, f)
    one_line(
        capsys, batch.main(["--results", str(tmp_path / "r" / "x"), str(f)]), prefix="sim.batch: "
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["...toml"]


def test_verify_names_a_worker_count_the_rerun_refuses(tmp_path, capsys):
    d = tmp_path / "res" / "brown_table1"
    d.mkdir(parents=True)
    write_table(d / "claims.parquet", {"claim": ["x"], "verdict": ["h"]}, {"study": "brown_table1"})
    code = verify_main(["--results", str(d.parent), "--workers", "100000"])
    one_line(capsys, code, "--workers", prefix="sim verify: error: ")
    assert sorted(p.name for p in d.parent.iterdir()) == ["brown_table1"]  # no record


def test_a_symlink_loop_or_a_deep_run_record_is_one_line(tmp_path, capsys):
    (tmp_path / "loop").symlink_to("loop")
    argv = ["--timings", str(tmp_path / "loop"), str(BROWN)]
    one_line(capsys, batch.main(argv), "loop", prefix="sim.batch: --timings")
    d = tmp_path / "res" / "brown_table1"
    d.mkdir(parents=True)
    write_table(d / "claims.parquet", {"claim": ["x"], "verdict": ["h"]}, {"study": "brown_table1"})
    argv = ["--results", str(d.parent), "--scratch", str(tmp_path / "loop")]
    one_line(capsys, verify_main(argv), "loop", prefix="sim verify: error: --scratch")
    (tmp_path / "o").mkdir()
    (tmp_path / "o" / "run.json").write_text("[" * 100_000)
    assert not batch.is_current(BROWN, tmp_path / "o")
    one_line(capsys, main(["run", str(BROWN), "--out", str(tmp_path / "o")]), prefix="sim: error: ")


def test_a_signal_to_report_cleans_up_with_one_line(tmp_path, capsys, monkeypatch):
    d = tmp_path / "r" / "network_testfield"
    shutil.copytree(ROOT / "results" / "network_testfield", d)
    tmp = d / ".README.md.tmp"

    def write_report(results, get_study, design=None, studies=()):  # killed half written
        try:
            tmp.write_text("half")
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(5)
        finally:
            tmp.unlink()

    monkeypatch.setattr(cli_read, "write_report", write_report)
    t = time.monotonic()
    code = main(["report", "--results", str(d.parent)])
    err = capsys.readouterr().err
    assert code == 130 and err == "sim: interrupted\n" and time.monotonic() - t < 4, err
    assert not tmp.exists() and signal.getsignal(signal.SIGTERM) is signal.SIG_DFL


def test_an_interrupted_dask_run_closes_without_dask_logs():
    """Each logger below asyncio, distributed and tornado, whatever its level, is silenced
    (the closing chatter came from child loggers dask's config set to INFO or ERROR)."""
    loggers = [logging.getLogger(n) for n in ("distributed.comm.tcp", "tornado.application")]
    for log in loggers:
        log.setLevel(logging.INFO)
    try:
        execute._quiet_dask_logs()
        assert not any(log.isEnabledFor(logging.CRITICAL) for log in loggers)
        assert logging.getLogger("sim").isEnabledFor(logging.WARNING)
    finally:
        for n in (
            "asyncio",
            "distributed",
            "tornado",
            "distributed.comm.tcp",
            "tornado.application",
        ):
            logging.getLogger(n).setLevel(logging.NOTSET)
