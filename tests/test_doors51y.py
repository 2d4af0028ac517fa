"""Issue 26, Y53: a second fresh acceptance set, heavy on kills, resumes and concurrent use.

A results directory's ``README.md`` is written, then its ``readme_sha256`` recorded in
``run.json``: two files, two renames. A process killed between them (``kill -9`` of ``sim
report`` as it rebuilds the READMEs, of a ``sim run`` as it writes its README into the staging
directory) left a README the suite wrote whose sha256 the record did not hold: taken from then
on as edited by hand, kept by every ``sim report`` with a note, and a re-run into the
directory refused naming it, until the user moved the suite's own file away."""

from __future__ import annotations

import contextlib
import shutil
from pathlib import Path

import pytest

import sim.report.run_summary as run_summary
from sim.cli import main
from sim.mc.export_edits import changed_exports
from tests.conftest import TRIANGLE_NETWORK


class _Killed(BaseException):
    """The process dies here: nothing after it runs (no ``finally`` of the suite's is left)."""


def _kill_after_readme(monkeypatch) -> None:
    """Die right after README.md is in place (its atomic rename done), as ``kill -9`` may."""
    real = run_summary.atomic_path

    @contextlib.contextmanager
    def dying(path, *a, **k):
        with real(path, *a, **k) as tmp:
            yield tmp
        if Path(path).name == "README.md":
            raise _Killed

    monkeypatch.setattr(run_summary, "atomic_path", dying)


@pytest.fixture(scope="module")
def triangle_results(tmp_path_factory) -> Path:
    base = tmp_path_factory.mktemp("y53")
    study = base / "triangle.toml"
    study.write_text(TRIANGLE_NETWORK)
    assert main(["run", str(study), "--out", str(base / "results" / "triangle"), "--quiet"]) == 0
    return base / "results"


def test_report_killed_between_readme_and_record(triangle_results, tmp_path, monkeypatch, capsys):
    """Kill during ``sim report`` (between a study's README.md and its run.json): before, the
    README the report had just written was taken as the user's (``changed_exports`` named it
    "edited by hand?"); the next ``sim report`` kept it with a note and a re-run was refused.
    Now the record names the README being written before it is written: either README is the
    suite's, and the next report rebuilds it without a note."""
    results = tmp_path / "moved"  # elsewhere: every README names its directory, rebuilt
    shutil.copytree(triangle_results, results, symlinks=True)
    out = results / "triangle"
    _kill_after_readme(monkeypatch)
    with pytest.raises(_Killed):
        main(["report", "--results", str(results)])
    monkeypatch.undo()
    assert changed_exports(out) == {}
    capsys.readouterr()
    assert main(["report", "--results", str(results)]) == 0
    assert "edited by hand" not in capsys.readouterr().err
    assert str(out) in (out / "README.md").read_text(encoding="utf-8")
    assert changed_exports(out) == {}
