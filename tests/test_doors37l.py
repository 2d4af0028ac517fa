"""Last session's left items (doors37l), decided: each class through a real door, fixed; each
test fails on the code before its fix:

* a network whose generated points (``network.grids``, ``network.random``) failed a check of
  the placed points (beyond 100,000 km from the origin, a duplicate name) named
  ``network.points``, a key the file did not have: it names the grid's ``origin_mm`` (the
  random set's ``center_mm``), or the set's ``prefix`` of a name given twice;
* ``python -m sim.report.verify`` run from a directory inside the project (``docs/``) took
  its default ``--results`` and ``--studies`` in the working directory ("no studies/ directory
  in .../docs"), and ``python -m benchmarks`` its ``--out`` and ``--rerun-files`` ("no study
  file matches studies/*.toml"; with ``--no-rerun`` it wrote ``docs/scratch/bench-quick``):
  each now takes the project's, as ``sim run``, ``sim report`` and ``python -m sim.batch`` do
  (:func:`sim.places.base`);
* ``sim run studies/NAME.toml`` without ``--out``, where ``results/NAME`` is a symbolic link
  (to the committed results kept on another disk, or to nothing), was refused as
  "--out: results/NAME is a symbolic link; sim never replaces it", an option the command did
  not hold: the run goes to ``scratch/NAME-<hash>/`` and says why, as for a file there or a
  directory sim did not write;
* a wolf table given relative to the study file (``table1.file = "my_table.csv"`` beside
  ``mine/wolf.toml``) is read from the project root, as the schema and the paper's page say;
  its refusal was "no such file: <root>/my_table.csv", not saying why there: it now says a
  relative path is read from the project root, not from the study file's directory;
* ``sim run studies/brown_tabel1.toml`` (a name mistyped) was "no such study file" with no
  guess, where a mistyped key or option is answered "did you mean ...?": the study file of the
  nearest name in that directory is named (``sim.load`` and ``python -m sim.batch`` too);
* ``--trials 1e3`` recorded ``trials=1000`` in ``run.json``'s overrides, and ``--set
  trials=1e3`` (or the API's ``trials=1e3``) ``trials=1000.0``: one input, one config, two
  records. A float the config reads as an integer is recorded as that integer;
* ``run(trials=None)`` (or ``seed=None``) ran the handle's value where ``sim.load(f,
  trials=None)`` is refused ("None is no value"): one rule for the API, ``run()`` refuses it
  in the same words (``seed=None`` taken for "a random seed" gave the file's seed silently);
* ``Results.names()`` left out a table of the run rewritten without its provenance (by a
  tool) while ``table(name)`` refused it as "not a table sim wrote, not of 'brown_table1'":
  it is listed (the run's ``run.json`` records it), and ``table()`` says it carries no
  provenance, as ``sim show`` says of a claims table; and ``Results`` read results made by
  another version of the suite's code without a word where ``sim show`` gives a note: reading
  a table warns (``sim.StaleResultsWarning``) in the note's words.
"""

from __future__ import annotations

import contextlib
import re
import shutil
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from oneline import SIM_ERROR, VERIFY_ERROR, one_line

import benchmarks.cli
import sim
import sim.api
import sim.cli
import sim.cli_run
import sim.report.verify.cli
import sim.stale
from sim.cli import main

ROOT = Path(__file__).resolve().parents[1]
PLATE = (ROOT / "studies" / "network_plate.toml").read_text(encoding="utf-8")
GRID = "spacing_mm = 40.0,"


@pytest.mark.parametrize(
    ("edit", "key", "why"),
    [
        ((GRID, GRID + " origin_mm = [2e11, 0.0],"), "network.grids[0].origin_mm", "100,000 km"),
        (
            (
                'grids = [ { prefix = "G", nx = 5, ny = 5, spacing_mm = 40.0,',
                'random = [ { prefix = "G", n = 25, half_extent_mm = 90.0, center_mm = [0, 2e11],',
            ),
            "network.random[0].center_mm",
            "100,000 km",
        ),
        (
            ("grids = [", 'points = [ { name = "G1", x_mm = 0.0, y_mm = 0.0 } ]\ngrids = ['),
            "network.grids[0].prefix",
            "duplicate point name 'G1'",
        ),
    ],
)
def test_a_generated_point_refused_names_the_key_that_placed_it(capsys, tmp_path, edit, key, why):
    path = tmp_path / "net.toml"
    path.write_text(PLATE.replace(*edit, 1), encoding="utf-8")
    line = one_line(capsys, main(["check", str(path)]), why, prefix=SIM_ERROR + key + ":")
    assert "network.points" not in line
    with pytest.raises(sim.ConfigError, match="^" + key.replace("[", r"\[").replace("]", r"\]")):
        sim.load(path)


def test_verify_and_the_benchmark_from_inside_the_project_take_its_paths(capsys, monkeypatch):
    monkeypatch.chdir(ROOT / "docs")
    rc = sim.report.verify.cli.main(["--study", "nosuch", "--no-record"])
    one_line(capsys, rc, "no results of 'nosuch' in ../results", prefix=VERIFY_ERROR)
    seen = []
    monkeypatch.setattr(benchmarks.cli, "OutLock", lambda out: contextlib.nullcontext())
    monkeypatch.setattr(benchmarks.cli, "run", lambda *a: seen.append(a) or {})
    assert benchmarks.cli.main(["--quick", "--only", "rerun"]) == 0, capsys.readouterr().err
    assert [(str(a[0]), a[3]) for a in seen] == [("../scratch/bench-quick", "../studies/*.toml")]


@pytest.mark.parametrize("to", ["../elsewhere", "../nothing"])
def test_a_link_at_the_default_results_sends_the_run_to_scratch(capsys, tmp_path, monkeypatch, to):
    (tmp_path / "studies").mkdir()
    (tmp_path / "results").mkdir()
    shutil.copytree(ROOT / "results" / "brown_table1", tmp_path / "elsewhere")  # its own run
    text = (ROOT / "studies" / "brown_table1.toml").read_text(encoding="utf-8")
    (tmp_path / "studies" / "brown_table1.toml").write_text(text, encoding="utf-8")
    (tmp_path / "results" / "brown_table1").symlink_to(to)
    monkeypatch.chdir(tmp_path)
    seen = []
    monkeypatch.setattr(sim.cli_run, "execute", lambda *a, **k: seen.append(a[4]))
    assert main(["run", "studies/brown_table1.toml", "--quiet"]) == 0
    err = capsys.readouterr().err
    assert seen and seen[0].startswith("scratch/brown_table1-"), (seen, err)
    assert "sim: results/brown_table1 is a symbolic link, which sim never replaces: " in err
    assert "--out:" not in err


def test_a_wolf_table_beside_its_study_file_is_refused_saying_where_it_was_looked_for(
    capsys, tmp_path
):
    (tmp_path / "mine").mkdir()
    shutil.copy(ROOT / "studies" / "data" / "wolf_table1.csv", tmp_path / "mine" / "t1.csv")
    text = (ROOT / "studies" / "wolf_polynomial.toml").read_text(encoding="utf-8")
    path = tmp_path / "mine" / "wolf.toml"
    path.write_text(text.replace("studies/data/wolf_table1.csv", "t1.csv"), encoding="utf-8")
    one_line(
        capsys,
        main(["check", str(path)]),
        f"no such file: {ROOT / 't1.csv'} (a relative path is read from the project root, not "
        "from the study file's directory",
        prefix=SIM_ERROR + "table1.file: ",
    )


def test_a_mistyped_study_file_is_answered_with_the_near_name(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    want = "studies/brown_tabel1.toml: no such study file (did you mean studies/brown_table1.toml?)"
    one_line(capsys, main(["run", "studies/brown_tabel1.toml"]), prefix=SIM_ERROR + want)
    with pytest.raises(sim.ConfigError, match=re.escape(want)):
        sim.load("studies/brown_tabel1.toml")
    line = one_line(capsys, main(["check", "studies/nosuch.toml"]))
    assert line == SIM_ERROR + "studies/nosuch.toml: no such study file"  # nothing near it
    line = one_line(capsys, main(["check", "project.toml"]))  # pyproject.toml: not a study's
    assert line == SIM_ERROR + "project.toml: no such study file"


def test_a_float_count_is_recorded_as_the_integer_by_every_door(tmp_path, monkeypatch):
    seen = []
    keep = lambda *a, **k: seen.append(k["overrides"])  # noqa: E731
    monkeypatch.setattr(sim.cli_run, "execute", keep)
    monkeypatch.setattr(sim.api, "execute", keep)
    brown = str(ROOT / "studies" / "brown_table1.toml")
    for opts in (["--trials", "1e3"], ["--set", "trials=1e3"], ["--set", "trials=1000.0"]):
        assert main(["run", brown, "--out", str(tmp_path / "o"), "--quiet", *opts]) == 0
    sim.load(brown, trials=1e3).run(out=tmp_path / "a")
    sim.load(brown).run(out=tmp_path / "b", trials=1000.0)
    assert seen == [["trials=1000"]] * 5, seen


def test_run_refuses_none_for_trials_and_seed_as_load_does(tmp_path, monkeypatch):
    monkeypatch.setattr(sim.api, "execute", lambda *a, **k: None)
    h = sim.load(ROOT / "studies" / "brown_table1.toml")
    for key in ("trials", "seed"):
        with pytest.raises(sim.ConfigError, match=f"^{key}: is None, which no study file holds"):
            sim.load(h.path, **{key: None})
        with pytest.raises(sim.ConfigError, match=f"^{key}: is None, which no study file holds"):
            h.run(out=tmp_path / "o", **{key: None})


def _copy_of_brown(tmp_path: Path) -> Path:
    d = tmp_path / "brown_table1"
    shutil.copytree(ROOT / "results" / "brown_table1", d, ignore=shutil.ignore_patterns("*.png"))
    return d


def test_results_list_a_table_without_provenance_and_say_why_it_is_refused(tmp_path):
    d = _copy_of_brown(tmp_path)
    table = pq.read_table(d / "points.parquet")
    pq.write_table(table.replace_schema_metadata(None), d / "points.parquet")  # by a tool
    res = sim.Results(d, "brown_table1")
    assert "points" in res.names()
    with pytest.raises(
        sim.ConfigError,
        match="points.parquet is not a table sim wrote: it carries no provenance",
    ):
        res.table("points")


def test_results_of_other_code_warn_in_the_words_of_sim_show(tmp_path, monkeypatch, capsys):
    d = _copy_of_brown(tmp_path)
    monkeypatch.setattr(sim.stale, "study_code_hash", lambda study: "0" * 16)  # code changed
    assert main(["show", str(d)]) == 0
    note = capsys.readouterr().err.strip().removeprefix(f"sim: note: {d} ")
    assert note.startswith("was made by another version of the suite's code"), note
    with pytest.warns(sim.StaleResultsWarning, match=re.escape(note)) as caught:
        sim.Results(d, "brown_table1").claims()
    assert caught[0].filename == __file__  # the caller's line, not the suite's
