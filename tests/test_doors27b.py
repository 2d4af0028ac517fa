"""The classes of the sweep doors27b: two of the suite's own entry points at once in one clone
(two terminals, or ``make -j``). Each test failed before its fix; none sleeps to order
processes (a lock held by the test, or a hook of the code, decides the order).

* ``make venv`` in one terminal and ``make venv`` or ``make test`` in another, on a fresh
  clone: every install step took the lock ``.venv.lock`` on its own, so the second make's
  ``venv --clear`` ran between the first one's last pip step and its stamp (or after it: the
  second make had found no stamp when it started), wiping the finished .venv while the first
  went on to run the tests in it; the first make also removed the lock file the second waited
  on. Now each step checks, under the lock, whether another make finished the install while
  it waited (then does nothing), and the stamp is written under the last pip step's lock.
"""

import fcntl
import os
import shutil
import subprocess
import time
from pathlib import Path

import pytest

from tests.test_doors18c import MAKE, fake_project, user_env

pytestmark = pytest.mark.skipif(
    MAKE is None or shutil.which("flock") is None or not Path("/proc/locks").exists(),
    reason="needs make, flock(1) and /proc/locks",
)


def _waiters(path: Path) -> int:
    """How many processes wait for a flock on ``path`` (its inode in /proc/locks: ``->``)."""
    ino = os.stat(path).st_ino
    lines = Path("/proc/locks").read_text(encoding="ascii").splitlines()
    return sum(1 for x in lines if "->" in x and x.split()[-3].endswith(f":{ino}"))


def test_a_second_make_venv_that_waited_for_the_first_leaves_its_install_alone(tmp_path):
    d = fake_project(tmp_path, "/nonexistent/python3")  # a fresh clone: no usable .venv yet
    (d / ".venv" / ".installed").unlink()
    lock = d / ".venv.lock"
    fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
    fcntl.flock(fd, fcntl.LOCK_EX)  # the first make, installing
    second = subprocess.Popen(
        [MAKE, "-s", "--no-print-directory", "venv", f"PYTHON={tmp_path / 'fakepython'}"],
        cwd=d,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=user_env(),
    )
    try:
        while _waiters(lock) == 0:  # the second make's first step waits for the lock
            assert second.poll() is None, second.communicate()
            time.sleep(0.01)  # (a poll: the order is the lock's, not the sleep's)
        # the first make ends its install: a working .venv and its stamp, then the lock
        (d / ".venv" / "bin" / "python").unlink()
        (d / ".venv" / "bin" / "python").symlink_to(tmp_path / "fakepython")
        (d / ".venv" / ".installed").write_text(f"{d}\n", encoding="utf-8")
    finally:
        os.close(fd)
    out, err = second.communicate(timeout=60)
    assert second.returncode == 0, err
    # no venv --clear over the finished install, and no mark of an unfinished one left
    assert not (tmp_path / "venv.log").exists(), (tmp_path / "venv.log").read_text("utf-8")
    assert not (d / ".venv.installing").exists()
    assert (d / ".venv" / ".installed").read_text(encoding="utf-8") == f"{d}\n"
    assert lock.exists()  # the lock file stays: a third make would lock a new one


def test_one_make_venv_alone_installs_and_writes_its_stamp(tmp_path):
    # the stamp is now written by the last pip step, under its lock
    d = fake_project(tmp_path, "/nonexistent/python3")
    (d / ".venv" / ".installed").unlink()
    p = subprocess.run(
        [MAKE, "-s", "--no-print-directory", "venv", f"PYTHON={tmp_path / 'fakepython'}"],
        cwd=d,
        capture_output=True,
        text=True,
        timeout=60,
        env=user_env(),
    )
    assert p.returncode == 0, p.stderr
    assert "-m venv --clear .venv" in (tmp_path / "venv.log").read_text(encoding="utf-8")
    assert (d / ".venv" / ".installed").read_text(encoding="utf-8") == f"{d}\n"
    assert not (d / ".venv.installing").exists()
