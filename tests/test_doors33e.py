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

Held (the harness, outside the project, ran every command: ``sim check``, ``run``, ``show``,
``report``, ``python -m sim.batch``, ``python -m sim.report.verify``, the API): a ``TMPDIR``
that names nothing, a file, or a directory read-only to its user (run as ``nobody`` by
``setpriv`` with only ``CAP_DAC_READ_SEARCH`` kept) is passed over by Python's ``tempfile``
for ``/tmp``; one whose name holds a space works; ``--out`` and the API's ``TMPDIR`` on a
full file system (a 4 MiB tmpfs in a private mount namespace) are one line naming the chunk
file, the earlier results intact, and the same command resumes once there is room.
"""

from __future__ import annotations

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
