"""Fuzz, seeds 4401.. and the doors fuzzer's 44001126/7 and 44011126/7 (brief F44), and a new
mutation kind, CONCURRENT (tests/fuzz_concurrent.py): seeded pairs of operations on one small
study and one output directory, started at once or the second while the first waits at a
marker (the ``k``-th rename of a file; pipes, never a sleep) -- two runs into one ``--out``, a
run and ``--overwrite`` of it, a run and ``sim show``, ``sim report`` or verify of its
directory, ``python -m sim.batch --stale-only`` and a run of its study, the API's run and the
command line's, a sweep and a run of one of its cells, the study file or its GNU Gama file
saved anew while the other reads it; after both, each exited 0 or was refused in one line, the
results are one whole run of a config one of them (or the results before) stood for, equal to
its clean run, no file of the user's was lost and the next run of the study file runs. The
seeds' cases of the earlier kinds found no new class (seed 4401-4403, 4410-4412: 40 cases and
4 sequences each; the doors fuzzer: 40 cases a seed). One case each, each failed on the code
before its fix.

* A run that started while another run into the same ``--out`` published its results (between
  the swap of the old results for the new and the rename of the old ones aside, or before the
  first run wrote its final record) ran to exit 0, and so did the first, leaving a ``run.json``
  of the first run's config over the second run's tables (``claims.parquet is not the file its
  run wrote``): the swap put the old results under the staging directory's name, unlocked,
  and the second run took them for its own unfinished run, resumed and published them; the
  first then wrote its record into the second's results. The publishing run now holds
  ``<out>/.lock`` from before the swap until its record is final (the old results' lock comes
  to the staging directory's name with them), and a run that finds it held is refused as one
  that finds the staging directory locked: ``--out: res/net is being written by a running sim
  (pid N)`` (sim/mc/swap.py).
* A run (a sweep) into ``res/net`` while a run into ``res/net/cells/cell0000_r0`` ran was
  refused as "res/net holds files but no sim run record (run.json); sim never replaces it",
  naming no run, where the files were that run's locked staging directory. It now names it:
  ``res/net holds cells/.cell0000_r0.partial, which is being written by a running sim (pid
  N); wait for it to finish or choose another --out`` (the first words again once it ended).
* A sweep whose GNU Gama file (or Wolf table) was saved anew while it ran recorded the cells
  after it as failed (``feasible`` false, "failed: network.gama_sha256: net.xml has changed
  ...") and published with exit 0: results of its config that a clean run does not give
  (``--stale-only`` then called them current). An input file changed since the study was
  loaded now stops the sweep as a full disk does: one line naming ``network.gama_sha256`` and
  the file, exit 2, the finished cells kept for the same command (sim/execute_sweep.py).

Held (about 170 pairs, seeds 1-9 of tests/fuzz_concurrent.py and the CONCURRENT cases of
``make fuzz`` 4411 and 4412): two runs, a run and ``--overwrite``, the API's and the command
line's, ``--stale-only`` and a run: one ran, the other was refused naming the pid of the lock,
the other's results or its unfinished run; ``sim show`` during a run printed the claims of a
run the directory held, or said that a run is writing it; ``sim report`` rewrote the README of
results published while it wrote them (its READMEs are settled); verify passed only results of
the study file with their recorded overrides; a sweep and a run into one of its cells: the cell
run refused as inside a running or finished run; a file of the user's was never lost, and the
next ``sim run --overwrite`` always ran. ``sim report`` and verify while only a staging
directory exists say there are no results yet ("a run is writing it now"): true, not a class.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from fuzz_sequence_run import Pause, incomplete, record

import sim.execute as execute_mod
import sim.mc.publish as publish_mod
from sim.cli import main
from sim.mc.storage import StageLock
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parent.parent
GAMA = ROOT / "tests" / "data" / "gama" / "one_fixed.xml"
STUDY = 'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "net.xml"\n'


def _paused_run(argv: list[str], where: str, pause: Pause) -> int:
    """Fork ``sim run`` that waits at ``where`` of its publish (after the swap, or before its
    final record) until the parent says go: its pid."""
    pid = os.fork()
    if pid == 0:  # child
        code = 99
        try:
            real = getattr(publish_mod, where)

            def held(*a, **kw):
                got = real(*a, **kw) if where == "_exchange" else None
                pause.hold()
                return got if where == "_exchange" else real(*a, **kw)

            setattr(publish_mod, where, held)
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, 1), os.dup2(devnull, 2)
            code = main(argv)
        finally:
            os._exit(code)
    return pid


@pytest.mark.parametrize("where", ["_exchange", "_drop_stale_swaps"])
def test_a_run_started_while_another_publishes_is_refused(tmp_path, capsys, monkeypatch, where):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "net.xml").write_bytes(GAMA.read_bytes())
    (tmp_path / "net.toml").write_text(STUDY)
    run = ["run", "net.toml", "--quiet", "--no-figures", "--out", "res/net", "--overwrite"]
    assert main(run) == 0, capsys.readouterr().err  # the old results
    if where == "_exchange" and getattr(publish_mod._libc(), "renameat2", None) is None:
        pytest.skip("no renameat2 here: no swap in one step")
    pause = Pause()
    first = _paused_run([*run, "--set", "seed=7"], where, pause)
    assert pause.reached(first, 120)
    capsys.readouterr()
    try:  # before: exit 0, and the first then wrote its record over these results
        line = one_line(capsys, main(run), "is being written by a running sim", prefix=SIM_ERROR)
    finally:
        pause.go()
        _, status = os.waitpid(first, 0)
    assert f"(pid {first})" in line
    assert os.waitstatus_to_exitcode(status) == 0
    out = tmp_path / "res" / "net"
    assert record(out)["config"]["seed"] == 7 and incomplete(out, set()) is None
    assert not (out / ".lock").exists() and sorted(os.listdir("res")) == ["net"]
    assert main(run) == 0 and record(out)["config"]["seed"] != 7  # the next run runs


def test_a_run_into_a_directory_holding_a_running_run_names_it(tmp_path, capsys, monkeypatch):
    """A sweep into ``res/net`` while a run into ``res/net/cells/cell0000_r0`` runs."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "net.xml").write_bytes(GAMA.read_bytes())
    (tmp_path / "net.toml").write_text(STUDY)
    stage = tmp_path / "res" / "net" / "cells" / ".cell0000_r0.partial"
    lock = StageLock(stage).acquire()  # as the inner run holds it while it runs
    try:  # before: "res/net holds files but no sim run record (run.json); ..."
        run = ["run", "net.toml", "--quiet", "--no-figures", "--out", "res/net"]
        line = one_line(capsys, main(run), prefix=SIM_ERROR)
    finally:
        lock.release()
    assert (
        f"res/net holds cells/.cell0000_r0.partial, which is being written by a running sim (pid {os.getpid()})"
        in line
    )
    assert "no sim run record" in one_line(capsys, main(run), prefix=SIM_ERROR)  # once it ended


def test_a_sweep_whose_gama_file_changes_between_cells_stops(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "net.xml").write_bytes(GAMA.read_bytes())
    (tmp_path / "net.toml").write_text(STUDY + "[sweep]\nreliability.power = [0.8, 0.9]\n")
    real, cells = execute_mod.cell_config, []

    def cell_config(*a, **kw):  # the file saved anew as the first cell ends
        cells.append(a)
        if len(cells) == 2:
            (tmp_path / "net.xml").write_bytes(GAMA.read_bytes().replace(b'"2.0"', b'"2.5"'))
        return real(*a, **kw)

    monkeypatch.setattr(execute_mod, "cell_config", cell_config)
    argv = ["run", "net.toml", "--quiet", "--no-figures", "--out", "res/net"]
    # before: exit 0, the second cell "failed: network.gama_sha256: net.xml has changed ..."
    line = one_line(capsys, main(argv), "net.xml has changed", prefix=SIM_ERROR)
    assert len(cells) == 2 and "network.gama_sha256" in line
    assert not (tmp_path / "res" / "net").exists()
