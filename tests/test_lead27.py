"""The lead's items of the session of 2026-11-28 (issue 26), one case each; each failed on the
code before its fix.

* a network whose sigmas make the normals singular was refused as "condition number 7.4e10,
  too large to solve in double precision": double precision solves that; the refusal is the
  engine's rule (the normals scaled to unit diagonal, a reciprocal condition number under
  :data:`sim.lsq.normals.RCOND`), and the line now states that rule and its number;
* a sweep's figure with ten values of its second key drew the tenth series exactly as the
  first (nine colours, one marker and line) and labelled a range's values
  ``alpha=0.0311111111111...``; the figure check skipped error-bar series, so it passed;
* ``sim.batch --timings F`` wrote F in place: a write cut short left a truncated file that
  every later batch refused as not its own (doors27b left it).
"""

import re
from pathlib import Path

import numpy as np
from oneline import one_line, one_line_of

from sim.cli import main
from sim.lsq.normals import RCOND
from sim.mc.storage import write_table
from sim.report.plotting import layout_problems
from sim.report.sweep import fig_sweep

ROOT = Path(__file__).resolve().parent.parent
PLATE = str(ROOT / "studies" / "network_plate.toml")


def test_a_network_singular_from_its_weights_states_the_engines_rule(capsys):
    """Weighted coordinates (1 m) beside differences of 2 um: the scaled normals' reciprocal
    condition number is printed, and it is under the engine's limit it names."""
    grid = '[{prefix="G",nx=5,ny=5,spacing_mm=40.0,role="observed",sigma_mm=1e3}]'
    err = one_line(
        capsys,
        main(["check", PLATE, "--set", f"network.grids={grid}"]),
        "from its weights",
        "scaled to unit diagonal",
        f"limit of {RCOND:g}",
    )
    assert "double precision" not in err
    rc = float(re.search(r"condition number of ([0-9.e+-]+),", err).group(1))
    assert 0 < rc < RCOND


def test_a_sweeps_series_past_the_colours_are_told_apart_and_labelled_short(tmp_path, monkeypatch):
    xs, ks = [0.001, 0.05, 0.1], list(np.linspace(0.01, 0.2, 10))
    n = len(xs) * len(ks)
    cols = {"cell": list(range(n)), "replicate": [0] * n, "label": [f"c{i}" for i in range(n)]}
    cols.update(seed=list(range(n)), feasible=[True] * n, reason=[""] * n)
    cols["reliability.alpha0"] = [x for x in xs for _ in ks]
    cols["test.alpha"] = [float(k) for _ in xs for k in ks]
    v = [1.0 + 0.1 * i for i in range(n)]
    cols.update({"v_mm": v, "v_mm:lo": [a - 0.01 for a in v], "v_mm:hi": [a + 0.01 for a in v]})
    keys = ["reliability.alpha0", "test.alpha"]
    write_table(tmp_path / "sweep.parquet", cols, {"study": "network", "sweep_keys": keys})
    figs = []
    monkeypatch.setattr("sim.report.sweep.save", lambda fig, png: figs.append(fig))
    fig_sweep(tmp_path / "sweep.parquet", tmp_path / "sweep.png")
    (fig,) = figs
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels[:3] == ["alpha=0.01", "alpha=0.03111", "alpha=0.05222"], labels
    assert labels[-1] == "alpha=0.2" and len(set(labels)) == 10
    assert not [p for p in layout_problems(fig) if "look alike" in p]


def test_the_figure_check_sees_two_error_bar_series_drawn_alike():
    """The check must be able to fail: two error-bar series in one colour and style."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    for y, lab in ((1.0, "a"), (2.0, "b")):
        ax.errorbar([1, 2], [y, y + 1], yerr=[0.1, 0.1], marker="o", color="C0", label=lab)
    ax.legend()
    assert any("'a' and 'b' look alike" in p for p in layout_problems(fig))
    plt.close(fig)


_CUT_SHORT = """
import resource, signal, sys
import sim.batch as b
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG
resource.setrlimit(resource.RLIMIT_FSIZE, (2000, 2000))
b.run_all = lambda *a, **k: {f"study{i:03d}": [0, 1.5, 2.5] for i in range(300)}
sys.exit(b.main([sys.argv[1], "--results", sys.argv[2], "--timings", sys.argv[3]]))
"""


def test_a_timings_file_cut_short_keeps_the_earlier_one(tmp_path):
    """``--timings`` was written in place: a write cut short (a full disk, ``ulimit -f``) left a
    truncated file, which every later batch then refused as "not a timings file of
    sim.batch; sim never replaces it". The runs are stubbed (nothing else is written)."""
    import json
    import subprocess
    import sys

    timings = tmp_path / "timings.json"
    timings.write_text(json.dumps({"earlier": [0, 1.0, 0.0]}), encoding="utf-8")
    study = str(ROOT / "studies" / "brown_table1.toml")
    args = [sys.executable, "-c", _CUT_SHORT, study, str(tmp_path / "res"), str(timings)]
    p = subprocess.run(args, capture_output=True, text=True, cwd=ROOT, timeout=120)
    one_line_of(p, "sim.batch: --timings: ")
    assert json.loads(timings.read_text(encoding="utf-8")) == {"earlier": [0, 1.0, 0.0]}
    assert sorted(f.name for f in tmp_path.iterdir()) == ["timings.json"]
