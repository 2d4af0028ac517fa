"""Doors of session 40's review (R40): the seams of the session's merged branches.

* An interrupt of ``sim run`` of brown_design while its last part (its Monte-Carlo check) still ran said "every chunk
  was done and is kept: run the same command again to write the results from them (no trial
  is computed again)": L39's test of "every chunk done" (the run's progress bar has counted the
  estimate's trials) met an estimate that counted 6 error-budget rows of its 11, neither the
  affine coverage case nor the posteriors' chains, and a bar that counted an adaptive stage's
  earlier chunks again at each stage (660 and 696 trials counted of 470 estimated: the bar was
  "full" with 130 chunks to come). The estimate now counts every part
  (:func:`sim.mc.workunits.design_estimate`) and a chunk counts once a run on the shared bar
  (:func:`sim.mc.runner.run_chunks`): the interrupt says the missing chunks are finished.
"""

from __future__ import annotations

import importlib
from pathlib import Path

import numpy as np
import pytest
from oneline import one_line

from sim.cli import main
from sim.mc.runner import ChunkStore, RunContext, run_chunks
from sim.mc.workunits import DESIGN_BUDGET_ROWS
from sim.studies.design.errbudget import BUDGET_ROWS

DESIGN = Path(__file__).resolve().parents[1] / "studies" / "brown_design.toml"
SMALL = (
    "trials=40 chunk=2 budget.max_trials=20 coverage.trials=20 coverage.sweep_trials=10 "
    "bayes.steps=200 region.points=256 region.plate_points=256 unprinted.plates=200 "
    "region.rounds=0"
).split()


@pytest.mark.long
def test_an_interrupt_while_design_chains_run_says_chunks_are_missing(
    tmp_path, monkeypatch, capsys
):
    mod = importlib.import_module("sim.studies.design.run")

    def stop(*a, **k):  # Ctrl-C in the first chunk of the part run last: 20 chunks to come
        raise KeyboardInterrupt

    monkeypatch.setattr(mod, "design_chunk", stop)
    run = ["run", str(DESIGN), "--quiet", "--no-figures", "--out", str(tmp_path / "D")]
    run += [w for kv in SMALL for w in ("--set", kv)]
    # before: "every chunk was done and is kept: run the same command again to write ..."
    one_line(capsys, main(run), "run the same command again to finish the missing chunks", code=130)


def test_the_design_estimate_counts_every_budget_row():
    assert DESIGN_BUDGET_ROWS == len(BUDGET_ROWS)


def _chunk(rng, n):
    return {"x": rng.normal(size=n)}


def test_an_adaptive_stage_counts_its_earlier_chunks_once(tmp_path):
    ctx = RunContext(quiet=True, store=ChunkStore(tmp_path))
    with ctx.progress_bar("t") as bar:
        run_chunks(_chunk, 4, 1, 2, ctx=ctx)  # a first stage: 2 chunks
        out = run_chunks(_chunk, 8, 1, 2, ctx=ctx)  # the next reads them again, adds 2
        # before: 12 trials counted of the 8 the run computed
        assert bar.done == 8 and np.asarray(out["x"]).size == 8
