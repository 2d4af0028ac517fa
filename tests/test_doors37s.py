"""The classes of the sweep doors37s (brief S37: sweeps and regions through last session's
features, and P35's left items), one case each; each failed on the code before its fix.

* A sweep with a cell the study refuses (a 150 x 150 plate at 45 mm, outside the format:
  recorded infeasible, never run) was estimated with that cell: beside a 5 x 5 plate it
  "needed 0.744 GiB" and ``sim check``/``sim run --max-memory-gb 0.5`` refused the sweep, and
  a work limit too. A sweep over a limit is estimated again without the cells the study
  refuses (:func:`sim.execute.sweep_limits`).
* A sweep over the memory limit at one swept value named no value: a network's sweep of
  ``network.grids`` with a 400 x 400 grid said "reduce chunk, trials or the sizes in the
  study file", a Brown sweep of ``plate.grid`` "reduce ... plate.grid" (the file's value, which
  the sweep overrides). The line now names the cell's swept values and ``sweep.<key>``; a
  network cell refused by its size check (:class:`sim.mc.limit_error.LimitError`, a limit of the
  machine, not of the design) refuses the sweep naming ``sweep.network.grids`` and the cell,
  where it would have been recorded infeasible and the others run.
* A sweep's table (its README.md, ``sim show --markdown``) gave a region row's value as the
  low end of its range over the region (``0.120`` where the cell's own README says
  ``0.12–0.92``): the range is given, as the cell's row gives it.
* A cell whose run failed for the machine, not its configuration (a full disk, ``[Errno 28]``
  writing its tables; memory; a worker killed) was recorded infeasible, "failed: [Errno 28]
  No space left on device", and the sweep published with exit 0, the cell's results lost.
  Such a failure now stops the sweep as it stops a single run, one line, the finished cells'
  chunks kept: the same command resumes (:func:`sim.execute_sweep.not_the_cells`).
* A sweep of a printed key (``errors.settings = [1, 2]``) said nothing of its cells off the
  paper's setup in its README.md, ``sim show`` or the end of ``sim run``, where ``sim show`` of
  such a cell says its predictions are findings: the three now give one line naming the
  cells off it (:func:`sim.report.off_paper.sweep_off_note`).
* P35's left items: ``datum.kind = "inner"`` on a network whose fixed points already fix the
  datum ran the fixed datum, said ``datum `inner` (0 constraints)``, and ``datum.points``
  changed nothing: refused, naming the key (``datum.points`` when given). ``snoop.alpha`` and
  ``snoop.test`` at ``snoop.max_reject = 0`` (no snooping) decide nothing: set, they are
  refused as any key the configuration does not read (``agnard_block_104.toml`` leaves them
  out; its resolved config is the same).

Held: a sweep without ``--out`` goes to ``scratch/<study>-<hash>/`` (never ``results/``); a
sweep killed (``kill -9``) and run again resumes every cell's chunks, its tables equal an
uninterrupted run's; a swept key also given by ``--set`` is refused; the values of a cell
refused for its design are named once and recorded.
"""

from __future__ import annotations

import dataclasses
import errno
import importlib
import textwrap
from pathlib import Path

import pytest
from conftest import TRIANGLE_NETWORK

import sim
from sim.cli import main
from sim.mc.storage import write_table
from sim.report.run_summary import run_markdown, terminal_summary, terminal_table
from sim.report.sweep import sweep_markdown
from sim.studies import MODULES, get_study

ROOT = Path(__file__).resolve().parents[1]
GRID = '{{ prefix = "G", nx = {n}, ny = {n}, spacing_mm = 40.0, role = "observed", sigma_mm = 0.0012 }}'


def _file(tmp_path, name: str, text: str):
    p = tmp_path / name
    p.write_text(textwrap.dedent(text))
    return p


def test_limits_of_a_sweep_leave_out_the_cells_the_study_refuses(tmp_path, capsys):
    f = _file(
        tmp_path,
        "sw.toml",
        """\
        study = "brown_table1"
        trials = 400
        chunk = 20
        [sweep]
        "plate.grid" = [5, 150]
        """,
    )
    assert main(["check", str(f), "--max-memory-gb", "0.5"]) == 0, capsys.readouterr().err
    assert main(["check", str(f), "--max-adjustments", "5e5"]) == 0, capsys.readouterr().err
    assert "cell0001" in capsys.readouterr().err  # the refused cell, named as before


def test_a_sweep_over_the_memory_limit_names_the_swept_value(tmp_path, capsys):
    grids = ", ".join(f"[ {GRID.format(n=n)} ]" for n in (5, 400))
    f = _file(
        tmp_path,
        "net.toml",
        f"""\
        study = "network"
        trials = 200
        chunk = 10
        [network]
        grids = [ {GRID.format(n=5)} ]
        generate = [ {{ kind = "dx", from = "G*", to = "G*", nearest = 4, sigma_mm = 0.002 }},
                     {{ kind = "dy", from = "G*", to = "G*", nearest = 4, sigma_mm = 0.002 }} ]
        [sweep]
        "network.grids" = [ {grids} ]
        """,
    )
    out = tmp_path / "o"
    assert main(["run", str(f), "--max-memory-gb", "1", "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert err.startswith("sim: error: sweep.network.grids:") and "nx = 400" in err, err
    assert not out.exists() and [p.name for p in tmp_path.iterdir()] == ["net.toml"]
    g = _file(
        tmp_path,
        "sw.toml",
        """\
        study = "brown_table1"
        trials = 400
        chunk = 20
        [plate]
        spacing_mm = 3.0
        [sweep]
        "plate.grid" = [5, 60]
        """,
    )
    assert main(["check", str(g), "--max-memory-gb", "0.05"]) == 2
    err = capsys.readouterr().err
    assert "plate.grid = 60" in err and "sweep.plate.grid" in err, err


def test_a_sweeps_table_gives_a_region_rows_range(tmp_path):
    cols = {
        "cell": [0, 1],
        "replicate": [0, 0],
        "label": ["cell0000_r0", "cell0001_r0"],
        "seed": [1, 2],
        "feasible": [True, True],
        "reason": ["", ""],
        "comparator.station_offset_mm": [8.0, 17.0],
        "r.share": [0.12, 0.04],
        "r.share:lo": [0.12, 0.04],
        "r.share:hi": [0.92, 0.92],
        "m.rms_um": [1.64, 1.65],
        "m.rms_um:lo": [1.60, 1.61],
        "m.rms_um:hi": [1.70, 1.71],
    }
    prov = {
        "study": "brown_table1",
        "sweep_keys": ["comparator.station_offset_mm"],
        "claim_intervals": {"r.share": ["region"], "m.rms_um": ["ci"]},
    }
    write_table(tmp_path / "sweep.parquet", cols, prov)
    text = sweep_markdown(tmp_path)
    assert "| 0.120–0.920 | 1.64 [1.60, 1.70] |" in text, text  # (U48: with its interval)
    assert "| 0.0400–0.920 | 1.65 [1.61, 1.71] |" in text, text


def test_a_sweeps_doors_say_which_cells_are_off_the_papers_setup(tmp_path):
    cfg = sim.load(ROOT / "studies" / "brown_table1.toml").config
    cols = {
        "cell": [0, 1],
        "replicate": [0, 0],
        "label": ["cell0000_r0", "cell0001_r0"],
        "seed": [1, 2],
        "feasible": [True, True],
        "reason": ["", ""],
        "errors.settings": [1, 2],
    }
    prov = {
        "study": "brown_table1",
        "config": cfg,
        "sweep": {"errors.settings": [1, 2]},
        "sweep_keys": ["errors.settings"],
    }
    write_table(tmp_path / "sweep.parquet", cols, prov)
    said = "Off the paper's setup in 1 of 2 cells (cell0000: errors.settings = 1 (paper: 2))"
    assert said in terminal_table(tmp_path, get_study=get_study)
    assert said in terminal_summary(tmp_path, get_study=get_study)
    assert said in run_markdown(tmp_path, get_study)


INNER = """\
study = "network"
trials = 200
chunk = 10
[network]
points = [ { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
           { name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" },
           { name = "C", x_mm = 400.0, y_mm = 300.0, role = "fixed" },
           { name = "P", x_mm = 150.0, y_mm = 120.0 }, { name = "Q", x_mm = 250.0, y_mm = 180.0 } ]
generate = [ { kind = "distance", from = ["A", "B", "C"], to = ["P", "Q"], sigma_mm = 0.002 },
             { kind = "direction", from = ["A", "B", "C"], to = "*", sigma_arcsec = 2.0 } ]
[datum]
kind = "inner"
"""


@pytest.mark.parametrize("extra,key", [("", "datum.kind"), ('points = ["P", "Q"]', "datum.points")])
def test_an_inner_datum_on_a_network_its_fixed_points_hold_is_refused(tmp_path, extra, key):
    f = _file(tmp_path, "inner.toml", INNER + extra + "\n")
    with pytest.raises(
        sim.ConfigError, match=f"^{key}: .*nothing to constrain: the fixed points A, B, C"
    ):
        sim.load(f)
    sim.load(f, **{"datum.kind": "fixed"}) if not extra else None  # the datum it ran


@pytest.mark.parametrize("key,value", [("alpha", "0.01"), ("test", '"tau"')])
def test_snooping_keys_are_refused_without_snooping(tmp_path, key, value):
    f = _file(
        tmp_path,
        "a.toml",
        f"""\
        study = "agnard_block"
        [snoop]
        max_reject = 0
        {key} = {value}
        """,
    )
    with pytest.raises(
        sim.ConfigError, match=f"^snoop.{key}: is not read when snoop.max_reject = 0"
    ):
        sim.load(f)


NETWORK = (
    TRIANGLE_NETWORK
    + """\
[sweep]
"network.scale_ppm" = [0.0, 10.0]
"""
)


def test_a_full_disk_in_a_sweeps_cell_stops_the_run_resumably(tmp_path, capsys, monkeypatch):
    mod = importlib.import_module(MODULES["network"])
    real = mod.STUDIES["network"]

    def full_disk(cfg, d, ctx):
        if d.name.startswith("cell0001"):
            raise OSError(errno.ENOSPC, "No space left on device", str(d / "claims.parquet"))
        return real.run(cfg, d, ctx)

    monkeypatch.setitem(mod.STUDIES, "network", dataclasses.replace(real, run=full_disk))
    f, out = _file(tmp_path, "s.toml", NETWORK), tmp_path / "out"
    cmd = ["run", str(f), "--out", str(out), "--quiet", "--no-figures"]
    assert main(cmd) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "No space left on device" in err, err
    assert not out.exists()
    monkeypatch.setitem(mod.STUDIES, "network", real)
    assert main(cmd) == 0
    assert "resuming network: 20 finished chunks found" in capsys.readouterr().err


def test_an_inner_datum_on_weighted_coordinates_names_them():
    """The lead at the merge: the plate network's datum is carried by its observed (weighted)
    coordinates, no fixed point; the refusal said "the fixed points  already fix" (no name)."""
    plate = str(Path(__file__).resolve().parents[1] / "studies" / "network_plate.toml")
    with pytest.raises(
        sim.ConfigError, match=r"observed \(weighted\) coordinates of G1, G2, G3, G4, G5 \.\.\. "
    ):
        sim.load(plate, datum__kind="inner")
