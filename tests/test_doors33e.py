"""Doors sweep 33e: the environment of a run, the part 32e left (``TMPDIR``, ``HOME``, the
caches, read-only and full file systems, standard streams), one case per class found; each
failed on the code before its fix.

* a ``TMPDIR`` holding a line break (or another character a path the suite records may not
  hold): ``sim.load(...).run()`` without ``out`` computed every chunk, then refused its own
  results directory as "path: must be a path (a str or os.PathLike of a str), got
  PosixPath(...)", an argument the caller never gave; ``make verify`` made its scratch
  directory there and each re-run refused its ``--out``. Both now refuse before any work,
  naming ``TMPDIR`` and its value (:func:`sim.api_tmp.temp_dir`,
  :func:`sim.report.verify.cli._main`).
* standard error that cannot be written (``2>/dev/full``): the first note a command printed
  raised, and the command stopped there: ``sim run mine/x.toml`` at its "writing to scratch/..."
  note with exit 1 and no results, ``sim check`` of a bad key with exit 1 (not 2), ``make
  verify`` with exit 1 (a failed comparison) at its first "re-running" line. A failed write to
  standard error is now dropped (there is nowhere to say it) and the command runs on, ending
  with its own code (:class:`sim.ends._Stderr`).

Held (the harness, outside the project, ran every command: ``sim check``, ``run``, ``show``,
``report``, ``python -m sim.batch``, ``python -m sim.report.verify``, the API): a ``TMPDIR``
that names nothing, a file, or a directory read-only to its user (run as ``nobody`` by
``setpriv`` with only ``CAP_DAC_READ_SEARCH`` kept) is passed over by Python's ``tempfile``
for ``/tmp``; one whose name holds a space works; ``--out`` and the API's ``TMPDIR`` on a
full file system (a 4 MiB tmpfs in a private mount namespace) are one line naming the chunk
file, the earlier results intact, and the same command resumes once there is room.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

import sim
from sim.mc.config import ConfigError

ROOT = Path(__file__).resolve().parents[1]
TABLE1 = str(ROOT / "studies" / "brown_table1.toml")


@pytest.fixture
def broken_tmpdir(tmp_path, monkeypatch):
    """A temporary directory whose name holds a line break, as ``TMPDIR`` would give it."""
    base = tmp_path / "new\nline"
    base.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(base))  # what gettempdir() read from TMPDIR
    return base


def test_a_run_without_out_refuses_a_tmpdir_with_a_line_break_before_it_runs(broken_tmpdir):
    st = sim.load(TABLE1, trials=40)
    with pytest.raises(ConfigError) as e:
        st.run(figures=False)
    assert e.value.key == "out" and "TMPDIR" in str(e.value), e.value
    assert "\n" not in str(e.value) and "new\\nline" in str(e.value)
    assert list(broken_tmpdir.iterdir()) == []  # nothing computed, nothing left


def test_verify_refuses_a_tmpdir_with_a_line_break_before_it_reruns(
    broken_tmpdir, monkeypatch, capsys
):
    from sim.report.verify import cli as verify_cli

    calls = []
    monkeypatch.setattr(verify_cli, "verify", lambda *a, **k: calls.append(a) or [])
    args = ["--results", str(ROOT / "results"), "--studies", str(ROOT / "studies")]
    rc = verify_cli.main([*args, "--study", "brown_table1", "--no-record"])
    err = capsys.readouterr().err.removesuffix("\n")
    assert rc == 2 and "\n" not in err, err
    assert "TMPDIR" in err and "--scratch" in err, err
    assert calls == [] and list(broken_tmpdir.iterdir()) == []


@pytest.mark.long
@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full on this system")
def test_a_full_standard_error_neither_stops_a_run_nor_changes_an_exit_code(tmp_path):
    (tmp_path / "studies").mkdir()  # a project of one's own: mine/ goes to scratch/, noted
    (tmp_path / "mine").mkdir()
    shutil.copy(TABLE1, tmp_path / "mine" / "brown_table1.toml")
    sim_ = [sys.executable, "-m", "sim"]

    def run(*args: str) -> int:
        with open("/dev/full", "w") as full:
            return subprocess.run(
                [*sim_, *args], cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=full
            ).returncode

    assert run("check", "mine/brown_table1.toml", "--set", "trials=-1") == 2
    run_ = ["run", "mine/brown_table1.toml", "--trials", "40", "--no-figures", "--quiet"]
    assert run(*run_) == 0
    assert len(list((tmp_path / "scratch").glob("brown_table1-*/run.json"))) == 1
