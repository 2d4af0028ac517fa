"""Issue 26, helper U48: a new user's first hour, the design trade-off workflow (an
instrument designer copies a study, changes the instrument, sweeps a key, compares two
designs and reads the figures and README.md). Each test names the class of input and what
was wrong before."""

from __future__ import annotations

import shutil
from types import SimpleNamespace

import numpy as np
import pytest
from oneline import one_line
from test_doors37k import run_make, venv_project

import sim
from sim.cli import main
from sim.mc.config import ConfigError
from sim.mc.storage import write_table
from sim.report.plotting import layout_problems
from sim.report.sweep import fig_sweep, sweep_markdown
from sim.studies.design import claims as design_claims
from sim.studies.design import figures as design_figures
from sim.studies.design.errbudget import BUDGET_ROWS
from sim.studies.network import claims as network_claims


def _generate(sigma: float) -> list[dict]:
    return [{"kind": k, "from": "G13", "to": "G*", "sigma_mm": sigma} for k in ("dx", "dy")]


def test_sweep_png_legend_tells_apart_lists_that_differ_past_their_start(tmp_path, monkeypatch):
    """Silent nonsense in a figure: a sweep whose second key is a list of tables differing
    only in a sigma (`"network.generate" = [[{kind = "dx", ..., sigma_mm = 0.002}, ...],
    [... 0.001 ...]]`, the designer's "compare two instruments") drew two series both named
    ``generate=[{'kind': 'dx',...`` in every panel's legend: which line was which design
    could not be read. Each series is named by what tells it apart now."""
    n = 4
    cols = {"cell": list(range(n)), "replicate": [0] * n, "label": list("abcd")}
    cols.update(seed=list(range(n)), feasible=[True] * n, reason=[""] * n)
    cols["network.constant_mm"] = [0.0, 0.0, 1.0, 1.0]
    cols["network.generate"] = [str(_generate(0.002)), str(_generate(0.001))] * 2  # as stored
    cols.update({"v_mm": [1.0] * n, "v_mm:lo": [0.9] * n, "v_mm:hi": [1.1] * n})
    keys = ["network.constant_mm", "network.generate"]
    write_table(tmp_path / "sweep.parquet", cols, {"study": "network", "sweep_keys": keys})
    figs = []
    monkeypatch.setattr("sim.report.sweep.save", lambda fig, png: figs.append(fig))
    fig_sweep(tmp_path / "sweep.parquet", tmp_path / "sweep.png")
    labels = [t.get_text() for t in figs[0].axes[0].get_legend().get_texts()]
    assert len(labels) == 2 and len(set(labels)) == 2, labels
    assert "0.002" in labels[0] and "0.001" in labels[1], labels


_SWEPT_ITEM = """\
study = "network"
trials = 40
chunk = 2
[network]
grids = [ { prefix = "G", nx = 3, ny = 3, spacing_mm = 40.0, role = "observed", sigma_mm = 0.0012 } ]
generate = [ { kind = "dx", from = "G5", to = "G*", sigma_mm = 0.002 } ]
[sweep]
KEY = [40.0, 60.0]
"""


@pytest.mark.parametrize("key", ['"network.grids[0].spacing_mm"', '"network.grids.spacing_mm"'])
def test_a_swept_field_of_a_list_item_says_to_sweep_the_whole_list(tmp_path, key):
    """Unclear message: a designer sweeping the plate's spacing wrote the field of the grid
    in the `[sweep]` table (`"network.grids[0].spacing_mm" = [40.0, 60.0]`, or without the
    index) and got "sweep.network.grids[0].spacing_mm: unknown key" alone, from `sim check`,
    `sim run` and `sim.load` (the `--set` door said what to do, the sweep did not). The line
    now says the list is swept whole, one list a cell."""
    f = tmp_path / "swept.toml"
    f.write_text(_SWEPT_ITEM.replace("KEY", key))
    with pytest.raises(ConfigError) as e:
        sim.load(f)
    assert e.value.key == f"sweep.{key.strip(chr(34))}"
    assert 'sweep the whole list, one list a cell: "network.grids" = [[...], [...]]' in str(e.value)


def test_set_of_a_list_items_field_without_index_names_the_list(tmp_path, capsys):
    """Unclear message: `--set network.grids.spacing_mm=60` (a grid's field, no index) was
    "unknown key" alone, where `network.grids[0].spacing_mm` said to give the whole list."""
    rc = main(["check", "studies/network_plate.toml", "--set", "network.grids.spacing_mm=60"])
    one_line(capsys, rc, "network.grids.spacing_mm: unknown key", "--set 'network.grids=[...]'")


def test_make_leaves_a_linked_venv_of_another_directory_alone(tmp_path):
    """Deleting what the suite did not write: a project whose `.venv` is a link to another
    checkout's virtual environment (`ln -s ../main/.venv .venv`, a worktree sharing one
    install) made it again through the link at any `make` target: its stamp names the other
    directory, so `python -m venv --clear .venv` ran and emptied the other checkout's
    environment (it happened here: the shared /work/main/.venv was emptied by a `make test` in
    a worktree). The link is named, left alone, exit 2; nothing is cleared or installed."""
    d = venv_project(tmp_path, ["numpy"])
    theirs = tmp_path / "main" / ".venv"
    theirs.parent.mkdir()
    (d / ".venv").rename(theirs)
    (theirs / ".installed").write_text(f"{tmp_path / 'main'}\n1-2\n", encoding="utf-8")
    (d / ".venv").symlink_to(theirs)
    p = run_make(d, "test")
    err = p.stderr.splitlines()
    assert p.returncode == 2 and len(err) == 2 and "Traceback" not in p.stderr, p.stderr
    assert err[0].startswith(f"make: .venv is a link to {theirs}, a virtual environment made for")
    assert "remove the link, then make venv" in err[0], err
    assert not (tmp_path / "calls.log").exists()  # no venv --clear, no pip
    assert (theirs / ".installed").exists() and (d / ".venv").is_symlink()


def test_a_mistyped_make_target_lists_the_targets(tmp_path):
    """Unclear message: `make tset` (or `make verfiy`, `make reproduce-n` for `-n`) was make's
    "No rule to make target 'tset'.  Stop.", naming no target the Makefile has. One line
    now lists them (exit 2), and nothing is installed or run."""
    d = venv_project(tmp_path, ["numpy"])
    p = run_make(d, "tset")
    err = p.stderr.splitlines()
    assert p.returncode == 2 and "No rule" not in p.stderr, p.stderr
    assert err[0].startswith("make: tset is not a target of this Makefile (its targets: help venv")
    assert " verify " in err[0] and "make help says what each does" in err[0], err
    assert not (tmp_path / "calls.log").exists()


def _budget_rows() -> dict:
    """brown_design's budget table, every source at 0.5 um but the wobble's first harmonic at
    its committed 3.13e-5 um (standard error 2.76e-7 um)."""
    src = [n for n, _, _, _ in BUDGET_ROWS]
    tiny = [s == "wobble_3kg_h1" for s in src]
    return {
        "source": src,
        "description": [d for _, _, _, d in BUDGET_ROWS],
        "rms_um": [3.13e-5 if t else 0.5 for t in tiny],
        "se_um": [2.76e-7 if t else 0.0045 for t in tiny],
        "trials": [1000] * len(src),
        "settings": [False] * len(src),
    }


def test_the_error_budget_says_a_tiny_source_and_its_standard_error(monkeypatch):
    """Silent nonsense in the designer's "which error sources matter": brown_design's budget
    of a source of 3e-5 um (the pivot wobble as a first harmonic) was an empty row in
    `budget.png` (no bar at that scale, read as a source left out) and its claim's note said
    "to a standard error of 0.0000 um". Each row's label says its value now, and the note
    the standard error in significant digits."""
    b = _budget_rows()
    figs = []
    monkeypatch.setattr(design_figures, "save", lambda fig, path: figs.append(fig))
    design_figures.fig_budget(b, None, 1.3)
    ticks = [t.get_text() for t in figs[0].axes[0].get_yticklabels()]
    assert any(t.startswith("wobble_3kg_h1 (") and t.endswith(": 3.13×10⁻⁵ µm") for t in ticks)
    assert layout_problems(figs[0]) == []
    R = {
        "budget": b,
        "external": {"table1_rms": np.array([1.2, 1.3])},
        "budget_sims": {"production": {"s0_um": np.linspace(1, 2, 50), "ok": np.ones(50, bool)}},
    }
    note = design_claims._budget(R)["brown.budget.wobble_3kg_h1_um"].note
    assert "to a standard error of 2.8e-07 um" in note, note


def test_the_largest_point_sigma_gives_the_monte_carlo_of_that_coordinate():
    """Silent nonsense for the designer: `network.design.sigma_max_mm` said "analytic; Monte
    Carlo 0.001192 mm" beside an analytic 0.001036 mm on a 5 x 5 plate of equal sigmas (200
    trials): the largest of 50 noisy Monte-Carlo sigmas, without an interval, read as the
    simulation 15 % worse than the design. The note gives the Monte Carlo of the coordinate
    whose analytic sigma is the largest, with its 95 % interval."""
    an_sig = np.array([1.0, 1.0, 2.0, 1.9, 1.0, 1.0])
    s_mc = np.array([1.4, 0.9, 2.1, 1.8, 1.1, 1.2])  # the largest MC sigma is another's
    est = SimpleNamespace(an_sig=an_sig, s_mc=s_mc, s_lo=s_mc / 2, s_hi=s_mc * 2)
    an = SimpleNamespace(redundancy=np.array([0.5]), mdb=np.array([0.01]))
    net = SimpleNamespace(kind=np.array([0]))
    design = network_claims.design_figures(net, an, np.ones(3), np.array([np.nan]), est)
    assert design["sigma_max"] == (2.0, 2.1, 1.05, 4.2)
    (find,) = [f for f in network_claims._findings(design) if f[0].endswith("sigma_max_mm")]
    assert find[2] == 2.0 and find[3].endswith("Monte Carlo of that coordinate 2.1 mm [1.05, 4.2]")


def test_a_sweeps_table_gives_each_claims_interval(tmp_path):
    """A number without its interval: the table of a sweep's README.md gave each cell's
    self-check as its value alone (`network.global_test.false_alarm` 0.0650 in one cell,
    0.0850 in the next: a designer compared two noisy numbers whose 95 % intervals, [0.038,
    0.11] and [0.054, 0.13], overlap). A claim with a 95 % interval gives it; an exact one
    stays a value."""
    cols = {"cell": [0, 1], "replicate": [0, 0], "label": ["c0", "c1"], "seed": [1, 2]}
    cols.update(feasible=[True, True], reason=["", ""], x_mm=[40.0, 60.0])
    cols.update({"a.rate": [0.065, 0.085], "a.rate:lo": [0.0384, 0.0537]})
    cols.update({"a.rate:hi": [0.108, 0.132], "b_mm": [0.00104] * 2, "b_mm:lo": [0.00104] * 2})
    cols["b_mm:hi"] = [0.00104] * 2
    prov = {"study": "network", "sweep_keys": ["x_mm"]}
    prov["claim_intervals"] = {"a.rate": ["ci"], "b_mm": ["exact"]}
    write_table(tmp_path / "sweep.parquet", cols, prov)
    text = sweep_markdown(tmp_path)
    assert "| 0.0650 [0.0384, 0.108] | 0.00104 |" in text, text
    assert "| 0.0850 [0.0537, 0.132] | 0.00104 |" in text, text


def test_make_jn_reproduce_runs_n_studies_at_a_time(tmp_path):
    """Silent nonsense: `make -j4 reproduce` (make's usual way to ask for four at once) ran
    two studies at a time without a word (RUN_JOBS's default). make's -jN is RUN_JOBS's
    default now; RUN_JOBS given wins, and -j without a number keeps 2 (printed by -n: nothing
    runs)."""
    d = venv_project(tmp_path, ["numpy"])
    for args, jobs in (
        (["-j4"], "4"),
        (["-j4", "RUN_JOBS=3"], "3"),
        (["-j"], "2"),
        ([], "2"),
    ):
        p = run_make(d, "-n", *args, "reproduce")
        assert f"-m sim.batch --stale-only --report --jobs {jobs} " in p.stdout, (args, p.stdout)
    assert not (tmp_path / "calls.log").exists()


def test_report_of_two_designs_alone_has_no_empty_table(tmp_path, tiny_run, capsys):
    """Silent nonsense: `sim report --results DIR` over two network designs of one's own (no
    paper study) opened with "The verdicts at a glance" as a table header without a row.
    The table is left out when no paper's study is there; the designs' line stays."""
    results = tmp_path / "results"
    for name in ("design_a", "design_b"):
        shutil.copytree(tiny_run("network_plate"), results / name)
    assert main(["report", "--results", str(results)]) == 0
    text = (results / "REPORT.md").read_text(encoding="utf-8")
    glance = text.split("## The verdicts at a glance", 1)[1].split("\n## ", 1)[0]
    assert "| paper (studies) |" not in glance and "|---|" not in glance, glance
    assert "[design_a](design_a/README.md)" in glance and "design_b" in glance, glance


def test_a_run_off_the_papers_setup_says_it_in_a_sentence(capsys):
    """Unclear message: a designer's Brown plate of 4 x 4 (`--set plate.grid=4`) was told
    "its predictions are findings, but the 5 it decides on the paper's own setup, which stay
    the paper's verdicts": a clause without its verb, which left unclear what the 5 are. It
    says which stay the paper's verdicts, and why, in a sentence now."""
    assert main(["check", "studies/brown_table1.toml", "--set", "plate.grid=4"]) == 0
    line = capsys.readouterr().out.splitlines()[-2]
    assert line == (
        "# off the paper's setup (plate.grid = 4 (paper: 5)): its predictions will be findings,"
        " except the 5 it decides on the paper's own setup whatever the run's: those stay the"
        " paper's verdicts"
    ), line
