"""The classes of the sweep doors45c (brief C45: the end of a publish, signals to ``python -m
sim.batch`` at each phase, two batches at once into one results root), one case each; each
failed on the code before its fix.

* SIGTERM (or Ctrl-C) to ``python -m sim.batch --report`` while its ``sim report`` rebuilt
  ``REPORT.md``: two lines, the report's own ``sim: interrupted`` and then the batch's
  ``sim.batch: interrupted while sim report rebuilt .../REPORT.md, which is as it was: ...``.
  The report's standard error is now kept until it ends and passed on, its interrupt line
  left out when it was interrupted (the batch's line says it): one line, exit 130
  (:mod:`sim.batch_report`).
"""

from __future__ import annotations

import sys

import sim.batch_report as br
from sim.batch_report import rebuild_report
from tests.oneline import one_line

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
