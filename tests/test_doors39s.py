"""The classes of the sweep doors39s (brief S39: a careless user of sweeps and batches: sweeps
interrupted and resumed, changed between runs, cells' tables moved by hand, sweeps over keys of
every kind, batches of sweeps), one case each; each failed on the code before its fix.

* A sweep's "Configuration" line (its README.md, ``sim show``) named only what its base
  config changed from the study file (``chunk``, ``seed``, ``trials``), never the swept keys,
  whose cells leave the file's design, nor their values; a swept key given another value
  outside ``[sweep]`` was named as a change of the run (``plate.spacing_mm = 40.0 (the file:
  45.0)``), a value no cell ran; a network's sweep (no study file to compare) said nothing.
  It now says the cells, the swept keys and their values (and the file's value of each), the
  seeds, then what the other keys change (:func:`sim.report.config_diff.sweep_config_line`).
* A sweep cell's table replaced by another cell's (``cp cells/cell0000_r0/claims.parquet
  cells/cell0001_r0/``: the same shape, other numbers) was read as its own by ``sim show`` of
  the cell and ``sim.Results(cell).table``, and ``--stale-only`` called the sweep current: the
  sweep's record kept the sha256 of its top-level tables only (a cell has no record of its
  own). It keeps every cell's tables' too, and the readers of a cell check them
  (:func:`sim.mc.table_edits.edited_cell`; ``--stale-only``: :func:`edited_tables`).
* A sweep with its keys reordered (``"test.alpha"`` and ``"reliability.power"`` swapped, to
  draw ``sweep.png`` against the other key) is another sweep: its cells come in the other
  order, each setting with another cell's seed. The run record's config is written with sorted
  keys and compared as a dict, so it was "the same config": ``--stale-only`` called the first
  order's results current (their figure against the old key, other numbers), and ``sim run``
  replaced them without ``--overwrite``. The record keeps the keys' order (``sweep_keys``,
  :func:`sim.mc.sweep.swept_order`), and both say so (:func:`sim.mc.sweep.reordered`).
* ``sim run FILE --trials 60`` of a sweep over ``trials`` (``python -m sim.batch ... --
  --trials 60`` too) ran with exit 0, recording ``trials = 60`` and ``--trials 60`` as the
  run's, where no cell ran 60 trials (each sets its swept value again); ``--set trials=60``,
  ``--chunk`` of a swept chunk and the API's ``run(trials=60)`` were refused. It is refused
  as they are (:func:`sim.studies.load_study`).
* ``sweep.png`` of a sweep over a list-valued key whose values differ in their middle
  (``network.grids`` of 3 x 3 and 4 x 4 points: ``[{'prefix': 'G', 'nx': 3, ...}]``) labelled
  every tick the same, ``"[{'pre…0012}]"`` (a long label kept both its ends): the ticks told
  no cell from another. A label leaves out the text all values share when both ends read the
  same (``…3, 'ny': 3…``, :func:`sim.report.labels.apart`).
* ``sim show`` of such a sweep gave every cell's ``network.grids`` as ``[{'prefix': 'GRID',
  '...`` (cut at 24 columns), and the sweep's configuration line would have cut them alike:
  no row said which setting its cell is (doors20b's class, for list values). A column whose
  values read the same when cut is cut apart (:func:`sim.report.labels.column`).

Held (tried through ``sim run``, ``python -m sim.batch`` and the API): a sweep killed by
SIGTERM or SIGKILL in a cell or between cells and run again gives every table and figure byte
for byte as an uninterrupted sweep; the same command with one value added, removed or
reordered is refused naming the unfinished run's sweep (``--overwrite``: started over, said
so), and a finished sweep replaced by a smaller one keeps none of the old cells; a sweep over
``network.gama_xml``, a Wolf table, ``seed`` or ``study`` is refused naming the key; a value
given twice or spelt twice (``1e3`` and ``1000``) is refused; ``[40]`` is one cell; a key of
another study is named with the study that has it; a batch naming one file twice (``./a.toml``)
is refused; two batches at once over one ``--results``: the second's run is refused in one line
naming the running one; ``--stale-only`` of a sweep whose base ``network.gama_xml`` changed runs
it again; a sweep of 50 numeric values draws its figure readably.
"""

from __future__ import annotations

import shutil
import textwrap
from pathlib import Path

import pytest
from conftest import TRIANGLE_NETWORK
from sweep_cells import cell_columns

import sim
from sim.batch_checks import why_stale
from sim.cli import main
from sim.mc.storage import write_table
from sim.mc.table_edits import edited_tables
from sim.report.run_summary import run_markdown, terminal_table
from sim.report.sweep import fig_sweep
from sim.studies import design_config, get_study

ROOT = Path(__file__).resolve().parents[1]

NETWORK = (
    TRIANGLE_NETWORK
    + """\
[sweep]
"test.alpha" = [0.05, 0.01]
"""
)


def _sweep_dir(d: Path, cfg: dict, table: dict, keys: list[str], values: dict) -> Path:
    """A sweep's results as its readers see them: ``sweep.parquet`` with its provenance."""
    cols = cell_columns(values)
    prov = {"study": cfg["study"], "config": cfg, "sweep": table, "sweep_keys": keys}
    d.mkdir()
    write_table(d / "sweep.parquet", cols, prov)
    return d


def test_a_sweeps_configuration_line_names_the_swept_keys(tmp_path):
    cfg = sim.load(ROOT / "studies" / "brown_table1.toml", trials=400).config
    cfg = {**cfg, "plate.spacing_mm": 40.0}  # outside [sweep]: no cell runs it
    table = {"plate.spacing_mm": [35.0, 45.0], "errors.settings": [1, 2]}
    values = {"plate.spacing_mm": [35.0, 35.0, 45.0, 45.0], "errors.settings": [1, 2, 1, 2]}
    d = _sweep_dir(tmp_path / "brown_table1", cfg, table, list(table), values)
    said = (
        "A sweep of 4 cells over `plate.spacing_mm` = [35.0, 45.0] (the file: 45.0); "
        "`errors.settings` = [1, 2] (the file: 2): each its own seed, spawned from seed 1967. "
        "Its other keys are not the configuration of `studies/brown_table1.toml`: `chunk` = 20 "
        "(the file: 200), `trials` = 400 (the file: 4000)."
    )
    md = run_markdown(d, get_study, design=design_config)
    assert f"**Configuration.** {said}" in md, md
    assert "(the file: 45.0), `trials`" not in md and "= 40.0" not in md
    assert said in terminal_table(d, design=design_config, get_study=get_study)
    # a network's sweep has no study file to compare with: its line still says what is swept
    net = sim.load(_file(tmp_path, "n.toml", NETWORK)).config
    values = {"test.alpha": [0.05, 0.01]}
    d = _sweep_dir(tmp_path / "n", net, {"test.alpha": [0.05, 0.01]}, ["test.alpha"], values)
    said = "A sweep of 2 cells over `test.alpha` = [0.05, 0.01]: each its own seed, spawned from"
    assert said in run_markdown(d, get_study, design=design_config)


def _file(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(textwrap.dedent(text))
    return p


@pytest.fixture(scope="module")
def swept(tmp_path_factory) -> Path:
    """A finished two-cell network sweep (tables only)."""
    tmp = tmp_path_factory.mktemp("swept")
    out = tmp / "out"
    cmd = ["run", str(_file(tmp, "s.toml", NETWORK)), "--out", str(out), "--quiet"]
    assert main([*cmd, "--no-figures"]) == 0
    return out


def test_a_cells_table_copied_from_another_cell_is_not_read_as_its_own(swept, tmp_path, capsys):
    out = tmp_path / "out"
    shutil.copytree(swept, out)
    cell = out / "cells" / "cell0001_r0"
    assert main(["show", str(cell)]) == 0  # as the run wrote it
    assert sim.Results(cell, "network").table("claims").num_rows
    assert edited_tables(out) == []
    shutil.copyfile(out / "cells" / "cell0000_r0" / "claims.parquet", cell / "claims.parquet")
    capsys.readouterr()
    assert main(["show", str(cell)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert "cell0001_r0/claims.parquet is not the table its cell's run wrote" in err, err
    with pytest.raises(sim.ConfigError, match="copied from another cell"):
        sim.Results(cell, "network").table("claims")
    assert sim.Results(cell, "network").table("points").num_rows  # its own tables still read
    assert main(["show", str(out / "cells" / "cell0000_r0")]) == 0
    assert edited_tables(out) == ["cells/cell0001_r0/claims.parquet"]  # --stale-only: re-run


def test_a_sweeps_figure_tells_list_values_apart_that_differ_in_their_middle(tmp_path, monkeypatch):
    grid = "[{{'prefix': 'G', 'nx': {n}, 'ny': {n}, 'spacing_mm': 40.0, 'sigma_mm': 0.0012}}]"
    values = [grid.format(n=n) for n in range(3, 53)]  # as sweep.parquet holds a list value
    cols = {
        "cell": list(range(50)),
        "replicate": [0] * 50,
        "label": [f"cell{i:04d}_r0" for i in range(50)],
        "seed": list(range(50)),
        "feasible": [True] * 50,
        "reason": [""] * 50,
        "network.grids": values,
        "c.x": [float(i) for i in range(50)],
        "c.x:lo": [i - 1.0 for i in range(50)],
        "c.x:hi": [i + 1.0 for i in range(50)],
    }
    prov = {"study": "network", "sweep_keys": ["network.grids"], "claim_intervals": {}}
    write_table(tmp_path / "sweep.parquet", cols, prov)
    figs: list = []
    monkeypatch.setattr("sim.report.sweep.save", lambda fig, png: figs.append(fig))
    fig_sweep(tmp_path / "sweep.parquet", tmp_path / "sweep.png")
    ticks = [t.get_text() for t in figs[0].axes[0].get_xticklabels()]
    assert len(ticks) == 25 and len(set(ticks)) == 25, ticks
    assert ticks[:2] == ["\u20263, 'ny': 3\u2026", "\u20265, 'ny': 5\u2026"], ticks
    assert all(len(t) <= 16 for t in ticks), ticks


def test_trials_of_a_sweep_over_trials_is_refused(tmp_path, capsys):
    text = NETWORK.replace('"test.alpha" = [0.05, 0.01]', "trials = [40, 80]")
    f, out = _file(tmp_path, "t.toml", text), tmp_path / "out"
    assert main(["run", str(f), "--trials", "60", "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err == (
        "sim: error: trials: is swept by the file's [sweep] table: an override would have no "
        "effect\n"
    ), err
    assert not out.exists()


def test_show_of_a_sweep_over_grids_tells_its_cells_apart(tmp_path):
    grids = [
        [{"prefix": "GRID", "nx": n, "ny": n, "spacing_mm": 40.0, "role": "observed"}]
        for n in (3, 4)
    ]
    net = sim.load(_file(tmp_path, "n.toml", NETWORK)).config
    values = {"network.grids": [repr(g) for g in grids]}  # as sweep.parquet holds a list
    d = _sweep_dir(tmp_path / "g", net, {"network.grids": grids}, ["network.grids"], values)
    lines = terminal_table(d, get_study=get_study).splitlines()
    assert lines[2].split()[:2] == ["cell0000_r0", "...'nx':"], lines
    assert "'nx': 3, 'ny': 3" in lines[2] and "'nx': 4, 'ny': 4" in lines[3], lines
    text = "\n".join(lines)
    assert "`network.grids` = [[{ nx = 3, ny = 3," in text and "[{ nx = 4, ny = 4," in text, text


def test_a_sweep_with_its_keys_reordered_is_another_run(tmp_path, capsys):
    two = NETWORK + '"reliability.power" = [0.8, 0.9]\n'
    f = _file(tmp_path, "s.toml", two)
    out = tmp_path / "results" / "s"
    assert main(["run", str(f), "--out", str(out), "--quiet", "--no-figures"]) == 0
    assert why_stale(f, out, ["--no-figures"]) is None
    alpha, power = '"test.alpha" = [0.05, 0.01]\n', '"reliability.power" = [0.8, 0.9]\n'
    f.write_text(two.replace(alpha + power, power + alpha))
    order = (
        "sweep (its keys in another order: test.alpha, reliability.power; this run "
        "reliability.power, test.alpha)"
    )
    assert why_stale(f, out, ["--no-figures"]) == f"made with another config: {order}"
    capsys.readouterr()
    assert main(["run", str(f), "--out", str(out), "--quiet", "--no-figures"]) == 2
    err = capsys.readouterr().err
    assert f"holds results of a different config: {order}; use --overwrite" in err, err
