"""The classes of the sweep doors42k (brief K42: the make targets and the report after a
failure), one case each; each failed on the code before its fix.

* ``make reproduce`` and ``make rerun`` stopped before ``sim report`` when one study's run
  failed or was killed (``kill -9`` of its ``sim run``: "its run was killed by SIGKILL"), so
  ``results/REPORT.md`` kept the claims of the studies that did publish as they were before
  (checked in a copy of the project: a run with ``--seed 9`` published, REPORT.md still said
  ``seed`` = 5) until the next make succeeded. The batch now rebuilds the report itself
  (``python -m sim.batch --report``, :mod:`sim.batch_report`): after runs that all ended
  well, and after a failed or interrupted batch when a run published its results; one that
  published nothing (every run failed) leaves the report and its failure line alone.
  Checked in the copy: a run killed (``kill -9``) and Ctrl-C as ``brown_table1`` published
  (both: REPORT.md then named its new ``seed``). A Ctrl-C that ends the report itself is said
  in one line (REPORT.md as it was; ``sim report`` rebuilds it): the batch said only
  "interrupted after every run ended".
* the consistent regions (``sim.report.region.fig_region``, called directly by four studies,
  and brown's own) and a sweep's figure (``fig_sweep``) were drawn outside the figure lock
  ``DRAWING`` that ``draw()`` holds, so two API runs in threads of one program could draw at
  once (matplotlib is not thread-safe). They hold it now (:mod:`sim.report.drawing`); a
  figure drawn inside a ``draw()`` job goes on without taking it again (a second acquire of
  the plain lock waited for itself: that case is checked too, in a thread with a timeout).

Held (found right): each study's README.md is written inside its run's sealed staging
directory, so it never disagrees with the tables beside it; ``results/reproducibility.parquet``
holds the sha256 of the tables it compared, so a rebuilt report marks re-published studies
"not checked now"; the batch names the failed study in its own line (``network_plate.toml:
its run was killed by SIGKILL; ...``) and make exits 2 naming the batch's code.
"""

from __future__ import annotations

import importlib
import shutil
import sys
import threading
from pathlib import Path

import pytest
from test_doors18c import MAKE, fake_project, run_make

from sim import batch
from sim.batch_report import rebuild_report
from sim.report.plotting import DRAWING, draw

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize(
    ("codes", "rebuilt", "code"),
    [((0, 1), True, 1), ((1, 1), False, 1), ((0, 0), True, 0), ((), True, 0)],
)
def test_a_batch_whose_run_failed_rebuilds_the_report_of_those_that_published(
    tmp_path, monkeypatch, codes, rebuilt, code
):
    files = [tmp_path / f for f in ("brown_table1.toml", "network_plate.toml")]
    for f in files:
        shutil.copyfile(ROOT / "studies" / f.name, f)
    ran = dict(zip([f.stem for f in files], [(c, 1.0, 0.0) for c in codes]))
    monkeypatch.setattr(batch, "run_all", lambda *a, **k: ran)  # () : every study up to date
    calls = []
    monkeypatch.setattr(batch, "rebuild_report", lambda r: calls.append(r) or 0)
    res = tmp_path / "res"
    assert batch.main(["--report", "--results", str(res), *map(str, files)]) == code
    assert calls == ([res] if rebuilt else [])


def test_the_report_is_rebuilt_in_a_sim_report_of_its_own(tmp_path, capfd):
    (tmp_path / "empty").mkdir()  # no results: sim report's own line, its exit code
    assert rebuild_report(tmp_path / "empty") == 2
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and "empty" in err, err


@pytest.mark.skipif(MAKE is None, reason="no make on this machine")
@pytest.mark.parametrize("target", ["reproduce", "rerun"])
def test_make_reproduce_and_rerun_leave_the_report_to_the_batch(tmp_path, target):
    log, fake = tmp_path / "calls.log", tmp_path / "python"
    fake.write_text(  # a Python whose batch fails, every other command succeeds
        f'#!/bin/sh\necho "$*" >> {log}\ncase "$*" in *sim.batch*) exit 1;; esac\n',
        encoding="utf-8",
    )
    fake.chmod(0o755)
    p = run_make(fake_project(tmp_path, str(fake)), target)
    calls = [ln for ln in log.read_text(encoding="utf-8").splitlines() if ln.startswith("-m ")]
    assert len(calls) == 1 and calls[0].startswith("-m sim.batch "), calls
    assert " --report " in calls[0] and p.returncode == 2, (calls, p.stderr)


def test_a_report_interrupted_as_it_is_rebuilt_is_said(tmp_path, monkeypatch, capfd):
    import sim.batch_report as br

    real = br.subprocess.Popen  # a sim report ended by Ctrl-C (its exit 130)
    monkeypatch.setattr(
        br.subprocess, "Popen", lambda cmd, **k: real([sys.executable, "-c", "exit(130)"], **k)
    )
    assert rebuild_report(tmp_path / "res") == 130
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and "which is as it was: sim report --results" in err, err


#: the figures drawn outside draw()'s jobs: (module, function, its arguments)
DIRECT = [
    ("sim.report.region", "fig_region", (None, Path("r.png"))),
    ("sim.studies.brown.figures", "fig_region", (Path("."), [], Path("r.png"))),
    ("sim.report.sweep", "fig_sweep", (Path("sweep.parquet"), Path("sweep.png"))),
]


@pytest.mark.parametrize(("module", "name", "args"), DIRECT)
def test_a_figure_drawn_directly_holds_the_figure_lock(monkeypatch, module, name, args):
    mod = importlib.import_module(module)
    held = []  # figures_off is the figure's first step: "off" here, nothing drawn
    monkeypatch.setattr(mod, "figures_off", lambda: held.append(DRAWING.locked()) or True)
    getattr(mod, name)(*args)
    assert held == [True] and not DRAWING.locked()


def test_a_figure_drawn_inside_a_draw_job_does_not_wait_for_itself(monkeypatch):
    import sim.report.region as region

    held = []
    monkeypatch.setattr(region, "figures_off", lambda: held.append(DRAWING.locked()) or True)
    t = threading.Thread(target=draw, args=([(region.fig_region, (None, Path("r.png")))],))
    t.daemon = True  # (a deadlock would hang here, not the test session)
    t.start()
    t.join(timeout=60)
    assert not t.is_alive() and held == [True] and not DRAWING.locked()
