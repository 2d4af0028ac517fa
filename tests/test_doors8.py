"""The failure classes of the eighth sweep of bad inputs (issue 26), one case per class, and
the two leftovers of the seventh; each failed on the code before its fix.

* ``sim.batch`` and ``make verify`` each had their own way of passing a signal on to their
  child runs (a near-copy): one implementation, :func:`sim.mc.children.stop_children`;
* Brown with ``plate.grid = 2`` (or four points in a square, or a 2 in ``dilution.grids``)
  passed ``sim check``; every trial's pivot adjustment was then singular at run time ("only
  0 trials converged", naming no key), or the dilution table's pivot column came out NaN
  with exit 0; ``brown_design`` with ``paper.grid = 2`` failed at run time in an eigenvalue
  solver ("LinAlgError: Eigenvalues did not converge");
* ``--set seed=3 --set seed=4`` ran with seed 4 and dropped the 3 silently (as ``--seed`` with
  ``--set seed=`` did before the seventh sweep);
* ``python -m sim.batch --stale-only FILE -- RUN_OPTIONS`` judged the results against the
  study file alone: results of ``network.offset_mm = 1`` were "up to date" for ``-- --set
  network.offset_mm=2.0``, and a batch with ``--trials`` was never up to date;
* Brown with ``solver.max_iter = 2`` or ``solver.tol_mm = 1e-300`` (no trial can converge)
  passed ``sim check`` and failed every trial with "singular reduced normal matrix, the
  geometry is degenerate": the solver's limits were blamed on the geometry, naming no key;
* a FIFO put by hand where the suite keeps its own file (``REPORT.md`` in ``--results``,
  ``run.json`` in a results or staging directory) made ``sim report``, ``sim run
  --overwrite`` and ``sim.batch --stale-only`` block forever on opening it;
* a standard deviation so large that the model overflows passed ``sim check`` and failed at
  run time: Brown's ``errors.setting_sigma_um = 1e300`` in an OverflowError, Wolf's
  ``plate.grid_sigma_um = 1e300`` after a page of NumPy warnings, naming no key (Wolf's
  other sigmas were bounded at 100 um, Brown's bias at 1e4 um; these now are too).
"""

import contextlib
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import sim.batch
import sim.report.verify.rerun
from sim.cli import main
from sim.mc import children
from sim.mc.config import ConfigError
from sim.mc.storage import read_record
from sim.report.markdown import write_report
from sim.studies import get_study

ROOT = Path(__file__).resolve().parent.parent
NETWORK = ROOT / "studies" / "network_brown.toml"


def test_batch_and_verify_stop_their_children_with_one_function(monkeypatch):
    assert sim.batch.stop_children is children.stop_children
    assert sim.report.verify.rerun.stop_children is children.stop_children
    old = {s: signal.getsignal(s) for s in (signal.SIGINT, *children.STOP_SIGNALS)}
    # one child ends on SIGTERM, one ignores it (killed after the grace), one fills its pipe
    stubborn = (
        "import signal, time; signal.signal(signal.SIGTERM, signal.SIG_IGN); "
        "print('ready', flush=True); time.sleep(30)"
    )
    chatty = "import sys, time; sys.stdout.write('x' * 10**6); sys.stdout.flush(); time.sleep(30)"
    procs = [
        subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"]),
        subprocess.Popen([sys.executable, "-c", stubborn], stdout=subprocess.PIPE),
        subprocess.Popen([sys.executable, "-c", chatty], stdout=subprocess.PIPE),
    ]
    # the stubborn child ignores SIGTERM only once it says so (a loaded machine starts Python
    # slowly); the others end on SIGTERM at any moment of their start
    assert procs[1].stdout.readline().strip() == b"ready"
    called = []
    try:
        t = time.monotonic()
        children.stop_children(procs, drain=True, first=lambda: called.append(1), grace=0.5)
        assert time.monotonic() - t < 5 and called == [1]
        assert [p.returncode for p in procs] == [-signal.SIGTERM, -signal.SIGKILL, -signal.SIGTERM]
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_IGN  # a second signal orphans none
    finally:
        for s, h in old.items():
            signal.signal(s, h)


@pytest.mark.parametrize(
    "study, sets, key",
    [
        ("brown_table1", ["plate.grid=2"], "plate.grid"),
        (
            "brown_dilution",
            ["plate.pattern=list", "plate.points=[[-9,-9],[9,-9],[-9,9],[9,9]]"],
            "plate.points",
        ),
        ("brown_dilution", ["dilution.grids=[2,3]"], "dilution.grids"),
        ("brown_design", ["paper.grid=2", "design.grids=[2,5]"], "paper.grid"),
    ],
)
def test_a_brown_geometry_the_pivot_model_cannot_solve_is_refused_by_check(
    capsys, study, sets, key
):
    # passed sim check, then every trial's pivot adjustment was singular at run time (or the
    # dilution curve's pivot column came out NaN, exit 0)
    argv = ["check", str(ROOT / "studies" / f"{study}.toml")]
    assert main([*argv, *(x for s in sets for x in ("--set", s))]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith(f"sim: error: {key}: the pivot model"), err
    assert "singular" in err


def test_a_key_given_twice_by_set_is_refused(capsys):
    # "--set seed=3 --set seed=4" ran with seed 4 and dropped 3 without a word
    argv = ["check", str(ROOT / "studies" / "network_brown.toml"), "--set", "seed=3"]
    assert main([*argv, "--set", "seed=4"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "sim: error: seed: given twice by --set: give one value", err


def test_stale_only_reads_the_run_options(tmp_path, capsys):
    # results of network.offset_mm = 1 were "up to date" for --set network.offset_mm=2.0, and
    # a batch with --trials was never up to date: the run options were left out of the check
    out = tmp_path / "r" / "network_brown"
    small = ["--trials", "40", "--no-figures"]
    assert main(["run", str(NETWORK), *small, "--quiet", "--out", str(out)]) == 0
    assert sim.batch.is_current(NETWORK, out, small)
    assert not sim.batch.is_current(NETWORK, out, [*small, "--set", "network.offset_mm=2.0"])
    assert not sim.batch.is_current(NETWORK, out)  # the file's own trials, and figures
    assert (
        sim.batch.main(["--stale-only", "--results", str(out.parent), str(NETWORK), "--", *small])
        == 0
    )
    assert "network_brown: up to date" in capsys.readouterr().out


def test_brown_solver_limits_are_named_not_blamed_on_the_geometry(tmp_path, capsys):
    # a tolerance no trial can meet, or too few iterations, failed every trial with "singular
    # reduced normal matrix, the geometry is degenerate", naming no key
    study = str(ROOT / "studies" / "brown_table1.toml")
    assert main(["check", study, "--set", "solver.tol_mm=1e-300"]) == 2
    assert capsys.readouterr().err.startswith("sim: error: solver.tol_mm: must be >= 1e-15")
    run = ["run", study, "--trials", "40", "--no-figures", "--quiet", "--out", str(tmp_path / "o")]
    assert main([*run, "--set", "solver.max_iter=2"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "solver.max_iter" in err, err


def test_a_fifo_where_the_suite_keeps_its_own_file_never_blocks(tmp_path):
    # a FIFO named REPORT.md in --results, or run.json in a results or staging directory, made
    # sim report, sim run --overwrite and sim.batch --stale-only wait forever on it
    d = tmp_path / "r" / "network_brown"
    d.mkdir(parents=True)
    shutil.copy(ROOT / "results" / "network_brown" / "claims.parquet", d)
    fifos = [d / "run.json", d.parent / "REPORT.md"]
    for f in fifos:
        os.mkfifo(f)
    got = []

    def calls():
        got.append(read_record(d))
        got.append(sim.batch.is_current(NETWORK, d))
        try:  # what sim report does first (main() sets signal handlers: the main thread only)
            write_report(d.parent, get_study)
        except ConfigError as e:
            got.append(str(e))

    t = threading.Thread(target=calls, daemon=True)
    t.start()
    t.join(20)
    blocked = t.is_alive()
    for f in fifos:  # a blocked reader gets end of file
        with contextlib.suppress(OSError):
            os.close(os.open(f, os.O_WRONLY | os.O_NONBLOCK))
    t.join(5)
    assert not blocked and got[:2] == [None, False], got
    assert "REPORT.md was not written by sim report" in got[2], got


@pytest.mark.parametrize(
    "study, key",
    [
        ("brown_table1", "errors.setting_sigma_um"),
        ("brown_dilution", "errors.comparator_sigma_um"),
        ("wolf_polynomial", "plate.grid_sigma_um"),
    ],
)
def test_a_standard_deviation_that_overflows_the_model_is_refused_on_load(capsys, study, key):
    # passed sim check, then failed at run time: Brown in an OverflowError, Wolf after a page
    # of NumPy overflow warnings with "phases beyond 1e6 rad", naming no key
    assert main(["check", str(ROOT / "studies" / f"{study}.toml"), "--set", f"{key}=1e300"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"sim: error: {key}: must be <= ") and "\n" not in err, err
