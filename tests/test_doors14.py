"""The classes of the confirmation sweep of bad inputs (issue 26, doors14), one case each; each
failed on the code before its fix.

* a run interrupted after it wrote its tables (while drawing its figures, say) leaves them in
  its hidden staging directory ``.<name>.partial``: ``sim report`` listed that directory as
  a study of its own (next to the finished results of the same study: counted twice, linked
  to a README.md it then wrote into the staging directory), and ``make verify`` took it for a
  study to compare (:func:`sim.mc.outputs.results_dirs`).
"""

from __future__ import annotations

import shutil

from sim.cli import main
from sim.report.verify.rerun import study_dirs


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
    assert main(["report", "--results", str(res)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no study results" in err[0], err
    assert sorted(p.name for p in res.iterdir()) == [".network_brown.partial"]
