"""An item issue 26's last sessions left open (brief L31; its other items, done alike by
the lead the same session, are tested in test_lead31.py).

3. ``sim.load(...).run(out=None)`` killed outright (SIGKILL) left ``$TMPDIR/sim-<study>-XXXX/``
   forever. The name now holds the process id, and a later ``run(out=None)`` of the study
   removes the directories of dead processes it can prove are killed runs' (:mod:`sim.api_tmp`):
   never a live process's, another user's, one holding finished results or chunks a failed
   run named (marked), nor another study's.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile

import pytest
from conftest import ROOT

import sim
import sim.api
from sim.api_tmp import KEPT, MARK

BROWN = str(ROOT / "studies" / "brown_table1.toml")


def test_a_killed_runs_temporary_directory_is_cleared_by_the_next_run(tmp_path, monkeypatch):
    gone = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        check=True,
        capture_output=True,
        text=True,
    )
    dead, live = int(gone.stdout), os.getpid()
    made = {}
    for tag, pid, study, inside in (
        ("killed", dead, "brown_table1", ".staging/chunk-0.parquet"),
        ("live", live, "brown_table1", ".staging/chunk-0.parquet"),
        ("finished", dead, "brown_table1", "run.json"),
        ("kept", dead, "brown_table1", None),
        ("other", dead, "brown_dilution", ".staging/chunk-0.parquet"),
    ):
        d = tmp_path / f"sim-{study}-{pid}-{tag[:4]:_<8}"
        (d / study / inside if inside else d / study).parent.mkdir(parents=True)
        (d / MARK).write_text(str(pid))  # each a run's (doors37r: the marker is needed too)
        if inside:
            (d / study / inside).write_text("x")
        else:
            (d / KEPT).write_text("x")
        made[tag] = d
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))

    def killed(*a, **k):
        raise RuntimeError("stopped")

    monkeypatch.setattr(sim.api, "execute", killed)
    with pytest.raises(RuntimeError):
        sim.load(BROWN).run(trials=40, workers=1)
    assert not made["killed"].exists()
    assert all(made[t].exists() for t in ("live", "finished", "kept", "other"))
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        made[t].name for t in ("live", "finished", "kept", "other")
    )  # this run's own (empty) directory removed after its failure, as before
