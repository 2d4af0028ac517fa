"""``python -m sim.batch --report``: the report of the results directory built again after the
runs, in a ``sim report`` process of its own (as ``make reproduce`` and ``make rerun`` ran it).

After runs that all ended well it is built always (a batch of up-to-date studies included: the
report's own code may be newer). After a batch that failed or was interrupted it is built when
a run published its results, and only then: ``make reproduce`` stopped before ``sim report``
when one study's run failed or was killed, so ``REPORT.md`` kept the claims the published
studies had before (and the *Reproducibility* section called their replaced tables verified)
until the next make succeeded; a batch that published nothing (its input refused, every run
failed) leaves the report as it is, and its failure line alone.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import tempfile
from pathlib import Path

from sim.mc.children import STOP_SIGNALS, child_env, stop_children

__all__ = ["rebuild_report"]


def rebuild_report(results: Path) -> int:
    """Run ``sim report --results RESULTS`` (its lines go to this process's standard output
    and error, as make's own command's did: its standard error once it ended, so that an
    interrupt is said in the batch's one line, not also in the report's); its exit code (2 with one line when it cannot
    start). An interrupt while it runs reaches it too (Ctrl-C) or is passed on (SIGTERM): it
    is waited for (``REPORT.md`` written whole or not at all) and said in one line, 130 (the
    batch's own line did not say that the report was left as it was)."""
    cmd = [sys.executable, "-m", "sim", "report", f"--results={results}"]  # (a name "-r")
    try:  # its standard error kept until it ends (a file: it never waits on a pipe)
        err = tempfile.TemporaryFile()
    except OSError:  # no temporary directory to be had: its lines go out as it says them
        err = None
    try:
        code = _report(cmd, err)
        said = _read(err)
    except OSError as e:  # no process to be had (ulimit -u): one line
        print(f"sim.batch: --report: cannot start sim report: {e.strerror or e}", file=sys.stderr)
        return 2
    finally:
        if err is not None:
            err.close()
    if code == 130:  # its own "sim: interrupted" left out: the batch's line says what it was
        said = "".join(ln for ln in said.splitlines(True) if not ln.startswith("sim: interrupted"))
    sys.stderr.write(said)
    sys.stderr.flush()
    if code == 130:  # (an interrupted batch ignores a second Ctrl-C: the report alone ends)
        print(
            f"sim.batch: interrupted while sim report rebuilt {results / 'REPORT.md'}, which "
            f"is as it was: sim report --results {results} rebuilds it",
            file=sys.stderr,
        )
    return code if code >= 0 else 1  # killed by a signal (the OOM killer)


def _report(cmd: list[str], err) -> int:
    """Run ``cmd`` (``sim report``) with its standard error into the file ``err``; its exit
    code, 130 when an interrupt reached it (Ctrl-C) or was passed on to it (SIGTERM): it is
    waited for, so ``REPORT.md`` is written whole or not at all."""
    proc = subprocess.Popen(cmd, env=child_env(), stderr=err, preexec_fn=_stoppable)
    try:
        return proc.wait()
    except KeyboardInterrupt:  # Ctrl-C reached it too; SIGTERM (to the batch) is passed on
        stop_children([proc])
        return 130


def _read(err) -> str:
    """The text of the temporary file ``err`` (``""`` without one)."""
    if err is None:
        return ""
    try:
        err.seek(0)
        said = err.read()
    except OSError:  # (EIO) what it said is lost, not its exit code
        return ""
    return said.decode(getattr(sys.stderr, "encoding", None) or "utf-8", "replace")


def _stoppable() -> None:
    """In the child before it starts: Ctrl-C and SIGTERM as by default (a batch interrupted
    ignores them from then on, and an ignored SIGINT stays ignored in the report's Python)."""
    for s in (signal.SIGINT, *STOP_SIGNALS):
        signal.signal(s, signal.SIG_DFL)
