"""The items issue 26's last note left open (review28's, doors28b's, doors28c's and doors28d's;
brief L14).

1. ``python -m sim.batch`` checked its files before any run with a near-copy of
   :func:`sim.mc.config.read_toml`'s checks in other words ("no study file x.toml" beside
   ``sim check``'s "x.toml: no such study file", no "did you mean studies/x.toml?", a
   pattern hint ``sim check`` lacked) and ``sim.load`` with a third ("x is not a study
   file"). One check, :func:`sim.mc.study_file.study_file_problem`, words every refusal of a
   path once; the three doors say its line after their own prefix.
2. (a refactor: tests/test_review28.py holds it) the chunk ``--trials`` picks is one helper,
   :func:`sim.studies.picking.load_picking_chunk`, for ``sim run`` and ``sim.load``.
3. ``make verify``'s record (``reproducibility.parquet``) named the machine and numerical
   path by a copy of :func:`sim.mc.storage.numerics` under keys of its own
   (``openblas_coretype``; an empty ``OPENBLAS_CORETYPE``, which OpenBLAS takes as unset,
   recorded as set), so the report's *Reproducibility* section and its "committed results
   were made on ... (OPENBLAS_CORETYPE=...)" named one variable two ways. The record now
   holds :func:`sim.mc.storage.numerics` as every run does.
4. The network's refusal of a ``solver.max_iter`` no probe trial meets lost, when its wording
   became the common one (:func:`sim.mc.runner.probe_limit`, left13), what the network said of
   it: the first correction from the true coordinates is the noise itself, so a trial
   converges in its second iteration at the earliest. The common line now ends with what a
   model knows of it (the network's, not Brown's models').
5. A results directory of an older version whose config held a key retired since
   (:mod:`sim.studies.retired`) was refused by ``sim run --out`` as "a different config:
   sweep.trials = 40 (this run None)", as if this run had set the key to None (and ``sim run``
   without ``--out`` said "sweep.trials 40 -> None", its own copy of the comparison). One
   function, :func:`sim.mc.config.config_changes`, says a key either side lacks as such.
6. ``python -m sim.batch`` (``make reproduce``) ended with the last run's own lines: a failed
   run among 17 was found by scrolling back. After the last run it now prints one line on
   standard output (:func:`sim.batch.summary`): ``sim.batch: 17 runs done`` (and ``, N up to
   date`` with ``--stale-only``), or ``sim.batch: 17 runs, 16 done, 1 failed
   (brown_table1.toml); exit 1``.
7. ``sim report`` over the project's own ``results/`` left out, without a word, a study file
   of ``studies/`` that had no results directory there (a paper's studies partly run read as
   the whole of it). The report now names such files below its opening screen
   (:func:`sim.cli_read.project_studies`); over a results directory of the user's (their own
   subset of studies) it says nothing of them.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

import sim
from sim import batch
from sim.cli import main
from sim.mc.config import ConfigError
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parents[1]
PLATE = ROOT / "studies" / "network_plate.toml"


# ------------------------------------------------------------- 1. one check of a study file
def _bad_path(tmp_path: Path, kind: str) -> str:
    """A path of ``kind`` that names no readable study file (the working directory is
    ``tmp_path``, which holds ``studies/net.toml``)."""
    if kind == "directory":
        (tmp_path / "d").mkdir()
        return "d"
    if kind == "fifo":
        os.mkfifo(tmp_path / "pipe.toml")
        return "pipe.toml"
    if kind == "device":
        return "/dev/null"
    if kind == "loop":
        (tmp_path / "ring").symlink_to(tmp_path / "ring")
        return "ring"
    if kind == "dangling":
        (tmp_path / "link.toml").symlink_to(tmp_path / "gone")
        return "link.toml"
    if kind == "huge":  # a sparse file over the size limit
        with open(tmp_path / "huge.toml", "wb") as f:
            f.truncate(17 * 1024**2)
        return "huge.toml"
    return {"missing": "nosuch.toml", "near": "net", "pattern": "no*.toml"}[kind]


KINDS = ["directory", "fifo", "device", "loop", "dangling", "huge", "missing", "near", "pattern"]


@pytest.mark.parametrize("kind", KINDS)
def test_the_batch_sim_check_and_the_api_refuse_a_path_in_one_wording(
    tmp_path, monkeypatch, capsys, kind
):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "studies").mkdir()
    (tmp_path / "studies" / "net.toml").write_text(PLATE.read_text(encoding="utf-8"))
    path = _bad_path(tmp_path, kind)
    line = one_line(capsys, main(["check", path]), prefix=SIM_ERROR)
    why = line.removeprefix(SIM_ERROR)
    assert why.startswith(f"{path}: "), why
    assert one_line(capsys, batch.main([path])) == f"sim.batch: {why}"
    with pytest.raises(ConfigError) as e:
        sim.load(path)
    assert str(e.value) == f"study_file: {why}"
    want = {
        "directory": "is a directory, not a study file (it holds no study file: name one)",
        "fifo": "not a regular file (a pipe or a device)",
        "device": "not a regular file (a pipe or a device)",
        "loop": "is a symbolic-link loop",
        "dangling": "is a symbolic link to",
        "huge": "over 16 MiB, too large for a study file",
        "missing": "no such study file",
        "near": "no such study file (did you mean studies/net.toml?)",
        "pattern": "no such study file (a pattern that matched no file",
    }[kind]
    assert want in why, why
    assert not (tmp_path / "results").exists()


# ------------------------------------------------------------- 3. one record of the numerics
@pytest.mark.parametrize("coretype", ["Haswell", ""])
def test_the_verify_record_names_the_numerical_path_as_every_run_does(
    tmp_path, monkeypatch, coretype
):
    from sim.mc.storage import numerics, read_provenance
    from sim.report.verify import markdown, write_record
    from sim.report.verify.rules import Comparison

    monkeypatch.setenv("OPENBLAS_CORETYPE", coretype)
    monkeypatch.setenv("SIM_NO_JIT", "1")
    run = numerics()  # what a run records in its tables' provenance
    assert run["SIM_NO_JIT"] == "1" and run.get("OPENBLAS_CORETYPE") == (coretype or None)
    machine = read_provenance(write_record(tmp_path, [Comparison("x", files=1)]))["machine"]
    assert {k: v for k, v in machine.items() if k in run or k.isupper()} == run, machine
    text = markdown(tmp_path)
    assert "SIM_NO_JIT=1" in text and "sim_no_jit" not in text, text
    assert ("OPENBLAS_CORETYPE=Haswell" in text) == bool(coretype), text
    assert "openblas_coretype" not in text, text


# ------------------------------------------------------------- 4. the network's probe hint
@pytest.mark.parametrize(
    "study, limit, hint",
    [("network_plate", 1, True), ("network_brown", 1, True), ("brown_table1", 1, False)],
)
def test_the_networks_solver_refusal_says_why_one_iteration_never_converges(
    capsys, study, limit, hint
):
    argv = ["check", str(ROOT / "studies" / f"{study}.toml"), "--set", f"solver.max_iter={limit}"]
    line = one_line(
        capsys, main(argv), "solver.max_iter", "raise solver.max_iter", prefix=SIM_ERROR
    )
    said = "the first correction from the true coordinates is the noise itself, so a trial "
    assert (said in line) == hint, line
    assert line.endswith("second iteration at the earliest") == hint, line
    if hint:  # and the limit it points to is met: two iterations pass the probe
        argv[-1] = "solver.max_iter=2"
        assert main(argv) == 0, capsys.readouterr().err


# ------------------------------------------------------------- 5. a key one config lacks
def test_a_key_of_an_older_config_is_not_said_as_none_in_this_run(tmp_path, capsys):
    from sim.cli import DOC
    from sim.cli_args import parser
    from sim.cli_run import load_run
    from sim.places import _differs

    argv = ["run", str(PLATE), "--trials", "40", "--out", str(tmp_path / "old")]
    _, cfg = load_run(parser(DOC).parse_args(argv))
    old = {k: v for k, v in cfg.items() if k != "seed"}  # a key added since
    old["sweep.trials"] = 40  # a key of an older version, retired since
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "run.json").write_text(
        json.dumps({"config": old, "code_hash": "x", "files": []}), encoding="utf-8"
    )
    line = one_line(capsys, main(argv), "--out", "holds results of a different config")
    for said in (line, _differs({"config": old}, {"config": cfg})):
        assert "None" not in said, said
        assert "sweep.trials = 40 (no such key in this run's config)" in said, said
        assert f"seed: not in that config (this run {cfg['seed']})" in said, said
    assert sorted(p.name for p in (tmp_path / "old").iterdir()) == ["run.json"]


# ------------------------------------------------------------- 6. the batch's closing line
def test_the_batch_ends_with_one_line_of_what_ran(tmp_path, capsys):
    f = tmp_path / "net.toml"
    f.write_text(PLATE.read_text(encoding="utf-8"))
    argv = ["--results", str(tmp_path / "R"), str(f), "--", "--trials", "40", "--no-figures"]
    assert batch.main(argv) == 0
    out, err = capsys.readouterr()
    assert out.splitlines()[-1] == "sim.batch: 1 run done" and err == "", (out, err)
    assert batch.main(["--stale-only", *argv]) == 0
    out, err = capsys.readouterr()
    assert out.splitlines() == ["net: up to date", "sim.batch: 1 up to date, none run"], out


def test_the_batch_summary_names_the_failed_runs_and_the_exit_code(tmp_path, capsys, monkeypatch):
    files = []
    for name in ("a", "b", "c", "d"):
        files.append(tmp_path / f"{name}.toml")
        files[-1].write_text(PLATE.read_text(encoding="utf-8"))
    codes = {"a": (0, 1.0, 0.0), "b": (2, 1.0, 0.0), "c": (-9, 1.0, 0.0)}  # d: up to date

    def run_all(files, results, jobs, run_args, stale_only, log, **_):
        return codes

    monkeypatch.setattr(batch, "run_all", run_all)
    argv = ["--stale-only", "--results", str(tmp_path / "R"), *map(str, files)]
    assert batch.main(argv) == 2
    assert capsys.readouterr().out.splitlines() == [
        "sim.batch: 3 runs, 1 done, 2 failed (b.toml, c.toml), 1 up to date; exit 2"
    ]
    codes.update(b=(0, 1.0, 0.0))
    assert batch.main(argv) == 1  # a run killed by a signal: exit 1
    assert capsys.readouterr().out == (
        "sim.batch: 3 runs, 2 done, 1 failed (c.toml), 1 up to date; exit 1\n"
    )
    codes.update(c=(0, 1.0, 0.0))
    assert batch.main(argv) == 0
    assert capsys.readouterr().out == "sim.batch: 3 runs done, 1 up to date\n"


# ------------------------------------------------------------- 7. studies the report lacks
def test_the_report_over_the_projects_results_names_study_files_without_results(
    tmp_path, capsys, monkeypatch
):
    import shutil

    from sim import cli_read

    project = tmp_path / "project"
    (project / "studies").mkdir(parents=True)
    for name in ("network_plate", "network_brown", "network_testfield"):
        shutil.copy(ROOT / "studies" / f"{name}.toml", project / "studies")
    shutil.copytree(ROOT / "results" / "network_plate", project / "results" / "network_plate")
    monkeypatch.setattr(cli_read, "STUDY_FILES", project / "studies")
    shutil.copytree(project / "results", tmp_path / "mine")  # a directory of the user's
    absent = "No results here for `studies/network_brown.toml`, `studies/network_testfield.toml`"
    for results, said in ((project / "results", True), (tmp_path / "mine", False)):
        assert main(["report", "--results", str(results)]) == 0, capsys.readouterr().err
        capsys.readouterr()
        text = (results / "REPORT.md").read_text(encoding="utf-8")
        assert (absent in text) == said, text[:3000]
        assert ("`studies/network_plate.toml`" in text) is False  # it has results
    (project / "studies" / "network_brown.toml").unlink()
    (project / "studies" / "network_testfield.toml").unlink()
    assert main(["report", "--results", str(project / "results")]) == 0
    text = (project / "results" / "REPORT.md").read_text(encoding="utf-8")
    assert "No results here" not in text  # every study file has its results: nothing said
