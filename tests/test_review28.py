"""Review of the session of 2026-11-28 (brief R28): a config or an output directory resolved
before a run (the batch's checks, the Python API) is the one the run resolves.

* ``python -m sim.batch --results lnk/..`` (a ``..`` after a symbolic link): each run reads its
  ``--out lnk/../<file name>`` as the system does (:func:`sim.mc.paths.absolute`, doors28a),
  beside the link's target, but the batch's check before any run (doors28b) made it absolute
  by its letters and checked another directory: a file of the user's where the run writes
  passed the check and was refused by the run, after the other runs.
"""

from __future__ import annotations

from pathlib import Path

import pytest

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


# * ``sim.load`` resolves ``trials`` (without ``chunk``) to the chunk ``sim run --trials``
#   picks, with or without a chunk error of the file's own chunk, and keeps a given chunk
#   (sim.studies.picking.load_picking_chunk, sim run's rule too; doors28b wrote it twice).


@pytest.mark.parametrize(
    "vals, argv",
    [
        ({"trials": 400}, ["--trials", "400"]),  # the file's chunk 200: two chunks, cut to 20
        ({"trials": 100}, ["--trials", "100"]),  # fewer trials than a chunk: the chunk error path
        ({"trials": 400, "chunk": 20}, ["--trials", "400", "--chunk", "20"]),  # given: kept
        ({"seed": 5}, ["--seed", "5"]),  # no trials: the file's chunk
    ],
)
def test_the_api_resolves_the_config_sim_run_resolves(vals, argv):
    import sim
    from sim.cli import DOC
    from sim.cli_args import parser
    from sim.cli_run import load_run

    study = ROOT / "studies" / "brown_table1.toml"
    _, cfg = load_run(parser(DOC).parse_args(["run", str(study), *argv]))
    assert sim.load(study, **vals).config == cfg


def test_a_batch_from_a_deleted_working_directory_is_one_line(tmp_path, monkeypatch, capsys):
    """Each run resolves its ``--out`` against the working directory (sim.mc.paths.absolute)
    and refuses when it is gone; the batch's check before the runs ended in a traceback
    (FileNotFoundError of os.getcwd) with the default, relative ``--results``."""
    from sim import batch

    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    study = str(ROOT / "studies" / "network_plate.toml")
    for results in ([], ["--results", str(tmp_path / "R")]):
        assert batch.main([*results, study, "--", "--trials", "40"]) == 2
        err = capsys.readouterr().err
        # one line naming the working directory as gone (with the default --results, the
        # argument it was read for, since doors41l)
        assert err.startswith("sim.batch: ") and err.count("\n") == 1, err
        assert "working directory" in err and ("gone" in err or "deleted" in err), err
    assert sorted(p.name for p in tmp_path.iterdir()) == []
