"""Review of the session of 2026-11-28 (brief R28): what the batch's checks before any run
resolve, resolved as the run resolves it.

* ``python -m sim.batch --results lnk/..`` (a ``..`` after a symbolic link): each run reads its
  ``--out lnk/../<file name>`` as the system does (:func:`sim.mc.paths.absolute`, doors28a),
  beside the link's target, but the batch's check before any run (doors28b) made it absolute
  by its letters and checked another directory: a file of the user's where the run writes
  passed the check and was refused by the run, after the other runs.
"""

from __future__ import annotations

from pathlib import Path

from sim.batch_checks import _configs_problems

ROOT = Path(__file__).resolve().parents[1]


def test_the_batch_checks_the_results_directory_its_run_writes(tmp_path, monkeypatch):
    (tmp_path / "far" / "sub").mkdir(parents=True)
    (tmp_path / "lnk").symlink_to(tmp_path / "far" / "sub")
    (tmp_path / "far" / "a").write_text("the user's file", encoding="utf-8")  # lnk/../a
    f = tmp_path / "a.toml"
    f.write_text((ROOT / "studies" / "network_plate.toml").read_text(encoding="utf-8"))
    monkeypatch.chdir(tmp_path)
    lines, loaded = _configs_problems([f], ["--trials", "40"], Path("lnk/.."))
    assert lines == [
        f"{f}: --results: lnk/../a is a file, not a results directory; sim never replaces it "
        "(choose another --results)"
    ], lines
    assert loaded == {}
    assert (tmp_path / "far" / "a").read_text(encoding="utf-8") == "the user's file"
