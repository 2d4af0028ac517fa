"""The classes of the sweep doors20b (issue 26: a designer's trade-off study end to end, with
``[sweep]`` tables), one case each; each failed on the code before its fix.

* an interrupted sweep was not resumable: its finished cells' chunks lie under
  ``cells/<label>/trials/``, which the staging directory's chunk count did not look at, so
  Ctrl-C or SIGTERM found "no finished chunk" and deleted the whole staging directory (while
  saying "run the same command again to finish the missing chunks");
* one value given twice in a swept key (``[1e-3, 0.001]``, ``[4, 4.0]`` of an integer key,
  ``["grid", 'grid']``, ``[2, 2, 1]``) made two cells of one configuration with different
  seeds: the table and the figure showed one setting with two results; it is refused naming
  ``sweep.<key>`` and the value, and a value is recorded as its key reads it (``4``, not
  ``4.0``, in ``sweep.parquet``);
* ``sim show`` of a sweep printed the cell labels and "yes" alone: which setting each cell
  is, and where its claims are, was not said; each row now has the swept values;
* a swept study was never current for ``sim.batch --stale-only`` (so ``make reproduce``):
  its run record holds the ``[sweep]`` table beside the config, the staleness check compared
  the config alone ("made with another config: sweep") and re-ran it every time;
* ``make verify`` over results that hold only sweeps said "no study results in DIR (no
  */claims.parquet)", as if they were lost, even with ``--study`` naming a sweep (whose own
  message, "holds a sweep's results", was never reached); it names the sweeps;
* a claim with no finite value in any cell drew ``sweep.png``'s panel empty, on axes of
  -0.04 to 0.04 (not the swept range), with a legend of series that were not there; it says
  so in the panel, over the swept range;
* a sweep of three keys labelled its series with the whole dotted keys cut at 40 characters,
  so two series read the same (``network.estimate_scale=False, solver.ma...`` twice): the
  legend names the keys by their last part;
* a first swept key of 50 long text values drew 50 overlapping tick labels, each cut at its
  end so that all read the same: at most 25, upright when many, shortened in the middle.
"""

from pathlib import Path

import pytest
from oneline import SIM_ERROR, one_line

import sim.execute
from sim.batch import why_stale
from sim.cli import main
from sim.mc.config import ConfigError
from sim.mc.estimate import CELL_UNITS, estimate
from sim.mc.storage import write_table
from sim.mc.sweep import expand
from sim.report.sweep import fig_sweep
from sim.report.verify import main as verify_main
from sim.studies import get_study

ROOT = Path(__file__).resolve().parents[1]
BROWN = ROOT / "studies" / "brown_table1.toml"

NETWORK = """study = "network"
trials = 40
chunk = 2
[network]
name = "n"
points = [
  { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },
  { name = "B", x_mm = 1000.0, y_mm = 0.0, role = "fixed" },
  { name = "C", x_mm = 400.0, y_mm = 700.0 },
]
generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 0.01 } ]
"""


def _study(tmp_path: Path, sweep: str, text: str = NETWORK) -> Path:
    f = tmp_path / "s.toml"
    f.write_text(text + "[sweep]\n" + sweep)
    return f


def test_an_interrupted_sweep_keeps_its_finished_cells_and_resumes(tmp_path, capsys, monkeypatch):
    f = _study(tmp_path, '"network.scale_ppm" = [0.0, 10.0, 20.0]\n')
    out = tmp_path / "out"
    calls = []
    real = sim.execute.cell_config

    def stop_at_the_third_cell(*a, **k):
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(sim.execute, "cell_config", stop_at_the_third_cell)
    assert main(["run", str(f), "--out", str(out), "--quiet", "--no-figures"]) == 130
    stage = tmp_path / ".out.partial"
    done = sorted(stage.glob("cells/*/trials/part-*/chunk-*.parquet"))
    assert len(done) == 40  # two cells of 20 chunks each, kept for the resumption
    stamps = {p: p.stat().st_mtime_ns for p in done}
    monkeypatch.setattr(sim.execute, "cell_config", real)
    capsys.readouterr()
    assert main(["run", str(f), "--out", str(out), "--quiet", "--no-figures"]) == 0
    assert "resuming network: 40 finished chunks found" in capsys.readouterr().err
    for p, t in stamps.items():  # read again, not computed again
        q = out / p.relative_to(stage)
        assert q.stat().st_mtime_ns == t
    assert len(list(out.glob("cells/*/claims.parquet"))) == 3


@pytest.mark.parametrize(
    "sweep, key, shown",
    [
        ('"errors.bias_um" = [1e-3, 0.001]', "sweep.errors.bias_um", "(0.001)"),
        ('"errors.settings" = [4, 4.0]', "sweep.errors.settings", "(4 and 4.0)"),
        ('"plate.pattern" = ["grid", \'grid\']', "sweep.plate.pattern", "('grid')"),
        ('"errors.settings" = [2, 2, 1]', "sweep.errors.settings", "(2)"),
        (
            '"plate.points" = [[[0, 0], [9, 0], [0, 9], [9, 9]], [[0.0, 0.0], [9.0, 0.0], '
            "[0.0, 9.0], [9.0, 9.0]]]",
            "sweep.plate.points",
            "and",
        ),
    ],
)
def test_a_value_given_twice_in_a_sweep_is_refused(tmp_path, capsys, sweep, key, shown):
    f = tmp_path / "s.toml"
    f.write_text(BROWN.read_text() + "[sweep]\n" + sweep + "\n")
    for cmd in ("check", "run"):
        args = [cmd, str(f)] + (["--out", str(tmp_path / "out")] if cmd == "run" else [])
        one_line(capsys, main(args), key, "twice", shown, "replicates", prefix=SIM_ERROR)
    assert not (tmp_path / "out").exists()


def test_a_swept_value_is_recorded_as_its_key_reads_it():
    schema = get_study("brown_table1").schema
    _, cells, _, _ = expand({"errors.settings": [4.0, 5], "plate.spacing_mm": [40]}, schema)
    assert [c["errors.settings"] for c in cells] == [4, 5]
    assert all(type(c["errors.settings"]) is int for c in cells)
    assert all(type(c["plate.spacing_mm"]) is float for c in cells)
    with pytest.raises(ConfigError, match="twice"):  # without the schema too (the estimate)
        expand({"errors.bias_um": [1e-3, 0.001]})


def test_show_of_a_sweep_names_each_cells_setting(tmp_path, capsys):
    f = _study(tmp_path, '"network.scale_ppm" = [0.0, 25.0]\nreplicates = 2\n')
    out = tmp_path / "out"
    assert main(["run", str(f), "--out", str(out), "--quiet", "--no-figures"]) == 0
    capsys.readouterr()
    assert main(["show", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split() == ["cell", "network.scale_ppm", "feasible"]
    rows = [ln.split() for ln in lines[2:6]]
    assert rows == [
        ["cell0000_r0", "0.0", "yes"],
        ["cell0000_r1", "0.0", "yes"],
        ["cell0001_r0", "25.0", "yes"],
        ["cell0001_r1", "25.0", "yes"],
    ]
    assert f"sim show {out} --markdown" in lines[-1] and "4 of 4 cells ran" in lines[-1]


def test_a_swept_study_just_run_is_current_until_its_sweep_changes(tmp_path, capsys):
    f = _study(tmp_path, '"network.scale_ppm" = [0.0, 25.0]\n')
    out = tmp_path / "results" / "s"
    assert main(["run", str(f), "--out", str(out), "--quiet"]) == 0
    assert why_stale(f, out) is None
    f.write_text(f.read_text().replace("25.0]", "30.0]"))
    assert why_stale(f, out) == "made with another config: sweep"


def test_verify_over_sweeps_alone_names_them(tmp_path, capsys):
    res = tmp_path / "results"
    for name in ("sw2", "sw1"):
        (res / name).mkdir(parents=True)
        (res / name / "sweep.parquet").write_bytes(b"")
    for extra in ([], ["--study", "sw1"]):
        rc = verify_main(["--results", str(res), "--no-record", *extra])
        one_line(capsys, rc, "--results", "only sweeps' results (sw1, sw2", "sim run")


def test_sweep_png_says_a_claim_has_no_finite_value(tmp_path, monkeypatch):
    nan, cols = float("nan"), {"cell": [0, 0, 1, 1], "replicate": [0, 0, 0, 0]}
    cols.update(label=["a", "b", "c", "d"], seed=[1, 2, 3, 4], feasible=[True] * 4)
    cols.update({"reason": [""] * 4, "x_mm": [10.0, 10.0, 20.0, 20.0], "k": [1, 2, 1, 2]})
    for c, v in (("gone_mm", [nan] * 4), ("kept_mm", [1.0, 2.0, 3.0, 4.0])):
        cols.update({c: v, c + ":lo": [x - 0.1 for x in v], c + ":hi": [x + 0.1 for x in v]})
    write_table(tmp_path / "sweep.parquet", cols, {"study": "network", "sweep_keys": ["x_mm", "k"]})
    figs = []
    monkeypatch.setattr("sim.report.sweep.save", lambda fig, png: figs.append(fig))
    fig_sweep(tmp_path / "sweep.parquet", tmp_path / "sweep.png")
    (fig,) = figs
    gone = next(a for a in fig.axes if a.get_title() == "gone_mm")
    kept = next(a for a in fig.axes if a.get_title() == "kept_mm")
    assert [t.get_text() for t in gone.texts] == ["no finite value in any cell"]
    assert gone.get_legend() is None and kept.get_legend() is not None
    lo, hi = gone.get_xlim()
    assert lo <= 10.0 and hi >= 20.0 and hi - lo < 15.0  # the swept range, not -0.04..0.04
    assert not kept.texts


def test_sweep_png_legend_tells_every_series_apart(tmp_path, monkeypatch):
    cols = {"cell": list(range(8)), "replicate": [0] * 8, "label": list("abcdefgh")}
    cols.update(seed=list(range(8)), feasible=[True] * 8, reason=[""] * 8)
    cols["network.scale_ppm"] = [0.0] * 4 + [20.0] * 4
    cols["network.estimate_scale"] = [False, False, True, True] * 2
    cols["solver.max_iter"] = [20, 5] * 4
    cols.update({"v_mm": [1.0] * 8, "v_mm:lo": [0.9] * 8, "v_mm:hi": [1.1] * 8})
    keys = ["network.scale_ppm", "network.estimate_scale", "solver.max_iter"]
    write_table(tmp_path / "sweep.parquet", cols, {"study": "network", "sweep_keys": keys})
    figs = []
    monkeypatch.setattr("sim.report.sweep.save", lambda fig, png: figs.append(fig))
    fig_sweep(tmp_path / "sweep.parquet", tmp_path / "sweep.png")
    labels = [t.get_text() for t in figs[0].axes[0].get_legend().get_texts()]
    assert len(labels) == 4 and len(set(labels)) == 4, labels
    assert "estimate_scale=false, max_iter=5" in labels  # as TOML writes it (doors51p)


def test_sweep_png_ticks_of_many_long_values_are_distinct_and_few(tmp_path, monkeypatch):
    n = 50
    cols = {"cell": list(range(n)), "replicate": [0] * n, "label": [str(i) for i in range(n)]}
    cols.update(seed=list(range(n)), feasible=[True] * n, reason=[""] * n)
    cols["network.name"] = [f"a very long network name, variant {i:02d}" for i in range(n)]
    cols.update({"v_mm": [1.0] * n, "v_mm:lo": [0.9] * n, "v_mm:hi": [1.1] * n})
    write_table(
        tmp_path / "sweep.parquet", cols, {"study": "network", "sweep_keys": ["network.name"]}
    )
    figs = []
    monkeypatch.setattr("sim.report.sweep.save", lambda fig, png: figs.append(fig))
    fig_sweep(tmp_path / "sweep.parquet", tmp_path / "sweep.png")
    ticks = figs[0].axes[0].get_xticklabels()
    texts = [t.get_text() for t in ticks]
    assert 10 <= len(texts) <= 25 and len(set(texts)) == len(texts), texts
    assert all(len(t) <= 16 for t in texts) and texts[0].endswith("00'")
    assert all(t.get_rotation() == 90 for t in ticks)


def test_sweep_png_draws_each_replicate_as_its_own_line(tmp_path, monkeypatch):
    """With ``replicates = 2`` one line ran through both replicates of each setting, up and
    down at every x value (a zig-zag read as noise in the design); each replicate is its own
    line now, in its group's colour, the group named once."""
    cols = {"cell": [0, 0, 1, 1, 2, 2, 3, 3], "replicate": [0, 1] * 4, "label": list("abcdefgh")}
    cols.update(seed=list(range(8)), feasible=[True] * 8, reason=[""] * 8)
    cols["x_mm"] = [1.0, 1.0, 2.0, 2.0] * 2
    cols["k"] = [1] * 4 + [2] * 4
    v = [1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5]
    cols.update({"v_mm": v, "v_mm:lo": [a - 0.1 for a in v], "v_mm:hi": [a + 0.1 for a in v]})
    write_table(tmp_path / "sweep.parquet", cols, {"study": "network", "sweep_keys": ["x_mm", "k"]})
    figs = []
    monkeypatch.setattr("sim.report.sweep.save", lambda fig, png: figs.append(fig))
    fig_sweep(tmp_path / "sweep.parquet", tmp_path / "sweep.png")
    ax = figs[0].axes[0]
    lines = [ln for ln in ax.get_lines() if ln.get_linestyle() == "-"]
    assert len(lines) == 4  # two settings of k, two replicates each
    for ln in lines:  # each line visits each x once, in order
        assert list(ln.get_xdata()) == [1.0, 2.0], ln.get_xdata()
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["k=1", "k=2"], labels
    assert "2 replicates, a line each" in ax.get_xlabel()


@pytest.mark.long
def test_a_sweep_counts_each_cells_own_cost_against_the_work_limit(tmp_path, capsys):
    """10,000 cells of Brown's 4,000 trials were estimated at 4.7e8 adjustments (under the
    5e8 limit) and ran for about 16 hours: each cell's claims, tables and README cost about a
    second of CPU that the estimate left out. Counted (CELL_UNITS a cell), the sweep is
    refused at once with the estimate."""
    sweep = (
        '"errors.settings" = [1, 2]\n'
        '"plate.spacing_mm" = {start = 10, stop = 50, num = 50}\n'
        '"errors.bias_um" = {start = 0, stop = 1, num = 100}\n'
    )
    f = tmp_path / "s.toml"
    f.write_text(BROWN.read_text().replace("trials = ", "trials = 4000 #", 1) + "[sweep]\n" + sweep)
    one_line(
        capsys, main(["check", str(f)]), "10000 sweep cells", "over the limit", prefix=SIM_ERROR
    )
    base = estimate({"study": "network", "trials": 40, "chunk": 2})
    swept = estimate({"study": "network", "trials": 40, "chunk": 2}, {"trials": [40, 40.0 + 1]})
    assert swept.adjustments >= base.adjustments + 2 * CELL_UNITS


def test_verify_says_which_sweeps_it_did_not_verify(tmp_path, capsys):
    """Results holding studies and sweeps: the sweeps were skipped without a word, and the
    run read as if everything in the directory had been verified."""
    res = tmp_path / "results"
    for name, table in (("one", "claims.parquet"), ("sw1", "sweep.parquet")):
        (res / name).mkdir(parents=True)
        (res / name / table).write_bytes(b"")
    rc = verify_main(
        ["--results", str(res), "--scratch", str(tmp_path / "s"), "--no-rerun", "--no-record"]
    )
    err = capsys.readouterr().err.splitlines()
    assert rc == 2 and err[0].startswith("sim verify: not verified: sw1 (sweeps"), err
    assert "no re-run of one" in err[1], err
