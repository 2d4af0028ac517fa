"""Review of the session ending bcd59378 (brief R34: the diff 77d4b1b3..bcd59378 read for
defects); one case each, each failed on the code before its fix.

* ``SIM_STOP_WITH_PARENT`` of thousands of ASCII digits (the variable a driver sets, left in a
  shell or mistyped) was a ValueError traceback of every ``sim`` command: ``int()`` refuses
  over 4,300 digits. The pid is compared as text (:func:`sim.mc.children.die_with_parent`).
* A network's results whose ``summary.parquet`` is no Parquet table (the network kind's
  "not converged" line reads it since lead32) were refused by ``sim show`` as "claims.parquet
  ... (column 'verdict': ArrowInvalid ...)": the table last read was blamed. The damaged table
  is named (``trials.parquet`` too, agnard_block's).
* ``make verify``'s check of a table edited after its run read every name of ``run.json``'s
  ``table_sha256`` as it stood: a name with a NUL was a ValueError traceback (a FIFO's name
  would hang it). Only the names seal() writes are read, as regular files.
* A committed table replaced by a pipe (``points.parquet`` a FIFO) hung ``make verify`` for
  ever: the sha256 of the tables it reads (:func:`sim.report.verify.rules.tables_digest`)
  and the comparison opened it and waited for a writer. It is named as no regular file.
* A network run of which too few trials converged named any bias "a gross error the
  adjustment cannot absorb" (0.001 mm on distances of sigma 1 mm) where the network is too
  far from linear: the probe's rule (lead32) was not the run's. Both name a bias only when
  the probe trials converge more often without it.
* The same refusal at ``solver.max_iter = 10`` of a network of which 11 of the 16 probe
  trials converge within the default 20 (1 within 10, so ``sim check`` passed) said "place
  the points further apart": it names ``solver.max_iter`` now, with both counts.
* ``python -m sim.batch --timings F``: a lock file ``.F.lock`` removed by hand while a batch
  ran, a second batch took a new one; the first, ending, removed the second's, and a third
  batch given ``F`` ran beside the second (the last to end overwrote the other's timings). A
  batch removes the lock file only while it is still the one it holds.
* A ``network.gama_xml`` that is no gama-local file at all (``<html lang="en">``) was refused
  for its root's attribute ("gama-local takes only xmlns and version"), not for its root.
* The sweep figure's tiny y values (lead32: ``2.0×10⁻¹⁷``) were labelled at two digits
  whatever the ticks: ticks 2.5e-18 apart read ``1.1×10⁻¹⁶`` three times, and 1.25e-16 read
  ``1.3×10⁻¹⁶``. The labels have the digits that tell each tick's value.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from sim.cli import main

STUDIES = Path(__file__).resolve().parents[1] / "studies"


@pytest.fixture(scope="module")
def plate(tmp_path_factory) -> Path:
    """network_plate's results of 40 trials, copied by each test that changes them."""
    out = tmp_path_factory.mktemp("plate") / "network_plate"
    args = ["--trials", "40", "--out", str(out), "--no-figures", "--quiet"]
    assert main(["run", str(STUDIES / "network_plate.toml"), *args]) == 0
    return out


def _refused(capsys, args) -> str:
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    return err


def test_a_parent_pid_variable_of_thousands_of_digits_is_one_line_not_a_traceback():
    env = {**os.environ, "SIM_STOP_WITH_PARENT": "9" * 5000}
    p = subprocess.run(
        [sys.executable, "-m", "sim", "check", str(STUDIES / "wolf_polynomial.toml")],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert "Traceback" not in p.stderr, p.stderr[-400:]
    assert p.returncode == 130 and p.stdout == "", p.stderr[-400:]
    assert p.stderr.startswith("sim: stopped: SIM_STOP_WITH_PARENT=99999999999999999999..."), (
        p.stderr[:200]
    )
    assert len(p.stderr.splitlines()) == 1 and len(p.stderr) < 300


def test_a_damaged_summary_or_trials_table_is_named_by_sim_show(plate, tmp_path, capsys):
    out = tmp_path / "plate"
    shutil.copytree(plate, out)
    (out / "summary.parquet").write_bytes(b"garbage")
    err = _refused(capsys, ["show", str(out)])
    assert "summary.parquet" in err and "claims.parquet" not in err, err
    (out / "trials.parquet").write_bytes(b"garbage")
    err = _refused(capsys, ["show", str(out)])
    assert "trials.parquet" in err and "claims.parquet" not in err, err


def test_verify_reads_only_the_table_names_a_run_records(plate, tmp_path, capsys):
    import pyarrow as pa
    import pyarrow.parquet as pq

    from sim.report.verify import main as verify_main

    R, S = tmp_path / "R" / "network_plate", tmp_path / "S" / "network_plate"
    shutil.copytree(plate, S)
    shutil.copytree(plate, R)
    t = pq.read_table(R / "summary.parquet")
    i = t.schema.get_field_index("redundancy_sum")
    t = t.set_column(i, "redundancy_sum", pa.array([v * 1.5 for v in t.column(i).to_pylist()]))
    pq.write_table(t, R / "summary.parquet")  # edited by hand, metadata and all
    rec = json.loads((R / "run.json").read_text(encoding="utf-8"))
    rec["table_sha256"]["x\x00y.parquet"] = "0" * 64  # a run.json edited by hand too
    (R / "run.json").write_text(json.dumps(rec), encoding="utf-8")
    capsys.readouterr()
    argv = ["--results", str(R.parent), "--scratch", str(S.parent), "--no-rerun", "--no-record"]
    assert verify_main(argv) == 1
    text = " ".join(capsys.readouterr().out.split())
    assert "summary.parquet changed after the run that wrote them" in text, text


def test_a_committed_table_that_is_a_pipe_is_named_not_waited_on(plate, tmp_path):
    R, S = tmp_path / "R" / "network_plate", tmp_path / "S" / "network_plate"
    shutil.copytree(plate, S)
    shutil.copytree(plate, R)
    (R / "points.parquet").unlink()
    os.mkfifo(R / "points.parquet")
    argv = ["--results", str(R.parent), "--scratch", str(S.parent), "--no-rerun", "--no-record"]
    p = subprocess.run(  # before: it waited for a writer of the pipe, for ever
        [sys.executable, "-m", "sim.report.verify", *argv],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert p.returncode == 1, p.stderr
    assert "points.parquet: the committed file is not a regular file" in p.stdout, p.stdout


def test_a_tiny_bias_is_not_blamed_when_too_few_trials_of_the_run_converge(tmp_path, capsys):
    # 300 random points in a 12 m square, 8 nearest distances of 1 mm: 1 of the 16 probe
    # trials converges (so `sim check` passes), too few of the run's; a bias of 0.001 sigma
    # changes no probe trial
    p = tmp_path / "tri.toml"
    p.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\nseed = 5\n[network]\n'
        'random = [ { prefix = "P", n = 300, half_extent_mm = 6000 } ]\n'
        'generate = [ { kind = "distance", from = "P*", to = "P*", nearest = 8, sigma_mm = 1.0,'
        ' bias_mm = 0.001 }, { kind = "direction", from = "P1*", to = "P*", nearest = 4,'
        " sigma_arcsec = 2.0 } ]\n"
        '[datum]\nkind = "inner"\n',
        encoding="utf-8",
    )
    args = ["run", str(p), "--out", str(tmp_path / "o"), "--no-figures", "--quiet"]
    err = _refused(capsys, args)
    assert "too few trials" in err and "weakest sight" in err, err
    assert "bias" not in err, err


def test_a_batch_leaves_the_timings_lock_another_batch_took_after_its_was_removed(tmp_path, capsys):
    from sim.batch import main as batch_main
    from sim.batch_timings import TimingsLock

    timings = tmp_path / "t.json"
    first = TimingsLock(timings)
    assert first.acquire() is None
    first.lock.unlink()  # "a stale lock file": removed by hand while its batch runs
    second = TimingsLock(timings)
    assert second.acquire() is None
    first.release()  # the first batch ends
    try:
        args = ["--timings", str(timings), "--results", str(tmp_path / "r")]
        rc = batch_main([*args, str(STUDIES / "brown_table1.toml")])
        err = capsys.readouterr().err
        assert rc == 2 and len(err.splitlines()) == 1, err  # before: it ran beside the second
        assert f"--timings: another sim.batch (pid {os.getpid()}) writes {timings}" in err, err
    finally:
        second.release()
    assert sorted(tmp_path.iterdir()) == []


def test_a_run_of_too_few_converged_trials_at_a_low_limit_names_the_limit(tmp_path, capsys):
    p = tmp_path / "tri.toml"
    p.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\nseed = 5\n[network]\n'
        'random = [ { prefix = "P", n = 300, half_extent_mm = 10000 } ]\n'
        'generate = [ { kind = "distance", from = "P*", to = "P*", nearest = 8, sigma_mm = 1.0 },'
        ' { kind = "direction", from = "P1*", to = "P*", nearest = 4, sigma_arcsec = 2.0 } ]\n'
        '[datum]\nkind = "inner"\n[solver]\nmax_iter = 10\n',
        encoding="utf-8",
    )
    args = ["run", str(p), "--out", str(tmp_path / "o"), "--no-figures", "--quiet"]
    err = _refused(capsys, args)
    assert err.startswith("sim: error: solver.max_iter: too few trials"), err
    assert "1 of 16 probe trials converge within solver.max_iter = 10, 11 within" in err, err
    assert "weakest sight" not in err, err


def test_a_gama_xml_of_another_root_is_named_for_its_root(tmp_path, capsys):
    (tmp_path / "h.xml").write_text('<?xml version="1.0"?>\n<html lang="en"><body/></html>\n')
    f = tmp_path / "g.toml"
    f.write_text(f'study = "network"\n[network]\ngama_xml = "{tmp_path / "h.xml"}"\n')
    err = _refused(capsys, ["check", str(f)])
    assert err.endswith("h.xml: the root element is <html>, not <gama-local>"), err


def test_the_sweep_figure_labels_each_tiny_tick_with_its_value(tmp_path, monkeypatch):
    import pyarrow as pa
    import pyarrow.parquet as pq

    from sim.report import sweep as sweep_fig

    vals = [1.1e-16, 1.3e-16, 1.2e-16]
    t = pa.table(
        {
            "errors.settings": [1, 2, 3],
            "replicate": [0, 0, 0],
            "feasible": [True, True, True],
            "a.tiny_mm": vals,
            "a.tiny_mm:lo": vals,
            "a.tiny_mm:hi": vals,
        }
    )
    meta = {b"sim.provenance": b'{"sweep_keys": ["errors.settings"]}'}
    pq.write_table(t.replace_schema_metadata(meta), tmp_path / "sweep.parquet")
    drawn = []
    monkeypatch.setattr(sweep_fig, "save", lambda fig, png: drawn.append(fig) or png)
    assert sweep_fig.fig_sweep(tmp_path / "sweep.parquet", tmp_path / "sweep.png") is not None
    ax = drawn[0].axes[0]
    drawn[0].canvas.draw()
    lo, hi = ax.get_ylim()
    ticks = [(y, x.get_text()) for y, x in zip(ax.get_yticks(), ax.get_yticklabels())]
    ticks = [(y, s) for y, s in ticks if lo <= y <= hi and s]
    labels = [s for _, s in ticks]
    assert len(set(labels)) == len(labels) > 2, labels
    for y, s in ticks:  # each label says its tick's value
        m, _, e = s.partition("×10")
        e = e.translate(str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789"))
        shown = float(m.replace("−", "-")) * 10 ** int(e or 0)
        assert abs(shown - y) <= 1e-3 * (hi - lo), (y, s)
