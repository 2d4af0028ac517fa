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
import threading
from pathlib import Path

from sim.held_stops import held_stops
from sim.mc.children import STOP_SIGNALS, child_env, child_text, stop_children
from sim.report.markdown import _ours
from sim.report_due import mark_due

__all__ = ["rebuild_report", "not_rebuilt", "report_problem"]


def report_problem(results: Path) -> str | None:
    """Why ``sim report`` would refuse to rebuild ``RESULTS/REPORT.md`` (a file, link or
    directory of that name the suite did not write: it never replaces one), asked before the
    runs: the batch ran every study, for hours, and then failed on its report."""
    out = Path(results) / "REPORT.md"
    if out.is_symlink() or (out.exists() and not _ours(out)):
        return f"--report: {out} was not written by sim report; sim never replaces it"
    return None


def rebuild_report(results: Path) -> int:
    """Run ``sim report --results RESULTS`` (its lines go to this process's standard output
    and error, as make's own command's did); its exit code (2 with one line when it cannot
    start). An interrupt while it runs reaches it too (Ctrl-C) or is passed on (SIGTERM): it
    is waited for (``REPORT.md`` written whole or not at all) and said in one line, 130: the
    batch's, which says that the report was left as it was (``sim report``'s own "sim:
    interrupted" is held back, so one interrupt is one line). One that comes while the
    process starts is handled once it has started (it was a ``KeyboardInterrupt`` out of
    ``Popen``, the report skipped and never said)."""
    cmd = [sys.executable, "-m", "sim", "report", f"--results={results}"]  # (a name "-r")
    proc = held = None
    mark_due(results)  # cleared by sim report once REPORT.md is written (kill -9: said later)
    try:
        try:
            with held_stops():
                proc = subprocess.Popen(
                    cmd,
                    stderr=subprocess.PIPE,
                    env=child_env(),
                    preexec_fn=_stoppable,
                    **child_text(),
                )
                held = _pass_on(proc.stderr)
        except OSError as e:  # no process to be had (ulimit -u): one line
            why = e.strerror or e
            print(f"sim.batch: --report: cannot start sim report: {why}", file=sys.stderr)
            return 2
        code = proc.wait()
    except KeyboardInterrupt:  # Ctrl-C reached it too; SIGTERM (to the batch) is passed on
        if proc is not None:
            stop_children([proc])
        code = 130
    if held is not None:
        held.join()
        if code != 130:  # (a line held back that was not an interrupt's: said after all)
            sys.stderr.writelines(held.lines)
    if code == 130:  # (an interrupted batch ignores a second Ctrl-C: the report alone ends)
        print(
            f"sim.batch: interrupted while sim report rebuilt {results / 'REPORT.md'}, which "
            f"is as it was: sim report --results {results} rebuilds it",
            file=sys.stderr,
        )
    return code if code >= 0 else 1  # killed by a signal (the OOM killer)


def not_rebuilt(results: str) -> str:
    """How the batch's line of an interrupt after every run ended, before ``sim report``
    started, ends: the report was due and is not rebuilt (the line said only that the runs
    ended, and the report was skipped without a word)."""
    return (
        f"{Path(results) / 'REPORT.md'} was not rebuilt: sim report --results {results} rebuilds it"
    )


#: how ``sim report`` begins the line of an interrupt (:func:`sim.cli._interrupted_line`)
_ITS_INTERRUPT = "sim: interrupted"


def _pass_on(stream) -> threading.Thread:
    """A thread that copies ``sim report``'s standard error to the batch's as it comes, but
    for its line of an interrupt, kept in the thread's ``lines``."""

    def copy() -> None:
        with stream:
            for line in stream:
                if line.startswith(_ITS_INTERRUPT):
                    t.lines.append(line)
                else:
                    sys.stderr.write(line)
                    sys.stderr.flush()

    t = threading.Thread(target=copy, daemon=True)
    t.lines = []
    t.start()
    return t


def _stoppable() -> None:
    """In the child before it starts: Ctrl-C and SIGTERM as by default (a batch interrupted
    ignores them from then on, and an ignored SIGINT stays ignored in the report's Python)."""
    for s in (signal.SIGINT, *STOP_SIGNALS):
        signal.signal(s, signal.SIG_DFL)
