"""The classes of the review R41 (last session's change, 407e16e0..551b69ac, read for defects:
a check a nearby input slips past, an error path that raises, a refusal of something
legitimate, a rule whose numbers are wrong), one case each; each failed on the code before its
fix.

* Every cell of a sweep over a key whose values are lists (``network.grids``, the very sweep
  :mod:`sim.report.labels` was written for) was refused by ``sim show CELL`` and
  ``sim.Results(CELL).table(...)`` as "not a table of the cell ... the cell holds another
  cell's or run's results" (F39's :func:`sim.api_paths.cell_mixed`): ``sweep.parquet`` records
  a swept list as its ``repr``, and the cell's config holds the list. The text is read back
  (``ast.literal_eval``) before the two are compared; a cell's table copied from another cell
  is still refused.
* A table of a finished run with a column retyped by hand to a timestamp of nanoseconds ended
  ``sim show`` on pyarrow's "Nanosecond resolution temporal type 1 is not safely convertible
  to microseconds ... Install pandas" and ``sim.Results.table`` on a traceback: V40's values
  digest (:func:`sim.mc.table_shape.values_digest`) is taken of every column before the
  columns' kinds are compared, through ``to_pylist``. Such values are now digested as Arrow
  bytes, and the readers name the column retyped, as before V40.
* L39's unit hint told ``--set plate.spacing_mm=".5mm"`` to "write .5" (and ``"07mm"`` "write
  07", ``"5.mm"`` "write 5."), a value ``--set`` refuses in turn ("got the text '.5': write
  0.5"), and ``"1e999 mm"`` to "write 1e999", an infinite number: the number is now written
  as TOML writes it (``0.5``, ``7``, ``5.0``), and a finite one asked for where there is none.
* An interrupt of ``sim run`` of agnard_block in its Table 1 scanner region said "every chunk
  was done and is kept: run the same command again to write the results from them (no trial
  is computed again)" with most of the region's chunks to come: L39's "every chunk done" (the
  bar has counted the estimate's trials; R40 made brown_design's estimate count every part)
  met agnard's estimate, which counted neither region (the tiny run: 10 trials estimated, 48
  on the bar). Nor did its work count the scanner region: ``table1.trials = 10000`` with
  ``table1.points = 256`` passed ``sim check`` with the defaults' estimate (6.2 minutes of one
  core). Both regions are now counted (:func:`sim.mc.agnard_size.agnard_estimate`, a scanner
  vector's block solves measured: the defaults' estimate is 7 minutes).
* ``sim.Results(root, "network").names()`` of a results root (a batch's ``--results``, the
  project's ``results/``) was ``[]``, exit 0: D39's refusal of a root looks for
  ``root/<study>``, and a network's results are named by its study file
  (``network_plate``); of a directory without a table it was ``[]`` too. The root's
  directories of the study are found by their run record and named; a directory without a
  table is "not a results directory (no tables)", as ``table()`` says.
* P39 gave the median of gridplate_two_plates' self-check its distribution-free interval and
  left :func:`sim.studies.gridplate.claims.quantile_ci` clipping its order statistics to the
  sample: the 95th percentile of the re-weighting counts (``twoplate.weight_ratio.
  reweight_trials``) took the sample's largest as its upper end below 72 values (it covers
  the percentile about 60 % of the time at 24, 23 % at 6), and at ``trials = 6`` (24
  adjustments) the configured inputs' outcome held on [1, 1]. Without an order statistic
  above it the interval now reaches the most re-weightings counted (undecided there).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from conftest import ROOT, tiny_overrides
from oneline import one_line

import sim
from sim.cli import main
from sim.mc.config import ConfigError

GRID = '{{ prefix = "G", nx = 5, ny = 5, spacing_mm = 40.0, role = "observed", sigma_mm = {} }}'


@pytest.fixture(scope="module")
def grids_sweep(tmp_path_factory) -> Path:
    """A network sweep over ``network.grids`` (two cells), run once for the module."""
    d = tmp_path_factory.mktemp("grids")
    text = (ROOT / "studies" / "network_plate.toml").read_text()
    f = d / "grids.toml"
    f.write_text(
        text.replace("trials = 2000", "trials = 40").replace("chunk = 100", "chunk = 2")
        + f"\n[sweep]\nnetwork.grids = [[{GRID.format(0.0012)}], [{GRID.format(0.0024)}]]\n"
    )
    out = d / "out"
    assert main(["run", str(f), "--out", str(out), "--quiet", "--no-figures"]) == 0
    return out


def test_cell_of_a_list_sweep_is_read(grids_sweep, capsys):
    cell = grids_sweep / "cells" / "cell0000_r0"
    assert sim.Results(cell, "network").table("claims").num_rows > 0
    capsys.readouterr()
    assert main(["show", str(cell)]) == 0
    assert "is not a table of the cell" not in capsys.readouterr().err


def test_cell_swapped_still_refused(grids_sweep, tmp_path, capsys):
    d = tmp_path / "sweep"
    shutil.copytree(grids_sweep, d)
    a, b = d / "cells" / "cell0000_r0", d / "cells" / "cell0001_r0"
    shutil.copy(b / "claims.parquet", a / "claims.parquet")
    with pytest.raises(ConfigError) as e:
        sim.Results(a, "network").table("claims")
    assert "claims.parquet" in str(e.value)
    one_line(capsys, main(["show", str(a)]), "claims.parquet")


def test_column_retyped_to_nanoseconds(tiny_run, tmp_path, capsys):
    d = tmp_path / "network_plate"
    shutil.copytree(tiny_run("network_plate"), d)
    p = d / "claims.parquet"
    t = pq.read_table(p)
    i = t.schema.get_field_index("value")
    ns = pa.array([1] * t.num_rows, pa.timestamp("ns"))
    pq.write_table(t.set_column(i, "value", ns).replace_schema_metadata(t.schema.metadata), p)
    one_line(capsys, main(["show", str(d)]), "claims.parquet", "'value'", "timestamp")
    with pytest.raises(ConfigError) as e:
        sim.Results(d, "network").table("claims")
    assert "'value'" in str(e.value) and "timestamp" in str(e.value)


@pytest.mark.parametrize(
    "typed, advice",
    [(".5mm", "write 0.5)"), ("07mm", "write 7)"), ("5.mm", "write 5.0)"), ("1e999 mm", "finite")],
)
def test_unit_hint_writes_toml(typed, advice, capsys):
    f = ROOT / "studies" / "gridplate_two_plates.toml"
    rc = main(["check", str(f), "--set", f'plate.spacing_mm="{typed}"'])
    one_line(capsys, rc, "plate.spacing_mm", "(_mm)", advice)


def test_agnard_interrupt_in_scanner_region_says_chunks_missing(tmp_path, monkeypatch, capsys):
    import importlib

    chunks = importlib.import_module("sim.studies.agnard.chunks")
    real, calls = chunks.table1_chunk, []

    def second_stops(*a, **k):  # Ctrl-C in the scanner region's second chunk of 20
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(chunks, "table1_chunk", second_stops)
    f = ROOT / "studies" / "agnard_block.toml"
    run = ["run", str(f), "--quiet", "--no-figures", "--out", str(tmp_path / "A")]
    rc = main(run + tiny_overrides("agnard_block"))
    one_line(capsys, rc, "run the same command again to finish the missing chunks", code=130)


def test_agnard_estimate_counts_the_scanner_region(capsys):
    f = ROOT / "studies" / "agnard_block.toml"
    big = ["--set", "table1.trials=10000", "--set", "table1.points=256"]
    one_line(capsys, main(["check", str(f), *big]), "adjustments", "over the limit")


def test_names_of_a_results_root_of_networks(grids_sweep, tmp_path):
    root = tmp_path / "root"
    root.mkdir()
    shutil.copytree(grids_sweep, root / "grids")
    with pytest.raises(ConfigError) as e:
        sim.Results(root, "network").names()
    assert "not a results directory" in str(e.value) and str(root / "grids") in str(e.value)
    with pytest.raises(ConfigError) as e:
        sim.Results(root, "wolf_polynomial").names()
    line = str(e.value)  # (doors44r: the studies the root holds are named)
    assert "not a results directory" in line and "no run of 'wolf_polynomial'" in line, line


def test_gridplate_95th_percentile_of_too_few_is_undecided(tmp_path):
    f = ROOT / "studies" / "gridplate_two_plates.toml"
    sets = tiny_overrides("gridplate_two_plates")[1::2]  # its --set values, sized down
    sets = [kv for kv in sets if not kv.startswith(("trials=", "chunk="))] + ["trials=6", "chunk=1"]
    small = [w for kv in sets for w in ("--set", kv)]
    out = tmp_path / "G"
    assert main(["run", str(f), "--out", str(out), "--quiet", "--no-figures", *small]) == 0
    rows = sim.Results(out, "gridplate_two_plates").claims().to_pylist()
    note = next(r["note"] for r in rows if r["claim"].endswith("reweight_trials"))
    assert "at the configured inputs" in note and "outcome inconclusive" in note, note
