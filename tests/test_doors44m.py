"""Helper m44: real sizes (brown_design with workers and Dask, the bar's time left, a GNU Gama
file read three times); one case per class found, each failing on the code before its fix
(small sizes here, the measured ones in the docstrings).

* a run of a ``network.gama_xml`` study parsed the file three times (the load's check, the
  run's network, the report's note; ``sim check`` twice), each a full parse and check of
  every element: a 6.3 MB file of 10,002 points and 80,006 observations took 4.4, 6.0 and
  4.0 s (wall, on the loaded 2-core machine) of a 74 s run of 40 trials. It is now parsed
  once per process and content (:mod:`sim.studies.network.gama_cache`, keyed by the file's
  path and the sha256 of its bytes, which are read again each time): one parse, and an edit
  of the file between two loads is still seen (parsed again, its digest recorded anew).
* brown_design's bar counted each of its 11 error-budget rows at ``budget.max_trials``
  (20,000 trials, 60,000 work units a row) until the row's adaptive stages stopped (1,000 to
  8,500 trials): 660,000 of the bar's 2.32 million units stood for 73,500 of real work, and the
  time left was 1.3 times the real one at the start and about 2 times when the posteriors
  (run first on one worker) were done. After each stage the bar now counts the trials the stage
  predicts (:func:`sim.studies.design.adaptive.run_adaptive`; more put back if a later stage
  predicts more), and the budget runs first, so every row is counted at its prediction within
  the first few percent of the run. No number changes (each chunk draws its own stream).
  Measured by the bar's time left against the real time left of the run (one worker, the
  loaded machine): from 30 % of the run on 1.0 to 6.3 times before; 1.4 to 2.8 after this fix
  alone, the rest from two parts' units:
* brown_design's affine coverage trial was counted 28 units (7 at 4 points) whatever the
  chunk: in the study's chunks of 500 it costs 0.39 (6.0 in chunks of 20; a chunk's own cost
  is most of it), so its 294,000 units stood for about 2,000 and the time left was 2.8 times
  the real one at 90 % of the run. It is now 0.16 units a trial and 117 a chunk
  (:func:`sim.mc.workunits.affine_units`); the two-plate posterior's share of a chain, 0.225
  of :data:`sim.mc.workunits.BAYES_UNITS`, measured 0.37 at 32 x 2,000 steps (Brown's 0.65,
  counted 0.55) and is 0.32.
* agnard_block's bar counted a trial one unit in every part: a trial of the main blocks
  (10,468 units at the defaults) as one of the five-point region's (1,792) or of a block of 8
  models (112), so the time left during the main part was the trials left over its slow rate
  of trials; and it counted the trials of the scan resolution and the re-centring error that
  the main blocks already have (200 of 1,618 at the defaults, never run): the bar ended at
  88 %. Each part now counts its trials at its units (:func:`sim.mc.agnard_size.agnard_units`)
  and the estimate leaves out the parts the run does not run.
* the bar's rate of work counted the time of a part it only names (brown_design's analytic
  design grid and regions, about a minute on the loaded machine, no work counted): the error
  budget, now first after them, showed 34 minutes left of a run that ended 91 s later
  (tests/test_doors42b.py's small run). The rate is measured from the end of such a part.
* gridplate_two_plates' bar counted a trial one unit and its region not at all: the region
  (about 2.7 s of the 7 s the estimate gives the study's defaults) ran after the bar had
  said 100 % and no time left. The bar now counts a trial at its units and, once the region is
  done, the region's (:func:`sim.mc.gridplate_size.gridplate_units`), and names the region
  while it runs (``gridplate_two_plates: region``).
"""

from __future__ import annotations

import io
from pathlib import Path

import pytest

import sim
import sim.studies.network.gama_read as gama_read
from sim.mc.estimate import Estimate, estimate
from sim.mc.gridplate_size import gridplate_units
from sim.mc.progress import Progress
from sim.mc.runner import ChunkStore, RunContext
from sim.mc.workunits import affine_units, design_bar_units
from sim.studies import get_study, load_study
from sim.studies.design.adaptive import run_adaptive
from sim.studies.network.definition import build
from sim.studies.network.gama import merge_gama, write_gama
from tests.conftest import TRIANGLE_NETWORK, tiny_overrides


def _gama_study(tmp_path: Path) -> tuple[Path, Path]:
    """A four-point network written as a gama-local file, and a study file that reads it."""
    text = TRIANGLE_NETWORK.replace(
        '{ name = "C", x_mm = 400.0, y_mm = 700.0 } ]',
        '{ name = "C", x_mm = 400.0, y_mm = 700.0 }, { name = "D", x_mm = 600.0, y_mm = -500.0 } ]',
    )
    src = tmp_path / "src.toml"
    src.write_text(text, encoding="utf-8")
    xml = write_gama(build(load_study(src)[1]), tmp_path / "net.xml")
    st = tmp_path / "gama.toml"
    st.write_text(
        f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{xml}"\n',
        encoding="utf-8",
    )
    return st, xml


def test_a_gama_file_is_parsed_once_a_run_and_an_edit_is_seen(tmp_path, monkeypatch):
    """The load and the run of a study reading a gama-local file parse it once (three times
    before); the file edited after, the next load parses it again and records its new digest;
    the records a caller gets are its own (changed, the next reader's are not)."""
    st, xml = _gama_study(tmp_path)
    parses = []
    real = gama_read._network
    monkeypatch.setattr(gama_read, "_network", lambda *a: parses.append(1) or real(*a))
    handle = sim.load(st)
    res = handle.run(out=tmp_path / "o", figures=False)
    assert len(parses) == 1
    assert res.table("points").num_rows > 0
    sha = handle.config["network.gama_sha256"]
    first = merge_gama(handle.config)
    first["network.points"][0]["x_mm"] = 1.0  # the caller's copy, not the kept one
    assert merge_gama(handle.config)["network.points"] != first["network.points"]
    assert len(parses) == 1
    xml.write_text(xml.read_text().replace('stdev="0.01"', 'stdev="0.02"', 1), encoding="utf-8")
    again = sim.load(st)
    assert len(parses) == 2
    assert again.config["network.gama_sha256"] != sha
    sigmas = [o["sigma_mm"] for o in merge_gama(again.config)["network.observations"]]
    assert sigmas[0] == 0.02 and sigmas[1:] == [0.01] * (len(sigmas) - 1)
    assert len(parses) == 2


def _draws(rng, n):
    return {"x": rng.normal(size=n)}


def test_an_adaptive_stage_counts_its_predicted_trials_on_the_bar_not_its_maximum(tmp_path):
    """A stage of 20 trials whose standard error is twice the target predicts 90 in all (20 x
    2^2 x 1.05, in whole chunks): while the second stage runs, the bar counts 90 trials (270
    units), not the estimate's 1,000 (3,000 units); it ends at 90 as before."""
    est = Estimate("x", 1000, 3000.0, 1, 1.0, work=3000.0)
    ctx = RunContext(quiet=True, store=ChunkStore(tmp_path / "trials"), estimate=est)
    seen = []

    def stat(res):
        seen.append((ctx.bar.total, ctx.bar.work_total))
        return {"se": (0.0, 2.0 if len(seen) == 1 else 0.5)}

    with ctx.progress_bar("x"):
        res, _ = run_adaptive(_draws, stat, 1.0, 7, 10, 0, 20, 1000, ctx=ctx, units=3.0)
    assert len(res["x"]) == 90
    assert seen == [(1000, 3000.0), (90, 270.0)]
    assert ctx.counted == [90, 90]


@pytest.mark.long
def test_the_gridplate_bar_counts_its_trials_work_and_its_regions(tmp_path):
    """A small run's bar: a total of the trials' units and the region's, every unit counted at
    its end (the region's once it is done, named while it runs); one unit a trial and no
    region before."""
    cfg = load_study(
        Path(__file__).parents[1] / "studies" / "gridplate_two_plates.toml",
        ["trials=40", "chunk=2", "region.points=8", "region.rounds=0", "region.draws=50"],
    )[1]
    per, region = gridplate_units(cfg)
    est = estimate(cfg)
    assert est.work == 40 * per + region and region > 0 and per > 1
    ctx = RunContext(quiet=True, store=ChunkStore(tmp_path / "trials"), estimate=est)
    shown = []
    with ctx.progress_bar("gridplate_two_plates") as bar:
        set_doing = bar.set_doing
        bar.set_doing = lambda text: shown.append((text, bar.work)) or set_doing(text)
        get_study("gridplate_two_plates").run(cfg, tmp_path / "out", ctx)
        assert bar.work == pytest.approx(est.work) and bar.work_total == pytest.approx(est.work)
    assert shown == [("region", pytest.approx(40 * per)), ("", pytest.approx(est.work))]


def test_an_affine_coverage_trial_is_counted_with_its_chunks_cost():
    """The study's affine coverage (10,000 trials at 25 points and 2,000 at 4, chunks of 500,
    measured 0.39 units a trial) is counted under one unit a trial, not 28 and 7; in chunks of
    20 (measured 6.0) about six."""
    cfg = load_study(Path(__file__).parents[1] / "studies" / "brown_design.toml")[1]
    assert cfg["chunk"] == 500
    assert 0.2 < affine_units(500) < 0.6 and 4 < affine_units(20) < 8
    fewer = load_study(
        Path(__file__).parents[1] / "studies" / "brown_design.toml", ["coverage.trials=10"]
    )[1]
    more = 10000 - 10  # trials of a coverage case (2 units) and of the affine case each
    assert design_bar_units(cfg) - design_bar_units(fewer) < more * 2.6


@pytest.mark.long
def test_the_agnard_bar_counts_each_parts_units_and_only_the_trials_run(tmp_path):
    """The tiny run (its resolution and re-centring error the main blocks' own): the bar ends
    with every trial it counted done and its work at its total, each part's trials at its
    units; before, 4 trials never run were counted and every trial one unit."""
    sets = [a for a in tiny_overrides("agnard_block") if a != "--set"]
    cfg = load_study(Path(__file__).parents[1] / "studies" / "agnard_block.toml", sets)[1]
    est = estimate(cfg)
    ctx = RunContext(quiet=True, store=ChunkStore(tmp_path / "trials"), estimate=est)
    with ctx.progress_bar("agnard_block") as bar:
        get_study("agnard_block").run(cfg, tmp_path / "out", ctx)
        assert bar.done == bar.total == est.trials
        assert bar.work == pytest.approx(est.work) and bar.work_total == pytest.approx(est.work)
    assert est.work > 100 * est.trials


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_the_rate_of_work_leaves_out_the_time_of_a_part_the_bar_only_names():
    """A minute naming an analytic part, then 10 of 100 units in a second: 9 s left, not the
    549 of a rate taken over the minute too."""
    bar = Progress(10, "x", stream=_Terminal(), work=100.0)
    t0 = bar.bar.start_t
    now = [t0]
    bar.bar._time = lambda: now[0]
    bar.set_doing("design grid")
    now[0] = t0 + 60
    bar.set_doing("")
    now[0] = t0 + 61
    bar.update(1, work=10.0)
    fd = bar.bar.format_dict
    assert (fd["total"] - fd["n"]) / fd["rate"] == pytest.approx(9.0)
    bar.bar.close()
