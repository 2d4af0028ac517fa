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

import sim.mc.publish as publish_mod
from sim.mc.outputs import stage_dir
from sim.mc.publish import publish
from sim.mc.storage import read_record, write_record
from tests.test_doors18c import MAKE, fake_project, user_env
from tests.test_doors28a import stamp_text

needs_make = pytest.mark.skipif(
    MAKE is None or shutil.which("flock") is None or not Path("/proc/locks").exists(),
    reason="needs make, flock(1) and /proc/locks",
)


def _waiters(path: Path) -> int:
    """How many processes wait for a flock on ``path`` (its inode in /proc/locks: ``->``)."""
    ino = os.stat(path).st_ino
    lines = Path("/proc/locks").read_text(encoding="ascii").splitlines()
    return sum(1 for x in lines if "->" in x and x.split()[-3].endswith(f":{ino}"))


@needs_make
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
        (d / ".venv" / ".installed").write_text(stamp_text(d), encoding="utf-8")
    finally:
        os.close(fd)
    out, err = second.communicate(timeout=60)
    assert second.returncode == 0, err
    # no venv --clear over the finished install, and no mark of an unfinished one left
    assert not (tmp_path / "venv.log").exists(), (tmp_path / "venv.log").read_text("utf-8")
    assert not (d / ".venv.installing").exists()
    assert (d / ".venv" / ".installed").read_text(encoding="utf-8") == stamp_text(d)
    assert lock.exists()  # the lock file stays: a third make would lock a new one


@needs_make
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
    assert (d / ".venv" / ".installed").read_text(encoding="utf-8") == stamp_text(d)
    assert not (d / ".venv.installing").exists()


# * ``sim report``, ``sim show`` or ``make verify`` in a second terminal while ``make
#   reproduce`` publishes a study: the old results were moved aside and the new ones moved in
#   by two renames, so for an instant the study had no directory (a loop of 300 publishes
#   against a process looking for it: absent 59 times of 72,617); a README.md written into it
#   then would have made an empty directory there. Now the two are swapped in one step
#   (renameat2 RENAME_EXCHANGE; the two renames where the system has no such call).


def _published(root: Path, text: str) -> Path:
    """``root/X`` published from a staging directory holding one table of ``text``."""
    out = root / "X"
    stage = stage_dir(out)
    stage.mkdir(parents=True)
    write_record(stage, {"config": {"study": "x"}, "code_hash": "h", "files": ["t.txt"]})
    (stage / "t.txt").write_text(text, encoding="utf-8")
    publish(stage, out)
    return out


@pytest.mark.parametrize("swap", [True, False])
def test_a_published_study_never_lacks_its_directory(tmp_path, monkeypatch, swap):
    if swap and getattr(publish_mod._libc(), "renameat2", None) is None:
        pytest.skip("no renameat2 here: the two renames are the fallback")
    out = _published(tmp_path, "old")
    (out / "notes.md").write_text("mine", encoding="utf-8")  # the user's: carried over
    real, seen = os.replace, []

    def replace(a, b):
        real(a, b)
        seen.append(out.is_dir())  # what another process looking at the study would see

    monkeypatch.setattr(os, "replace", replace)
    if not swap:  # a file system without the call: as before
        monkeypatch.setattr(publish_mod, "_exchange", lambda a, b: False)
    _published(tmp_path, "new")
    monkeypatch.undo()
    assert (out / "t.txt").read_text(encoding="utf-8") == "new"
    assert (out / "notes.md").read_text(encoding="utf-8") == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["X"]  # nothing left beside it
    if swap:
        assert seen and all(seen), seen
    else:
        assert False in seen  # the instant the fallback still has


class _Killed(BaseException):
    """A kill at one point of a run (no handler of the suite catches it)."""


def test_a_run_killed_right_after_the_swap_loses_nothing(tmp_path, monkeypatch, capsys):
    # killed between the swap and moving the old results (now at the staging path) aside:
    # the new results are in place with the user's file; the next run clears the old ones
    from sim.cli import main

    plate = str(Path(__file__).resolve().parents[1] / "studies" / "network_plate.toml")
    small = ["--trials", "40", "--chunk", "2", "--no-figures", "--quiet"]
    out = tmp_path / "out"
    assert main(["run", plate, *small, "--seed", "7", "--out", str(out)]) == 0
    (out / "user.txt").write_text("mine", encoding="utf-8")
    real = publish_mod._exchange

    def killed(a, b):
        if not real(a, b):
            pytest.skip("no renameat2 here")
        raise _Killed  # (as kill -9: nothing after the swap ran)

    monkeypatch.setattr(publish_mod, "_exchange", killed)
    with pytest.raises(_Killed):
        main(["run", plate, *small, "--seed", "8", "--overwrite", "--out", str(out)])
    monkeypatch.undo()
    assert read_record(out)["config"]["seed"] == 8
    assert (out / "user.txt").read_text(encoding="utf-8") == "mine"
    capsys.readouterr()
    assert main(["run", plate, *small, "--seed", "3", "--overwrite", "--out", str(out)]) == 0
    assert "note" not in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert (out / "user.txt").read_text(encoding="utf-8") == "mine"
    assert read_record(out)["config"]["seed"] == 3


# * ``sim run --out A`` in one terminal and ``sim run --out A/B`` in another while the first
#   works (``A`` not made yet: the first run works in ``.A.partial``): the second made ``A``,
#   and the first computed every chunk, then refused to replace it ("holds files but no sim
#   run record"). Now the second is refused at once: it lies inside the output of a run that
#   is running or unfinished.


def test_an_out_inside_the_output_of_a_run_still_working_is_refused(tmp_path, capsys):
    from sim.cli import main
    from sim.mc.storage import StageLock
    from tests.oneline import SIM_ERROR, one_line

    plate = str(Path(__file__).resolve().parents[1] / "studies" / "network_plate.toml")
    small = ["--trials", "40", "--chunk", "2", "--no-figures", "--quiet"]
    first = tmp_path / "A"
    lock = StageLock(stage_dir(first)).acquire()  # the first run, working
    try:
        rc = main(["run", plate, *small, "--out", str(first / "B")])
        one_line(capsys, rc, f"lies inside {first}, the output of a run", prefix=SIM_ERROR)
        assert not first.exists()  # nothing made where the first run will publish
    finally:
        lock.release()


# * ``sim report`` in one terminal while ``make reproduce`` publishes a study in another: the
#   report read some of the study's tables before the new results came in and the rest after
#   (or all before), and, ending last, left a REPORT.md of results no longer there. Now a report
#   whose directories changed while it read them reads them again.


def test_a_report_that_read_a_study_while_it_was_replaced_reads_it_again(tmp_path, monkeypatch):
    import sim.report.markdown as md
    from sim.cli import main

    plate = str(Path(__file__).resolve().parents[1] / "studies" / "network_plate.toml")
    small = ["--trials", "40", "--chunk", "2", "--no-figures", "--quiet"]
    res, new = tmp_path / "R", tmp_path / "new"
    assert main(["run", plate, *small, "--seed", "7", "--out", str(res / "network_plate")]) == 0
    assert main(["run", plate, *small, "--seed", "8", "--out", str(new / "network_plate")]) == 0
    real, swapped = md._entry, []

    def entry(d, get_study):
        got = real(d, get_study)
        if not swapped:  # the other terminal's run publishes right after the report read it
            os.rename(res / "network_plate", tmp_path / "old")
            os.rename(new / "network_plate", res / "network_plate")
            swapped.append(d)
        return got

    monkeypatch.setattr(md, "_entry", entry)
    assert main(["report", "--results", str(res)]) == 0
    monkeypatch.undo()
    assert swapped
    text = (res / "REPORT.md").read_text(encoding="utf-8")
    assert main(["report", "--results", str(res)]) == 0  # the report of what is there now
    assert text == (res / "REPORT.md").read_text(encoding="utf-8")
