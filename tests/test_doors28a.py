"""The classes of the sweep doors28a: the clock and the file-system boundary (file times in the
future or at 1970, time zones, ``SOURCE_DATE_EPOCH``; ``--out`` on another file system, a
mount point, a path through a symbolic link). Each test failed before its fix; none sleeps.

* A ``pyproject.toml`` dated in the future (clock skew, a copy from a machine whose clock is
  ahead, ``touch -d``) made every make target install the project again (make: "Clock skew
  detected"), each time until the clock caught up, and fail with "pip could not install"
  offline; one edited while the clock stood behind the stamp's time was never installed.
  The stamp now records pyproject.toml's checksum beside the directory: decided by content,
  as the suite decides whether results are current.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import time
from pathlib import Path

import pytest

from tests.test_doors18c import MAKE, OFFLINE, fake_project, run_make, write_fake

ROOT = Path(__file__).resolve().parents[1]


def stamp_text(d: Path) -> str:
    """What a finished install writes to ``d/.venv/.installed``: the directory it serves and
    the checksum of the pyproject.toml it installed."""
    cksum = subprocess.run(
        ["cksum"], stdin=open(d / "pyproject.toml", "rb"), capture_output=True, check=True
    )
    return f"{d}\n{cksum.stdout.decode().strip().replace(' ', '-')}\n"


needs_make = pytest.mark.skipif(
    MAKE is None or shutil.which("cksum") is None, reason="needs make and cksum"
)


@needs_make
def test_a_pyproject_dated_in_the_future_is_installed_once_not_at_every_target(tmp_path):
    d = fake_project(tmp_path, str(tmp_path / "fakepython"))
    (d / ".venv" / ".installed").unlink()
    assert run_make(d, "venv").returncode == 0  # the install writes its stamp
    ahead = time.time() + 86_400  # a day ahead: clock skew, or a copy from a machine ahead
    os.utime(d / "pyproject.toml", (ahead, ahead))
    # offline now: a second install would fail
    write_fake(tmp_path / "fakepython", OFFLINE)
    p = run_make(d, "venv")
    assert p.returncode == 0 and p.stderr == "", p.stderr  # nothing to install: it is current


@needs_make
def test_a_pyproject_edited_with_an_older_time_than_the_stamp_is_installed(tmp_path):
    # the clock stood behind the stamp's time when pyproject.toml was edited (or the edit
    # kept its time: cp -p, an archive): its content changed, so the project is installed
    d = fake_project(tmp_path, str(tmp_path / "fakepython"))
    (d / ".venv" / ".installed").unlink()
    assert run_make(d, "venv").returncode == 0  # installed from this pyproject.toml
    write_fake(tmp_path / "fakepython", OFFLINE)  # offline now
    (d / "pyproject.toml").write_text("[project]\nname = 'x'\ndependencies = ['y']\n", "utf-8")
    os.utime(d / "pyproject.toml", (1_000_000_000, 1_000_000_000))  # older than the stamp
    p = run_make(d, "venv")
    assert p.returncode == 2 and "pip could not install" in p.stderr, p.stderr  # it tried
