"""The classes of the sweep doors20a (issue 26: the Python API in a long-lived user process, a
notebook or a script, whose state is not the suite's), one case each; each failed on the code
before its fix.

* tqdm's monitor thread, started by the first progress bar of a run (a disabled one too) and
  left running, made the next ``run(workers=2)`` of the same script see a second thread and
  start its workers by ``forkserver``, which runs the caller's script again: a script without
  ``if __name__ == "__main__"`` (fine under fork) started a second run of its own into the same
  directory and the caller's run failed (:func:`sim.mc.progress._bar_class`);
* a ``matplotlibrc`` of the user's (in the working directory, ``MATPLOTLIBRC`` or
  ``~/.config/matplotlib``) changed every PNG of ``sim run`` and of the API: the suite draws
  over matplotlib's own defaults (:func:`sim.report.mpl._defaults`), and the API puts the
  caller's file's values back after the run;
* a ``Results`` read after its directory was replaced by another run of the same study (another
  seed, ``overwrite=True``) returned that run's tables as its own: it records the run's
  ``run.json`` and refuses another's;
* a study that writes a ``trials.parquet`` of its own (wolf, agnard, gridplate): ``names()``
  listed ``trials`` twice and ``table("trials")`` read the chunk dataset, so the study's
  documented per-trial table could not be read; now ``trials`` is that table and ``chunks`` the
  dataset;
* ``run()`` with ``out=None`` where no temporary directory can be made (the caller's
  ``tempfile.tempdir`` gone, or a file) ended in FileNotFoundError from ``tempfile``;
* ``import sim.studies`` (every run) in a host process without ``sys.argv``, or with ``None``
  (an embedded Python), ended in a TypeError from ``sim.report.verify``;
* two runs of the API in threads of the caller that overlap (one ends before the other) left the
  suite's ``sys.unraisablehook`` in the caller's process for good: each put back the hook it had
  found (:func:`sim.stops.keep_lost_interrupts` now counts);
* an executor that could not start because its workers (Dask's spawn, a forkserver) ran the
  caller's unguarded script again said only "Nanny failed to start": it asks for the main guard
  (:func:`sim.mc.executors.script_words`);
* an interrupted Dask run of the API left the caller's ``asyncio``, ``distributed`` and ``tornado``
  loggers silenced for good (:func:`sim.api_loggers.loggers_kept`);
* a run with ``quiet=False`` while the caller's ``sys.stderr`` was a closed stream failed as
  "the run failed in sim.mc.progress: ValueError: I/O operation on closed file".
"""

import hashlib
import io
import json
import logging
import os
import subprocess
import sys
import tempfile
import threading
import types
from pathlib import Path

import pytest
from oneline import python_lines

import sim
from sim.mc.executors import script_words
from sim.mc.progress import Progress
from sim.mc.storage import read_provenance
from sim.stops import keep_lost_interrupts

ROOT = Path(__file__).resolve().parent.parent
STUDY = ROOT / "studies" / "network_plate.toml"


def test_a_run_leaves_no_thread_behind(tmp_path):
    before = {t.ident for t in threading.enumerate()}
    sim.load(STUDY, trials=40, chunk=2).run(out=tmp_path / "o", figures=False)
    left = [t.name for t in threading.enumerate() if t.ident not in before]
    assert left == [], left  # a thread left: the next run(workers=2) starts a fork server


def test_figures_do_not_depend_on_a_matplotlibrc_of_the_users(tmp_path):
    rc = tmp_path / "rc"
    rc.mkdir()
    (rc / "matplotlibrc").write_text("lines.linewidth: 6\naxes.facecolor: black\nfont.size: 20\n")
    run = (  # matplotlib not loaded by the caller before the run: the suite loads it
        "import sys, sim; "
        f"sim.load({str(STUDY)!r}, trials=40, chunk=2).run(out=sys.argv[1]); "
        "import matplotlib; "
        "print(matplotlib.rcParams['lines.linewidth'], matplotlib.rcParams['font.size'])"
    )
    outs = []
    for name, env in (("mine", {"MATPLOTLIBRC": str(rc)}), ("clean", {})):
        env = {k: v for k, v in os.environ.items() if k != "MATPLOTLIBRC"} | env
        p = subprocess.run(
            [sys.executable, "-c", run, str(tmp_path / name)],
            capture_output=True,
            text=True,
            env=env,
            cwd=tmp_path,
            timeout=120,
        )
        assert p.returncode == 0, p.stderr
        outs.append(p.stdout.split())
    assert outs[0] == ["6.0", "20.0"], outs  # the caller's own values, after the run
    for png in ("network.png", "reliability.png"):
        assert (tmp_path / "mine" / png).read_bytes() == (tmp_path / "clean" / png).read_bytes()


def test_results_of_a_run_replaced_by_another_are_refused(tmp_path):
    out = tmp_path / "o"
    first = sim.load(STUDY, trials=40, chunk=2).run(out=out, figures=False)
    claims = first.claims()
    again = sim.load(STUDY, trials=40, chunk=2).run(out=out, figures=False)  # the same run
    assert first.claims().equals(claims) and again.claims().equals(claims)
    sim.load(STUDY, trials=40, chunk=2, seed=7).run(out=out, figures=False, overwrite=True)
    with pytest.raises(sim.ConfigError, match="holds another run") as e:
        first.claims()
    assert str(e.value).startswith("path: ") and "\n" not in str(e.value)
    assert sim.Results(out, "network").claims().num_rows == claims.num_rows  # read anew


def test_a_studys_own_trials_table_is_read_and_the_chunks_are_named_chunks(tmp_path):
    res = sim.load(STUDY, trials=40, chunk=2).run(out=tmp_path / "o", figures=False)
    assert res.table("trials").num_rows == 40 == res.table("chunks").num_rows
    prov = read_provenance(tmp_path / "o" / "claims.parquet")  # written by the run (wolf's is)
    sim.write_table(tmp_path / "o" / "trials.parquet", {"trial": list(range(5))}, prov)
    record = json.loads((tmp_path / "o" / "run.json").read_text("utf-8"))  # listed as a study
    sha = hashlib.sha256((tmp_path / "o" / "trials.parquet").read_bytes()).hexdigest()  # that
    record["table_sha256"]["trials.parquet"] = sha  # writes one records it (else not its table)
    (tmp_path / "o" / "run.json").write_text(json.dumps(record), "utf-8")
    names = sim.Results(tmp_path / "o", "network").names()
    assert len(names) == len(set(names)) and {"trials", "chunks"} <= set(names), names
    own = sim.Results(tmp_path / "o", "network")
    assert own.table("trials").column_names == ["trial"] and own.table("trials").num_rows == 5
    assert own.table("chunks").num_rows == 40


def test_no_temporary_directory_is_one_line_naming_out(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setattr(tempfile, "tempdir", str(blocker))
    with pytest.raises(sim.ConfigError, match="no temporary directory") as e:
        sim.load(STUDY, trials=40, chunk=2).run(figures=False)
    assert str(e.value).startswith("out: ") and "\n" not in str(e.value)


@pytest.mark.parametrize("how", ["del sys.argv", "sys.argv = None"])
def test_the_suite_loads_in_a_process_without_argv(how):
    p = python_lines(
        "import sys",
        how,
        "import sim",
        f"print(sim.load({str(STUDY)!r}, trials=40, chunk=2).name)",
    )
    assert p.returncode == 0 and p.stdout == "network\n", p.stderr


def test_a_closed_stderr_is_no_terminal():
    closed = io.StringIO()
    closed.close()
    with Progress(10, "x", quiet=False, stream=closed) as bar:
        bar.update(10)
    assert not bar.enabled


def test_overlapping_runs_in_threads_put_the_callers_unraisable_hook_back():
    mine = sys.unraisablehook
    first, second = threading.Event(), threading.Event()

    def a():  # opens first, closes first
        with keep_lost_interrupts():
            first.set()
            second.wait(10)

    def b():
        first.wait(10)
        with keep_lost_interrupts():
            second.set()
            ta.join(10)

    ta, tb = threading.Thread(target=a), threading.Thread(target=b)
    ta.start()
    tb.start()
    tb.join(10)
    assert sys.unraisablehook is mine  # was the suite's recording hook, for good


def test_an_executor_that_cannot_start_under_a_script_asks_for_the_main_guard(monkeypatch):
    """Dask's workers (spawn) import the caller's script again: an unguarded one started its
    run again there, and the run ended in "cannot start the dask executor: Nanny failed to
    start", no cause named."""
    script = types.ModuleType("__main__")
    script.__file__ = "/home/me/analysis.py"
    monkeypatch.setitem(sys.modules, "__main__", script)
    words = script_words("dask", 1, None)
    assert "analysis.py" in words and 'if __name__ == "__main__"' in words
    assert script_words("dask", 1, "tcp://h:8786") == ""  # a scheduler's workers are not ours
    assert script_words("local", 1, None) == ""  # no worker process
    monkeypatch.delattr(script, "__file__")  # a notebook: nothing is imported again
    assert script_words("dask", 1, None) == ""


def test_an_interrupted_run_puts_the_callers_log_levels_back(tmp_path, monkeypatch):
    """An interrupted Dask run silences asyncio, distributed and tornado for the cluster's
    closing chatter (:func:`sim.execute._quiet_dask_logs`): in the caller's process they stayed
    silenced, the caller's own asyncio errors with them."""
    import sim.api
    from sim.execute import _quiet_dask_logs

    def interrupted(*args, **kw):
        _quiet_dask_logs()
        raise KeyboardInterrupt

    monkeypatch.setattr(sim.api, "execute", interrupted)
    mine = logging.getLogger("asyncio.mine")
    mine.setLevel(logging.INFO)
    before = logging.getLogger("asyncio").level
    with pytest.raises(KeyboardInterrupt):
        sim.load(STUDY, trials=40, chunk=2).run(out=tmp_path / "o")
    assert logging.getLogger("asyncio").level == before and mine.level == logging.INFO
    assert logging.getLogger("distributed").level < logging.CRITICAL
