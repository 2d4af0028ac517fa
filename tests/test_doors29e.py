"""The classes of the sweep doors29e (brief D29e: every filesystem step of a command fails in
turn, by an OSError or a kill), one case each; each failed on the code before its fix.

* ``sim run`` wrote the run's README.md (and the run record that lists it) into the results
  directory after the run had replaced it with its staging directory. A failure there (a full
  disk, EIO: the 2nd to 5th of the run's last filesystem steps) ended in exit 0 with the new
  results but no README.md (``--quiet``: not a word), and a kill there left results without
  their README, or with one that ``run.json`` does not list (the next run kept it as the
  user's). The README is now written into the sealed staging directory, so the results
  directory is the old complete one or the new complete one, and a failure is one line naming
  the file, exit 2, the finished chunks kept for the same command to resume.
* After the new results were swapped into place (renameat2), an error moving the old ones
  aside (EIO: k=70 of ``--overwrite`` over earlier results) or removing the lock file from the
  published results (k=71) ended the run in exit 2 naming a path, with its results published;
  the first left the old results in the staging directory, where they blocked the next run
  without ``--overwrite`` as "an unfinished run of a different config". The old results are
  now removed where they are, and a lock file that cannot be removed is left: exit 0.
"""

from __future__ import annotations

import errno
import json
import os

import sim.report.run_summary as run_summary
from sim.cli import main
from sim.mc import publish as publish_mod
from sim.mc.outputs import stage_dir
from sim.mc.storage import LOCK
from tests.oneline import SIM_ERROR, one_line

RUN = ["run", "studies/brown_table1.toml", "--trials", "40", "--chunk", "2", "--quiet"]
RUN += ["--set", "region.points=256", "--set", "region.rounds=0", "--no-figures"]


def test_readme_is_in_the_results_when_they_are_published(tmp_path, monkeypatch, capsys):
    """A kill right after the results directory was replaced finds README.md in it, listed
    in its run record (before: neither, the README was written afterwards)."""
    out, seen = tmp_path / "X", {}
    real = publish_mod.publish

    def publish_then_look(stage, dest):
        real(stage, dest)
        rec = json.loads((dest / "run.json").read_text())
        seen["readme"] = (dest / "README.md").is_file() and "README.md" in rec["files"]
        seen["title"] = (dest / "README.md").read_text().splitlines()[1]

    monkeypatch.setattr("sim.execute.publish", publish_then_look)
    assert main([*RUN, "--out", str(out)]) == 0
    assert seen["readme"], seen
    assert seen["title"].startswith("# X: "), seen  # its name, not the staging directory's


def test_a_readme_that_cannot_be_written_is_one_line_and_nothing_published(
    tmp_path, monkeypatch, capsys
):
    """ENOSPC writing README.md: exit 2, one line naming it and the cause; no results
    directory (before: exit 0, silently, results without a README); the same command again
    resumes the kept chunks and writes it."""
    out = tmp_path / "X"
    real = run_summary.atomic_path

    class full(real):
        def __enter__(self):
            raise OSError(errno.ENOSPC, "No space left on device", str(self.path))

    monkeypatch.setattr(run_summary, "atomic_path", full)
    rc = main([*RUN, "--out", str(out)])
    one_line(capsys, rc, "No space left on device", "README.md", prefix=SIM_ERROR)
    assert not out.exists() and stage_dir(out).is_dir()
    monkeypatch.setattr(run_summary, "atomic_path", real)
    assert main([*RUN, "--out", str(out)]) == 0
    assert "resuming brown_table1: 20 finished chunks" in capsys.readouterr().err
    assert "README.md" in json.loads((out / "run.json").read_text())["files"]
    assert not stage_dir(out).exists()


def test_a_users_readme_is_kept_over_a_rerun(tmp_path, capsys):
    """A README.md of the user's in the results (one its run record does not list: the
    Python API's runs write none) is carried into the new ones, untouched: the README now
    written before publishing must not take its place."""
    out = tmp_path / "X"
    assert main([*RUN, "--out", str(out)]) == 0
    rec = json.loads((out / "run.json").read_text())
    rec["files"].remove("README.md")
    (out / "run.json").write_text(json.dumps(rec))
    (out / "README.md").write_text("my own notes\n")
    assert main([*RUN, "--out", str(out)]) == 0
    assert (out / "README.md").read_text() == "my own notes\n"
    assert "README.md" not in json.loads((out / "run.json").read_text())["files"]
    assert main([*RUN, "--out", str(out)]) == 0  # and again: still the user's
    assert (out / "README.md").read_text() == "my own notes\n"


def _failing(monkeypatch, name, when):
    """``os.<name>`` raising EIO for the paths ``when(*args)`` picks (the others pass)."""
    real = getattr(os, name)

    def call(*a, **k):
        if when(*map(str, a[:2])):
            raise OSError(errno.EIO, "Input/output error", str(a[0]))
        return real(*a, **k)

    monkeypatch.setattr(os, name, call)


def test_old_results_that_cannot_be_moved_aside_do_not_fail_the_published_run(
    tmp_path, monkeypatch, capsys
):
    out = tmp_path / "X"
    assert main([*RUN, "--seed", "7", "--out", str(out)]) == 0
    _failing(monkeypatch, "replace", lambda a, b="": a == str(stage_dir(out)) and ".old." in b)
    assert main([*RUN, "--out", str(out), "--overwrite"]) == 0
    monkeypatch.undo()
    assert json.loads((out / "run.json").read_text())["config"]["seed"] != 7
    assert not stage_dir(out).exists() and not (out / LOCK).exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["X"]
    assert main([*RUN, "--out", str(out)]) == 0  # the next run without --overwrite


def test_a_lock_file_that_cannot_be_removed_does_not_fail_the_published_run(
    tmp_path, monkeypatch, capsys
):
    out = tmp_path / "X"
    _failing(monkeypatch, "unlink", lambda a, b="": a == str(out / LOCK))
    assert main([*RUN, "--out", str(out)]) == 0
    monkeypatch.undo()
    assert (out / "claims.parquet").is_file() and not stage_dir(out).exists()
    assert main([*RUN, "--out", str(out)]) == 0  # and it does not stand in the next run's way
