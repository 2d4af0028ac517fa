"""The classes of the sweep doors45c (brief C45: the end of a publish, signals to ``python -m
sim.batch`` at each phase, two batches at once into one results root), one case each; each
failed on the code before its fix.

* SIGTERM (or Ctrl-C) to ``python -m sim.batch --report`` while its ``sim report`` rebuilt
  ``REPORT.md``: two lines, the report's own ``sim: interrupted`` and then the batch's
  ``sim.batch: interrupted while sim report rebuilt .../REPORT.md, which is as it was: ...``.
  The report's standard error is now kept until it ends and passed on, its interrupt line
  left out when it was interrupted (the batch's line says it): one line, exit 130
  (:mod:`sim.batch_report`).
* A signal to ``python -m sim.batch --stale-only`` while it asked which studies are current
  (each study's tables and figures hashed against its run record: seconds for the project's
  results) said "interrupted; the same command again resumes the unfinished runs" of a batch
  that had started none. It says ``sim.batch: interrupted before any run started: nothing was
  run``, as while it checked its files; so does one after those checks, before the first run
  started.

Held (found right, on top of F44's ``<out>/.lock``, merged here): a run held at the end of its
publish (before removing the replaced results, before its record without ``replaced``): a
second run is refused naming its pid, ``sim show`` and ``sim report`` read the new results
whole, and the first ends 0 with one run's results. SIGTERM, SIGHUP or Ctrl-C to ``python -m
sim.batch --report`` (``--jobs 2``, run options ``--workers 2`` and ``--executor dask
--workers 2``) as a run starts, as its pool or cluster starts, with chunks written, between two
runs (``--jobs 1``) and during the report: exit 130, one line, no process left, and the same
command again resumes and ends 0. Two batches at once over overlapping study lists into one
results root (other seeds, ``--report``): each run either ran or was refused in one line
naming the pid of the run writing it; the results are whole runs and ``REPORT.md`` names the
seeds of the results it sits beside.
"""

from __future__ import annotations

import os
import shutil
import signal
import sys
from pathlib import Path

import sim.batch
import sim.batch_report as br
from sim.batch_report import rebuild_report
from tests.oneline import one_line

ROOT = Path(__file__).resolve().parent.parent

#: a ``sim report`` that an interrupt ended: its own line, its exit code
INTERRUPTED_REPORT = "import sys; sys.stderr.write('sim: interrupted\\n'); sys.exit(130)"


def test_a_report_interrupted_by_the_batch_is_said_in_one_line(tmp_path, monkeypatch, capfd):
    real = br.subprocess.Popen
    monkeypatch.setattr(
        br.subprocess,
        "Popen",
        lambda cmd, **k: real([sys.executable, "-c", INTERRUPTED_REPORT], **k),
    )
    # before: "sim: interrupted" and then the batch's line
    one_line(capfd, rebuild_report(tmp_path / "res"), "which is as it was", code=130)


def test_a_batch_interrupted_while_it_asks_which_studies_are_current_says_nothing_ran(
    tmp_path, monkeypatch, capsys
):
    plate = tmp_path / "network_plate.toml"
    shutil.copyfile(ROOT / "studies" / plate.name, plate)

    def asking(*a, **k):
        os.kill(os.getpid(), signal.SIGTERM)  # handled before the next line of Python runs
        raise AssertionError("not interrupted")

    monkeypatch.setattr(sim.batch, "why_stale", asking)
    argv = [str(plate), "--stale-only", "--results", str(tmp_path / "r"), "--", "--trials", "40"]
    # before: "sim.batch: interrupted; the same command again resumes the unfinished runs"
    line = one_line(capsys, sim.batch.main(argv), code=130)
    assert line == sim.batch.NOTHING_RUN and not (tmp_path / "r").exists()
