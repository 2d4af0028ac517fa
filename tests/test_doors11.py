"""The classes of the tenth sweep of bad inputs (issue 26, doors11), one case each; each
failed on the code before its fix.

* a key given twice, once as a quoted dotted key and once in a table (``"plate.grid" = 3``
  and ``[plate] grid = 4``, in the study or in its ``[sweep]``): the later silently won; now
  refused naming the key (:func:`sim.mc.config.flatten`, :func:`sim.mc.sweep.read_sweep`);
* a sweep range whose ends are too far apart (``{start = -1.7e308, stop = 1.7e308, num =
  3}``) printed NumPy's overflow warnings before the one-line error;
* ``python -m benchmarks`` with bad arguments: argparse's two-line usage errors; ``--out``
  a file or FIFO failed after a minute of work with a traceback, ``--out ''`` wrote into the
  working directory, ``--out`` a study's results directory mixed the bench's files into it;
  ``--rerun-files`` empty, a directory or broken TOML ended in a traceback; ``--only rerun
  --no-rerun`` measured nothing and exited 0; ``--rerun-files`` without the rerun section
  was ignored.
"""

import contextlib
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from oneline import one_line

from benchmarks import cli as bench
from sim import cli, cli_check
from sim.cli import main
from sim.mc.storage import write_table
from sim.report.plotting import checking_figures
from sim.report.sweep import fig_sweep

ROOT = Path(__file__).resolve().parent.parent
TABLE1 = (ROOT / "studies" / "brown_table1.toml").read_text()


@pytest.mark.parametrize(
    "text, key",
    [
        ('"plate.grid" = 3\n' + TABLE1, "plate.grid: is given twice"),
        (TABLE1 + '\n[sweep]\n"plate.grid" = [3]\n[sweep.plate]\ngrid = [4]\n', "sweep.plate.grid"),
    ],
)
def test_a_key_given_twice_is_refused_naming_it(tmp_path, capsys, text, key):
    f = tmp_path / "twice.toml"
    f.write_text(text)
    one_line(capsys, main(["check", str(f)]), key, "given twice")


def test_an_overflowing_sweep_range_is_one_line_without_warnings(tmp_path, capsys):
    f = tmp_path / "wide.toml"
    f.write_text(
        TABLE1
        + '\n[sweep]\n"errors.setting_sigma_um" = {start = -1.7e308, stop = 1.7e308, num = 3}\n'
    )
    with _no_warnings():
        rc = main(["check", str(f)])
    # its values -1.7e308, 0, 1.7e308 are finite (L51: the span reckoned in halves; it was
    # "the range's values are not finite"): the key's own range refuses the first
    one_line(capsys, rc, "sweep.errors.setting_sigma_um", "must be > 0")


@contextlib.contextmanager
def _no_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


def test_bench_bad_arguments_are_one_line_before_any_work(tmp_path, capsys):
    (tmp_path / "a.toml").write_text("x = \n")
    (tmp_path / "res").mkdir()
    (tmp_path / "res" / "claims.parquet").write_text("")
    (tmp_path / "file").write_text("")
    out = ["--out", str(tmp_path / "b")]
    cases = [
        (["--only", "rerun", "--no-rerun", *out], "nothing to measure"),
        (["--only", "brown", "--rerun-files", "x/*.toml", *out], "--rerun-files: the rerun"),
        (["--only", "brown", "--out", ""], "--out: is empty"),
        (["--only", "brown", "--out", str(tmp_path / "file")], "not a directory"),
        (["--only", "brown", "--out", str(tmp_path / "file" / "x")], "not a writable directory"),
        (["--only", "brown", "--out", str(tmp_path / "res")], "a study's results directory"),
        (["--only", "rerun", "--rerun-files", "", *out], "--rerun-files: is empty"),
        (["--only", "rerun", "--rerun-files", str(tmp_path), *out], "is not a study file"),
        (["--only", "rerun", "--rerun-files", str(tmp_path / "a.toml"), *out], "not a readable"),
    ]
    for argv, needle in cases:
        one_line(capsys, bench.main(argv), needle)
    with pytest.raises(SystemExit) as e:
        bench.main(["--only", "nosuch"])
    one_line(capsys, e.value.code, "benchmarks: error: argument --only", "--help")
    assert not (tmp_path / "b").exists() and sorted(
        p.name for p in (tmp_path / "res").iterdir()
    ) == ["claims.parquet"]


def test_ctrl_c_while_an_entry_point_loads_is_one_line_and_exit_130():
    """Ctrl-C in the second or two in which ``sim``, ``python -m sim.batch`` or ``python -m
    sim.report.verify`` import the suite printed a KeyboardInterrupt traceback from whichever
    import ran; the entry points now guard their imports (:func:`sim.threads.interrupt_while_loading`)."""
    code = (
        "import os, signal, time\n"
        "from sim.threads import interrupt_while_loading\n"
        "interrupt_while_loading('sim')\n"
        "os.kill(os.getpid(), signal.SIGINT)\n"
        "time.sleep(30)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 130 and done.stderr == "sim: interrupted\n", done


@pytest.mark.long
def test_the_entry_points_hand_ctrl_c_back_once_loaded():
    for mod in ("sim.__main__", "sim.batch", "sim.report.verify"):  # none runs its main
        code = (
            f"import signal, sys\nsys.argv = ['-m']\nimport {mod}\n"
            "assert signal.getsignal(signal.SIGINT) is signal.default_int_handler\n"
        )
        done = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, timeout=120
        )
        assert done.returncode == 0, (mod, done.stderr[-500:])


def test_a_refused_sweep_of_a_list_valued_key_isone_line(tmp_path, capsys):
    """Every cell of a sweep of a list-valued key (``plate.points``) refused: the message
    collected the distinct values in a dict and ended in ``TypeError: unhashable type``. (The
    file's grid keys are left out: no cell of a list pattern reads them, test_left6.)"""
    f = tmp_path / "points.toml"
    f.write_text(
        TABLE1.replace("grid = 5\nspacing_mm = 45.0\n", "")
        + '\n[sweep]\n"plate.points" = [[[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]]]\n'
        '"plate.pattern" = ["list"]\n'
    )
    one_line(capsys, main(["check", str(f)]), "sweep.plate.points: every cell failed", "4 points")


def test_sweep_png_of_list_values_keeps_its_axes(tmp_path, monkeypatch):
    """A sweep of ``plate.points`` (list values) drew its legend labels whole, crowding the
    axes to nothing (matplotlib: "axes sizes collapsed to zero"), and put a text first key's
    cells at their row numbers; now the labels are shortened and each distinct value of a
    first key that is not a number has one place, its tick labelled with the value."""
    pts = [repr([[float(i), 0.0], [0.0, 10.0 * i], [5.0, 5.0], [50.0, 50.0]]) for i in (1, 2)]
    v = np.array([3.0, 3.0, 2.5, 2.6])
    cols = {
        "cell": [0, 1, 2, 3],
        "replicate": [0, 0, 0, 0],
        "label": [f"cell{i:04d}_r0" for i in range(4)],
        "seed": [1, 2, 3, 4],
        "feasible": [True, True, True, False],
        "reason": ["", "", "", "bad"],
        "plate.pattern": ["list", "grid", "list", "grid"],
        "plate.points": [pts[0], pts[0], pts[1], pts[1]],
        "brown.closure_um": v,
        "brown.closure_um:lo": v - 0.1,
        "brown.closure_um:hi": v + 0.1,
    }
    path = tmp_path / "sweep.parquet"
    write_table(
        path, cols, {"study": "brown_table1", "sweep_keys": ["plate.pattern", "plate.points"]}
    )
    with _no_warnings(), checking_figures() as found:
        fig_sweep(path, tmp_path / "sweep.png")
    assert found == {"sweep.png": []}
    figs = []
    monkeypatch.setattr("sim.report.sweep.save", lambda fig, png: figs.append(fig))
    fig_sweep(path, tmp_path / "sweep.png")
    (ax,) = figs[0].axes
    assert [t.get_text() for t in ax.get_xticklabels()] == ["'list'", "'grid'"]
    assert all(len(t.get_text()) <= 40 for t in ax.get_legend().get_texts())


def test_bench_a_failing_write_isone_line(tmp_path, monkeypatch, capsys):
    """A write that fails (``ulimit -f``: "File too large") ended in an OSError traceback."""

    def full(*a, **k):
        raise OSError(27, "File too large")

    monkeypatch.setattr(bench, "engine_rows", lambda quick: {"case": ["x"]})
    monkeypatch.setattr(bench, "write_table", full)
    rc = bench.main(["--quick", "--only", "engines", "--out", str(tmp_path / "b")])
    one_line(capsys, rc, "benchmarks: error: writing under", "File too large")


def test_a_bug_outside_a_run_is_one_line_and_exit_3(monkeypatch, capsys):
    """A TypeError raised by ``sim check`` itself (not bad input, not inside a run) was a raw
    traceback with exit 1; docs/cli.md promises one line and exit 3 (SIM_DEBUG=1: the
    traceback)."""

    def broken(args):
        raise TypeError("unhashable type: 'list'")

    monkeypatch.setattr(cli_check, "check", broken)
    monkeypatch.delenv("SIM_DEBUG", raising=False)
    rc = cli.main(["check", str(ROOT / "studies" / "brown_table1.toml")])
    one_line(capsys, rc, "internal error: TypeError: unhashable", code=3)
    monkeypatch.setenv("SIM_DEBUG", "1")
    with pytest.raises(TypeError):
        cli.main(["check", str(ROOT / "studies" / "brown_table1.toml")])


def test_a_plate_region_too_small_to_hold_a_point_is_refused(capsys):
    """region.plate_points = 8 passed check, and the plates part then held no point of Table 1's
    region (about 3 % of the box): its rows came out undecidable naming Table 1's statements as
    conflicting. At least 256 points (about 6 in the region)."""
    f = str(ROOT / "studies" / "brown_design.toml")
    one_line(
        capsys,
        main(["check", f, "--set", "region.plate_points=8"]),
        "region.plate_points",
        ">= 256",
    )


def test_an_output_name_too_long_for_its_staging_directory_is_refused(tmp_path, capsys):
    """A study file (so a results directory) named with 247 or more characters passed the
    checks, then failed naming the run's staging directory ``.<name>.partial``: the names the
    run works with next to ``--out`` must fit the file system's name limit."""
    out = tmp_path / ("a" * 250)
    f = str(ROOT / "studies" / "brown_table1.toml")
    one_line(
        capsys, main(["run", f, "--out", str(out), "--trials", "40", "--quiet"]), "--out", "shorter"
    )
    assert list(tmp_path.iterdir()) == []  # nothing made
