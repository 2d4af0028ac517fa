"""Stop signals that Python would drop or die of (issue 26, left3).

* A Ctrl-C or SIGTERM (raised as ``KeyboardInterrupt``) inside a C callback, as numba's
  ``_raw_object_cache_notify``, was printed as "Exception ignored in: ... KeyboardInterrupt" and
  dropped: the run went on and exited 0. The tests drop one the same way, from a real ``ctypes``
  callback, at a chosen point of a run: a chunk, the pool's close, the run's summary; and in
  ``sim.batch``, ``make verify`` and the Python API.
* A stop signal after a command returned its exit code (while Python shuts down) killed the
  program by the signal (exit -2 or -15, no line) or printed a traceback of an atexit callback.
  The tests deliver it from an atexit callback or from a ``__del__`` of the teardown (a
  ``sitecustomize`` module in the program's path), so nothing races a sleep.
"""

import ctypes
import os
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from oneline import one_line, python_lines

import sim
import sim.batch
import sim.report.verify.cli as verify_cli
from sim import cli_check, cli_run, execute
from sim.cli import main
from sim.mc import executors
from sim.stops import check_interrupt, keep_lost_interrupts

ROOT = Path(__file__).resolve().parent.parent
PLATE = str(ROOT / "studies" / "network_plate.toml")
RUN = ["--quiet", "--no-figures", "--set", "trials=40", "--set", "chunk=2"]


def _drop_an_interrupt() -> None:
    """Ctrl-C landing in a C callback: Python can only report it as unraisable."""

    def callback():
        raise KeyboardInterrupt

    ctypes.CFUNCTYPE(None)(callback)()


def _interrupted(capsys, rc: int, prog: str = "sim") -> str:
    return one_line(capsys, rc, prefix=f"{prog}: interrupted", code=130)


def test_a_dropped_interrupt_is_kept_silently_and_raised_once(monkeypatch, capsys):
    seen = []

    def hook(u):
        seen.append(u)

    monkeypatch.setattr(sys, "unraisablehook", hook)
    with keep_lost_interrupts():
        _drop_an_interrupt()
        assert seen == [] and capsys.readouterr().err == ""
        with pytest.raises(KeyboardInterrupt):
            check_interrupt()
        check_interrupt()  # raised once
        ctypes.CFUNCTYPE(None)(lambda: 1 / 0)()  # any other goes to the hook that was there
        assert [u.exc_type for u in seen] == [ZeroDivisionError]
        with keep_lost_interrupts():  # nested (execute inside a command): one flag
            _drop_an_interrupt()
        with pytest.raises(KeyboardInterrupt):
            check_interrupt()
    assert sys.unraisablehook is hook  # put back
    _drop_an_interrupt()  # outside a command: Python's own business
    check_interrupt()
    assert [u.exc_type for u in seen] == [ZeroDivisionError, KeyboardInterrupt]


def test_an_interrupt_dropped_in_a_chunk_stops_the_run_resumably(tmp_path, monkeypatch, capsys):
    out = tmp_path / "np"
    call = executors._call_chunk

    def chunk(fn, seed, part, k, n):
        if k == 3:
            _drop_an_interrupt()
        return call(fn, seed, part, k, n)

    monkeypatch.setattr(executors, "_call_chunk", chunk)
    _interrupted(capsys, main(["run", PLATE, "--out", str(out), *RUN]))
    assert not out.exists()
    stage = tmp_path / ".np.partial"
    assert len(list(stage.rglob("chunk-*.parquet"))) == 4  # chunks 0 to 3, the last one saved
    monkeypatch.setattr(executors, "_call_chunk", call)
    assert main(["run", PLATE, "--out", str(out), *RUN]) == 0
    assert "4 finished chunks found" in capsys.readouterr().err
    assert main(["run", PLATE, "--out", str(tmp_path / "whole"), *RUN]) == 0
    resumed, whole = (pq.read_table(d / "claims.parquet") for d in (out, tmp_path / "whole"))
    assert resumed.column("value").to_pylist() == whole.column("value").to_pylist()


def test_an_interrupt_dropped_after_the_last_chunk_is_not_published(tmp_path, monkeypatch, capsys):
    out = tmp_path / "np"
    made = execute.make_executor

    def executor(*args):
        ex = made(*args)
        close = ex.close
        ex.close = lambda kill=False: (_drop_an_interrupt(), close(kill))
        return ex

    monkeypatch.setattr(execute, "make_executor", executor)
    _interrupted(capsys, main(["run", PLATE, "--out", str(out), *RUN]))
    assert not out.exists() and len(list((tmp_path / ".np.partial").rglob("chunk-*"))) == 20


def test_an_interrupt_dropped_after_publishing_is_not_exit_0(tmp_path, monkeypatch, capsys):
    summary = cli_run.terminal_summary  # the first step after publishing (the README is before)
    monkeypatch.setattr(
        cli_run, "terminal_summary", lambda *a, **k: (_drop_an_interrupt(), summary(*a, **k))[1]
    )
    err = _interrupted(capsys, main(["run", PLATE, "--out", str(tmp_path / "np"), *RUN]))
    assert err == f"sim: interrupted after the results were written to {tmp_path / 'np'}/", err
    assert (tmp_path / "np" / "claims.parquet").is_file()  # published, complete
    monkeypatch.setattr(cli_check, "check", lambda args: (_drop_an_interrupt(), 0)[1])
    _interrupted(capsys, main(["check", PLATE]))  # any command


def test_the_api_raises_an_interrupt_dropped_in_a_chunk(tmp_path, monkeypatch):
    call = executors._call_chunk
    monkeypatch.setattr(
        executors,
        "_call_chunk",
        lambda fn, seed, part, k, n: (k == 5 and _drop_an_interrupt(), call(fn, seed, part, k, n))[
            1
        ],
    )
    handle = sim.load(PLATE, trials=40, chunk=2)
    with pytest.raises(KeyboardInterrupt):
        handle.run(out=tmp_path / "np", figures=False)
    assert not (tmp_path / "np").exists()


def test_batch_and_verify_do_not_end_0_after_a_dropped_interrupt(tmp_path, monkeypatch, capsys):
    timings = tmp_path / "t.json"
    monkeypatch.setattr(sim.batch, "run_all", lambda *a, **k: (_drop_an_interrupt(), {})[1])
    rc = sim.batch.main([PLATE, "--results", str(tmp_path), "--timings", str(timings)])
    assert _interrupted(capsys, rc, "sim.batch") == sim.batch.INTERRUPTED
    assert not timings.exists()  # its final output is not written
    monkeypatch.chdir(ROOT)
    monkeypatch.setattr(verify_cli, "verify", lambda *a, **k: (_drop_an_interrupt(), [])[1])
    rc = verify_cli.main(["--results", str(tmp_path), "--scratch", str(tmp_path / "s")])
    err = _interrupted(capsys, rc, "sim verify")  # dropped as the comparisons ended (test_doors33a)
    record = tmp_path / "reproducibility.parquet"
    assert (
        err == f"sim verify: interrupted after the comparisons; they were not recorded in {record}"
    )
    assert not (tmp_path / "reproducibility.parquet").exists()  # nor is the record


_LATE = """import atexit, os, signal
SIG = getattr(signal, os.environ["LATE_SIG"])
if os.environ["LATE_WHEN"] == "atexit":  # registered first: the last atexit callback but ours
    atexit.register(os.kill, os.getpid(), SIG)
else:  # a module's object torn down after Python reset its handlers
    class _Late:
        def __del__(self):
            os.kill(os.getpid(), SIG)
    _late = _Late()
"""


def _late_signal(tmp_path, when: str, sig: str, *argv: str) -> subprocess.CompletedProcess:
    (tmp_path / "sitecustomize.py").write_text(_LATE)
    env = {**os.environ, "PYTHONPATH": str(tmp_path), "LATE_WHEN": when, "LATE_SIG": sig}
    return subprocess.run(
        [sys.executable, "-m", *argv],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.mark.parametrize("when", ["atexit", "teardown"])
@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_signal_after_sim_returned_leaves_its_exit_code(tmp_path, when, sig):
    """Before: killed by the signal (-2, -15) with no line, or an atexit traceback, exit 0."""
    done = _late_signal(tmp_path, when, sig, "sim", "check", PLATE)
    assert done.returncode == 0 and done.stderr == "", (done.returncode, done.stderr[-500:])
    assert done.stdout.startswith("# network")


@pytest.mark.parametrize(
    "argv, line",
    [
        (["sim.batch", "nosuch.toml"], "sim.batch: nosuch.toml: no such study file\n"),
        (["sim.report.verify", "--workers", "0"], "sim verify: error: argument --workers: must be"),
    ],
)
def test_a_signal_after_batch_or_verify_returned_leaves_its_exit_code(tmp_path, argv, line):
    done = _late_signal(tmp_path, "teardown", "SIGINT", *argv)
    assert done.returncode == 2 and done.stderr.startswith(line), done
    assert done.stderr.count("\n") == 1, done.stderr


def test_a_signal_as_the_program_ends_exits_at_once_with_the_commands_code():
    """A stop signal after the command returned and before Python's teardown (an atexit
    callback registered after the suite's) ends the process with the command's code; one as
    the command returns (a KeyboardInterrupt out of main) is one line and 130."""
    done = python_lines(
        "import atexit, os, signal, sys",
        "from sim.threads import interrupt_while_loading",
        "loaded = interrupt_while_loading('sim')",
        "from sim.stops import run_program",
        "def command():",
        "    atexit.register(os.kill, os.getpid(), signal.SIGTERM)",
        "    print('done')",
        "    return 3",
        "sys.exit(run_program('sim', command, loaded))",
    )
    assert done.returncode == 3 and done.stdout == "done\n" and done.stderr == "", done
    done = python_lines(
        "import sys",
        "from sim.threads import interrupt_while_loading",
        "loaded = interrupt_while_loading('sim')",
        "from sim.stops import run_program",
        "def command():",
        "    raise KeyboardInterrupt",
        "sys.exit(run_program('sim', command, loaded))",
    )
    assert done.returncode == 130 and done.stderr == "sim: interrupted\n", done
