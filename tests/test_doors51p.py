"""Doors, session 51, helper P52: sweeps and overrides used as a design study would use them.

Each test names the class of bad (or merely careless) input and what the suite did with it
before: a level silently changed, a table or note that mislabels a level, an unclear refusal.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from sweep_cells import cell_columns

import sim
from sim.cli import main as sim_main
from sim.mc.chunk_count import require_chunks
from sim.mc.config import ConfigError
from sim.mc.estimate import estimate
from sim.mc.storage import provenance, write_table
from sim.mc.sweep import expand, read_sweep
from sim.report.off_paper import sweep_off_note
from sim.report.run_summary import terminal_table
from sim.report.sweep import sweep_markdown
from sim.studies import get_study
from tests.conftest import TRIANGLE_NETWORK

ROOT = Path(__file__).resolve().parent.parent
BROWN = ROOT / "studies" / "brown_table1.toml"


def _sweep_dir(
    tmp_path: Path, keys: list[str], cells: list[dict], table: dict, claim: bool = False
) -> Path:
    """A sweep's results directory as ``sim run`` writes its ``sweep.parquet`` (its record's
    ``sweep`` with its keys sorted, as the JSON of the run record writes them; the keys'
    order in ``sweep_keys``), its cells all feasible, no claims."""
    cfg = sim.load(BROWN).config
    d = tmp_path / "sw"
    d.mkdir()
    n = len(cells)
    cols = cell_columns({k: [c[k] for c in cells] for k in keys})
    if claim:  # one claim with its interval, for the figure
        cols |= {"c.v_mm": [1.0] * n, "c.v_mm:lo": [0.5] * n, "c.v_mm:hi": [1.5] * n}
    prov = provenance(
        cfg,
        sweep=dict(sorted(table.items())),
        sweep_keys=keys,
        seed_mode="spawn",
        claim_intervals={},
    )
    write_table(d / "sweep.parquet", cols, prov)
    return d


def test_range_levels_are_the_decimal_values_asked(tmp_path):
    """Class: a sweep range of decimal steps (``{start = 0.1, stop = 0.3, step = 0.1}``,
    ``{start = 0.0, stop = 1.0, num = 11}``, a descending step). The levels were reckoned in
    binary: 0.30000000000000004, 0.6000000000000001, 0.19999999999999998, each cell run at a
    value nobody asked for (and shown as such by every table). Now the values as written."""
    study = tmp_path / "range.toml"
    study.write_text(
        'study = "brown_table1"\n[sweep]\n'
        '"errors.setting_sigma_um" = { start = 0.1, stop = 0.3, step = 0.1 }\n'
        '"errors.comparator_sigma_um" = { start = 0.3, stop = 0.1, step = -0.1 }\n'
    )
    table = read_sweep(study, get_study("brown_table1").schema)
    cells = expand(table)[1]
    assert sorted({c["errors.setting_sigma_um"] for c in cells}) == [0.1, 0.2, 0.3]
    assert [c["errors.comparator_sigma_um"] for c in cells[:3]] == [0.3, 0.2, 0.1]
    tenths = expand({"k": {"start": 0.0, "stop": 1.0, "num": 11}})[1]
    assert [c["k"] for c in tenths] == [i / 10 for i in range(11)]
    # integers stay exact, a step that does not fall on stop stops before it
    assert [c["k"] for c in expand({"k": {"start": 1, "stop": 10, "step": 3}})[1]] == [1, 4, 7, 10]
    assert [c["k"] for c in expand({"k": {"start": 0.0, "stop": 1.0, "step": 0.3}})[1]] == [
        0.0,
        0.3,
        0.6,
        0.9,
    ]


def test_off_paper_note_names_the_cell_with_its_own_values(tmp_path):
    """Class: a sweep of two keys, the first not in alphabetical order (``plate.grid`` then
    ``errors.settings``). The line on the cells off the paper's setup (README.md, ``sim
    show``, the end of ``sim run``) read the run record's sweep, whose keys are sorted, and
    named ``cell0001`` (plate.grid = 5, errors.settings = 1) with the values of cell0002
    (``plate.grid = 3 (paper: 5)``). Now each cell with its own values."""
    keys = ["plate.grid", "errors.settings"]
    cells = [{"plate.grid": g, "errors.settings": s} for g in (5, 3) for s in (2, 1)]
    d = _sweep_dir(tmp_path, keys, cells, {"plate.grid": [5, 3], "errors.settings": [2, 1]})
    note = sweep_off_note(d, get_study)
    assert "3 of 4 cells (cell0001: errors.settings = 1 (paper: 2) ...)" in note, note
    assert "plate.grid" not in note, note


def test_table_levels_are_told_apart(tmp_path):
    """Class: levels of a swept float closer than three significant digits
    (``plate.spacing_mm = [45.0, 45.001]``). README.md's table of cells and ``sim show``'s
    wrote both as ``45.0``: two rows of one setting, as if the level were given twice. Now
    each level as asked (``45.001``), or with the digits that keep them apart."""
    keys = ["plate.spacing_mm"]
    cells = [{"plate.spacing_mm": v} for v in (45.0, 45.001, 0.1 + 0.2, 0.3)]
    d = _sweep_dir(tmp_path, keys, cells, {"plate.spacing_mm": [c[keys[0]] for c in cells]})
    md = sweep_markdown(d)
    rows = [line.split(" | ")[1] for line in md.splitlines() if line.startswith("| cell0")]
    assert rows == ["45.0", "45.001", "0.30000000000000004", "0.3"], md
    shown = terminal_table(d)
    lines = [line.split()[1] for line in shown.splitlines() if line.startswith("cell0")]
    assert lines == rows, shown


def test_chunk_advice_of_chunks_of_one_says_one_thing():
    """Class: too few trials in chunks of 1 (a sweep's ``trials = [40, 4]`` picks chunks of
    1 for its small cell). The refusal advised "give at least 20 trials in chunks of 1, or
    20 in chunks of 1". Now "give at least 20 trials"."""
    with pytest.raises(ConfigError) as e:
        require_chunks({"trials": 4, "chunk": 1})
    assert str(e.value).endswith("need at least 20: give at least 20 trials"), str(e.value)


def test_a_swept_switch_is_drawn_and_shown_as_its_values(tmp_path, monkeypatch):
    """Class: a bool key swept (``network.estimate_scale = [false, true]``). ``sweep.png``
    drew it on a number axis from 0.0 to 1.0, ticks at 0.2, 0.4, ... (levels nobody asked
    for), and the tables wrote ``no`` and ``yes``. Now two places labelled ``false`` and
    ``true``, as the study file writes them, and the same words in the tables."""
    import sim.report.sweep as sweep_report

    keys = ["network.estimate_scale"]
    cells = [{keys[0]: v} for v in (False, True)]
    d = _sweep_dir(tmp_path, keys, cells, {keys[0]: [False, True]}, claim=True)
    drawn = []
    monkeypatch.setattr(sweep_report, "save", lambda fig, png: drawn.append(fig) or png)
    assert sweep_report.fig_sweep(d / "sweep.parquet", d / "sweep.png") is not None
    ax = drawn[0].axes[0]
    assert [t.get_text() for t in ax.get_xticklabels()] == ["false", "true"]
    rows = [line.split(" | ")[1] for line in sweep_markdown(d).splitlines() if "| cell0" in line]
    assert rows == ["false", "true"]


def test_a_sweep_of_trials_is_estimated_at_the_chunk_its_cells_run(tmp_path):
    """Class: a sweep of ``trials`` below the study file's (``trials = [200]`` of a file of
    2,000 trials in chunks of 100). Each cell runs in the chunk ``--trials`` picks (10 here),
    but the memory estimate counted the file's chunk: ten times the memory, a sweep refused
    over a limit its cells stay far below. Now the cell's chunk."""
    f = tmp_path / "n.toml"
    f.write_text(
        TRIANGLE_NETWORK.replace("trials = 40", "trials = 2000").replace("chunk = 2", "chunk = 100")
    )
    cfg = sim.load(f).config
    swept = estimate(cfg, {"trials": [200]})
    assert swept.bytes == estimate({**cfg, "trials": 200, "chunk": 10}).bytes
    assert swept.bytes < estimate({**cfg, "trials": 200}).bytes


def test_sim_check_estimates_only_the_cells_that_run(tmp_path, capsys):
    """Class: a sweep with a level the study refuses in its cell (``trials = [40, 4]``: 4
    trials give too few chunks; recorded infeasible, never run). ``sim check``'s estimate
    counted it, "44 trials in 2 sweep cells", of a sweep that runs one cell of 40; only a
    sweep over a limit was estimated again without it. Now always without it, and the
    refused cell named once."""
    f = tmp_path / "n.toml"
    f.write_text(TRIANGLE_NETWORK + "[sweep]\ntrials = [40, 4]\n")
    assert sim_main(["check", str(f)]) == 0
    out, err = capsys.readouterr()
    work = [line for line in out.splitlines() if line.startswith("# work:")]
    assert work and work[0].startswith("# work: 40 trials,"), work
    assert err.count("1 of 2 cells are infeasible") == 1, err
