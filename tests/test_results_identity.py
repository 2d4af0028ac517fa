"""What a results directory is, as its readers take it (issue 26: doors20c and doors20a left
these): its figures, the code that made it, the directory a relative path names.

A figure replaced by hand. ``run.json`` recorded
every table's provenance and every chunk's sha256, but nothing of the figures: a PNG drawn by
hand (or copied from another run) beside the run's tables was embedded in the study's README
and in REPORT.md as the run's, and ``--stale-only`` called the results current. The run now
records each figure's sha256 (:func:`sim.mc.publish.seal`), and every reader of a whole
results directory checks them (:func:`sim.mc.publish.changed_figure`). Results of code that
changed since are noted by ``sim show``; ``sim.Results`` of a relative path stays where it
was named."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from sim.batch_checks import why_stale
from sim.cli import main
from sim.mc.publish import changed_figure, file_sha256
from tests.oneline import one_line

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture
def plate(tiny_run, tmp_path) -> Path:
    """A copy of the tiny network_plate run (its figures drawn) under ``tmp_path/results``."""
    d = tmp_path / "results" / "network_plate"
    shutil.copytree(tiny_run("network_plate"), d)
    return d


def test_the_run_records_the_sha256_of_every_figure_it_drew(plate):
    rec = json.loads((plate / "run.json").read_text())
    pngs = sorted(p.name for p in plate.glob("*.png"))
    assert pngs and sorted(rec["figure_sha256"]) == pngs
    assert all(rec["figure_sha256"][f] == file_sha256(plate / f) for f in pngs)
    assert changed_figure(plate) is None


def test_a_figure_replaced_by_hand_is_named_by_show_and_report(plate, capsys):
    fig = sorted(plate.glob("*.png"))[0]
    fig.write_bytes(fig.read_bytes() + b"\0")  # one byte more: another picture
    assert str(fig) in changed_figure(plate)
    one_line(capsys, main(["show", str(plate)]), fig.name, "not the figure its run drew")
    rc = main(["report", "--results", str(plate.parent)])
    one_line(capsys, rc, fig.name, "not the figure its run drew", "run its study again")


def test_a_figure_removed_is_seen_missing_and_drawn_again_by_stale_only(plate, capsys):
    """A figure deleted (to save room) is seen missing by a reader: ``sim show`` prints the
    tables; ``--stale-only`` re-runs the study to draw it again. A figure read through a
    symbolic link to the run's own bytes is the run's."""
    fig = sorted(plate.glob("*.png"))[-1]
    keep = plate.parent / "kept.png"
    fig.rename(keep)
    assert main(["show", str(plate)]) == 0 and capsys.readouterr().err == ""
    assert "is missing (the run drew it)" in changed_figure(plate)
    fig.symlink_to(keep)
    assert changed_figure(plate) is None


def test_stale_only_re_runs_results_with_a_figure_replaced_by_hand(plate, tiny_run):
    """``--stale-only`` called such results current: now it names the figure."""
    study = plate.parent / "network_plate.toml"
    run = json.loads((plate / "run.json").read_text())
    cfg = run["config"]
    src = (ROOT / "studies" / "network_plate.toml").read_text()
    src = src.replace("trials = 2000", f"trials = {cfg['trials']}")
    study.write_text(src.replace("chunk = 100", f"chunk = {cfg['chunk']}"))
    assert why_stale(study, plate) is None
    fig = sorted(plate.glob("*.png"))[0]
    fig.write_bytes(b"\x89PNG not the run's")
    assert "not the figure its run drew" in why_stale(study, plate)


def test_show_notes_results_made_by_code_that_changed_since(plate, capsys, monkeypatch):
    """Results of an older checkout that still load were shown without a word (doors20c): the
    verdicts of code since changed read as current. Now a note follows the table."""
    assert main(["show", str(plate)]) == 0
    assert capsys.readouterr().err == ""
    monkeypatch.setattr("sim.stale.study_code_hash", lambda study: "another")
    assert main(["show", str(plate)]) == 0
    out, err = capsys.readouterr()
    assert " claims: " in out  # the table as before, the note after it
    assert err.count("\n") == 1 and err.startswith("sim: note: ") and str(plate) in err
    assert "another version" in err and "make reproduce" in err


def test_results_of_a_relative_path_stay_where_they_were_named(plate, monkeypatch, tmp_path):
    """``sim.Results("network_plate", ...)`` followed a later ``os.chdir``: the same object
    read another directory's tables (doors20a). The path is taken when it is named."""
    import sim

    monkeypatch.chdir(plate.parent)
    res = sim.Results("network_plate", "network")
    assert res.path == plate
    elsewhere = tmp_path / "elsewhere" / "network_plate"
    elsewhere.mkdir(parents=True)
    monkeypatch.chdir(elsewhere.parent)
    assert res.table("claims").num_rows > 0  # still the run's, not "no tables"


def test_results_of_a_relative_path_in_a_removed_directory_is_one_line(tmp_path, monkeypatch):
    import sim
    from sim.mc.config import ConfigError

    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    with pytest.raises(ConfigError, match="current directory no longer exists"):
        sim.Results("network_plate", "network")
