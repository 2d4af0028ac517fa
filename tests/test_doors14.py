"""The classes of the confirmation sweep of bad inputs (issue 26, doors14), one case each; each
failed on the code before its fix.

* a run interrupted after it wrote its tables (while drawing its figures, say) leaves them in
  its hidden staging directory ``.<name>.partial``: ``sim report`` listed that directory as
  a study of its own (next to the finished results of the same study: counted twice, linked
  to a README.md it then wrote into the staging directory), and ``make verify`` took it for a
  study to compare (:func:`sim.mc.outputs.results_dirs`);
* a run into an earlier results directory interrupted while it copied the user's files into
  its staging directory (:func:`sim.mc.publish.publish`): every later run into it refused,
  naming the user's own file as one the run writes (the copies had been recorded as the run's
  files when the resumed run sealed its staging directory);
* Ctrl-C while a run imported a module on first use (a SciPy extension raises ImportError
  from the KeyboardInterrupt): exit 3 and "the run failed", not an interruption
  (:func:`sim.threads.interrupted`).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from oneline import one_line

from sim import cli_check
from sim.cli import main
from sim.mc import publish as publishing
from sim.mc import runner
from sim.report.verify.rerun import study_dirs

ROOT = Path(__file__).resolve().parent.parent


def test_an_interrupted_runs_staging_directory_is_no_study_of_the_report(
    tiny_run, tmp_path, capsys
):
    done = tiny_run("network_brown")
    res = tmp_path / "results"
    res.mkdir()
    shutil.copytree(done, res / "network_brown")
    stage = res / ".network_brown.partial"  # what a run killed while drawing leaves
    shutil.copytree(done, stage, ignore=shutil.ignore_patterns("README.md", "*.png"))
    assert main(["report", "--results", str(res)]) == 0
    text = (res / "REPORT.md").read_text()
    assert ".partial" not in text and "[network_brown](network_brown/README.md)" in text
    assert not (stage / "README.md").exists()  # nothing written into the run's staging
    assert [d.name for d, _ in study_dirs(res)] == ["network_brown"]
    # the staging directory alone is no results: one line, exit 2, nothing written
    shutil.rmtree(res / "network_brown")
    (res / "REPORT.md").unlink()
    capsys.readouterr()
    one_line(capsys, main(["report", "--results", str(res)]), "no study results")
    assert sorted(p.name for p in res.iterdir()) == [".network_brown.partial"]


def test_a_run_cut_short_while_keeping_the_users_files_is_resumed(tmp_path, monkeypatch, capsys):
    """A run into an earlier results directory copies the user's files into its staging
    directory before it swaps it in. Interrupted there (a large file of the user's takes a
    while), every later run, the same command and ``--overwrite``, refused, naming the user's
    own file as one the new run writes; the copies were recorded as the run's own files."""
    f = str(ROOT / "studies" / "network_plate.toml")
    out = tmp_path / "np"
    cmd = ["run", f, "--out", str(out), "--quiet", "--no-figures", "--set", "trials=40"]
    cmd += ["--set", "chunk=2"]
    assert main(cmd) == 0
    (out / "notes.txt").write_text("mine")
    (out / "big.dat").write_bytes(b"\x01" * 1000)
    carry = publishing._carry
    copied = []

    def cut_short(src, dst):  # the second copy is interrupted half way
        if copied:
            dst.write_bytes(src.read_bytes()[:10])
            raise KeyboardInterrupt
        copied.append(carry(src, dst))

    monkeypatch.setattr(publishing, "_carry", cut_short)
    assert main([*cmd, "--overwrite"]) == 130
    monkeypatch.setattr(publishing, "_carry", carry)
    assert len(list((tmp_path / ".np.partial").iterdir())) > 2  # a staging directory left
    capsys.readouterr()
    assert main(cmd) == 0, capsys.readouterr().err
    assert (out / "notes.txt").read_text() == "mine"
    assert (out / "big.dat").read_bytes() == b"\x01" * 1000
    files = json.loads((out / "run.json").read_text())["files"]
    assert "notes.txt" not in files and "big.dat" not in files and "claims.parquet" in files
    assert sorted(p.name for p in tmp_path.iterdir()) == ["np"]


def _import_cut_short(*args, **kwargs):
    """What a pybind11 module of SciPy's raises when Ctrl-C lands while it initialises."""
    try:
        raise KeyboardInterrupt
    except KeyboardInterrupt as k:
        raise ImportError("initialization failed") from k


def test_ctrl_c_inside_an_import_is_an_interruption(tmp_path, monkeypatch, capsys):
    """Ctrl-C while a run imported a module on first use (Wolf's region, SciPy's qmc) ended
    as ``sim: error: wolf_polynomial: the run failed in ...explore_region: ImportError:
    initialization failed`` and exit 3 (a bug), not as an interruption: exit 130, one line."""
    f = str(ROOT / "studies" / "network_plate.toml")
    out = tmp_path / "np"
    monkeypatch.setattr(runner.RunContext, "progress_bar", _import_cut_short)
    cmd = ["run", f, "--out", str(out), "--quiet", "--no-figures", "--set", "trials=40"]
    one_line(capsys, main([*cmd, "--set", "chunk=2"]), prefix="sim: interrupted", code=130)
    monkeypatch.setattr(cli_check, "check", _import_cut_short)  # outside a run: the same
    assert one_line(capsys, main(["check", f]), code=130) == "sim: interrupted"
