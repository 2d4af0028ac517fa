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
import sys
import time
from pathlib import Path

import pytest
from oneline import one_line_of

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


# * ``--out`` naming a mount point (an empty file system mounted for the results, a bind
#   mount): accepted, every chunk computed, then "Device or resource busy" when the run
#   replaced it, its staging directory left on the file system above. Refused at once now.
# * ``--out lnk/x`` with ``lnk`` a symbolic link into another run's ``trials/`` (or its
#   results directory), or a relative ``--out`` from a shell inside them (``cd lnk``): the
#   check that an output lies in no other run's directory read the path's names only, so the
#   run wrote its results into that dataset, which then failed its own check ("not one of
#   the run's chunk files"). The directories the system reaches through the links are
#   checked too.


def _unshare_works() -> bool:
    if shutil.which("unshare") is None:
        return False
    p = subprocess.run(["unshare", "-Urm", "true"], capture_output=True)
    return p.returncode == 0


#: a small run of brown_table1, as a shell command (the mount-namespace cases append --out)
_RUN = (
    f"{sys.executable} -m sim run {ROOT / 'studies' / 'brown_table1.toml'} "
    "--trials 40 --no-figures --quiet"
)


def _unshared(script: str, *args, timeout: float = 600) -> subprocess.CompletedProcess:
    """``sh -c script sh args...`` as root of a user and mount namespace of its own (its
    mounts vanish with it), from the project's root."""
    return subprocess.run(
        ["unshare", "-Urm", "sh", "-c", script, "sh", *map(str, args)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


@pytest.mark.skipif(not _unshare_works(), reason="needs unshare -Urm (a mount namespace)")
@pytest.mark.parametrize("how", ["tmpfs", "bind"])
def test_out_naming_a_mount_point_is_refused_before_the_run(tmp_path, how):
    mp = tmp_path / "mnt"
    mp.mkdir()
    (tmp_path / "src").mkdir()
    mount = "mount -t tmpfs tmpfs" if how == "tmpfs" else f"mount --bind {tmp_path / 'src'}"
    p = _unshared(f'{mount} "$1" && exec {_RUN} --out "$1"', mp)
    one_line_of(p, "is a mount point", prefix="sim: error: --out:")
    assert not (tmp_path / ".mnt.partial").exists()  # refused before any work


def test_out_through_a_link_into_another_runs_trials_is_refused(tmp_path, capsys, monkeypatch):
    from sim.cli import main
    from tests.oneline import one_line

    run = tmp_path / "run"
    (run / "trials" / "part-0").mkdir(parents=True)
    (run / "run.json").write_text("{}", encoding="utf-8")
    (tmp_path / "lnk").symlink_to(run / "trials" / "part-0")
    study = str(ROOT / "studies" / "brown_table1.toml")
    argv = ["run", study, "--trials", "40", "--no-figures", "--quiet", "--out"]
    for out in (tmp_path / "lnk" / "x",):
        one_line(capsys, main([*argv, str(out)]), "--out", "lies inside", str(run))
    monkeypatch.chdir(tmp_path / "lnk")  # a shell in the link: cd lnk; sim run ... --out x
    one_line(capsys, main([*argv, "x"]), "--out", "lies inside", str(run / "trials"))
    assert sorted(p.name for p in (run / "trials" / "part-0").iterdir()) == []


# * ``--out lnk/../y`` (a ``..`` after a symbolic link, as ``ls`` and every other program read
#   it: the parent of the link's target) was made absolute by its letters (``./y``): the run
#   wrote ``./y``, said "results in lnk/../y" (where ``ls`` then found nothing), and with
#   ``--overwrite`` replaced a ``./y`` the user had not named. ``sim run`` and the Python API
#   now resolve such a path as the system does.


@pytest.mark.parametrize("door", ["cli", "api"])
def test_out_with_dotdot_after_a_link_is_where_the_system_says(tmp_path, capsys, door):
    import sim
    from sim.cli import main
    from tests.oneline import one_line

    (tmp_path / "far" / "sub").mkdir(parents=True)
    (tmp_path / "lnk").symlink_to(tmp_path / "far" / "sub")
    (tmp_path / "far" / "y").write_text("the user's file", encoding="utf-8")  # lnk/../y
    study = ROOT / "studies" / "brown_table1.toml"
    out = str(tmp_path / "lnk" / ".." / "y")
    if door == "cli":
        rc = main(["run", str(study), "--trials", "40", "--no-figures", "--quiet", "--out", out])
        one_line(capsys, rc, "--out", "is a file, not a results directory")
    else:
        with pytest.raises(sim.ConfigError, match="is a file, not a results directory"):
            sim.load(study, trials=40).run(out=out, figures=False)
    assert not (tmp_path / "y").exists()  # nothing written where lnk/.. reads by its letters
    assert (tmp_path / "far" / "y").read_text(encoding="utf-8") == "the user's file"


# * A file system mounted inside an earlier results directory (a disk or a tmpfs in
#   ``results/x/data``): the run copied its files into the new results, moved the mount aside
#   with the old results and emptied it while removing them (the user's files deleted from
#   their own file system, the mount left under a hidden ``.x.old.<pid>``). Refused at once.


@pytest.mark.skipif(not _unshare_works(), reason="needs unshare -Urm (a mount namespace)")
def test_out_holding_a_mount_point_is_refused_before_the_run(tmp_path):
    out = tmp_path / "res"
    (out / "data").mkdir(parents=True)
    record = '{"config": {"study": "brown_table1"}, "code_hash": "0", "files": ["t.txt"]}'
    (out / "run.json").write_text(record, encoding="utf-8")  # an earlier run's results
    script = f'mount -t tmpfs tmpfs "$1/data" && echo mine > "$1/data/f" && exec {_RUN} --overwrite'
    p = _unshared(f'{script} --out "$1"', out)
    one_line_of(p, f"holds a mount point, {out / 'data'}", prefix="sim: error: --out:")
    assert not (tmp_path / ".res.partial").exists()  # refused before any work


# * A results directory of an overlay's lower layer (the project baked into a container's
#   image, ``make reproduce`` run in the container): the kernel renames no such directory
#   ("Invalid cross-device link", EXDEV, for the swap and for the two renames), so the run
#   computed every chunk and failed at its end, and again at each try. It is now removed
#   (what the user put there copied into the new results first) and the new results renamed
#   in its place.

_OVERLAY_PUBLISH = """
import sys
from pathlib import Path
from sim.mc.outputs import stage_dir
from sim.mc.publish import publish
from sim.mc.storage import read_record, write_record
out = Path(sys.argv[1]) / "X"
stage = stage_dir(out)
stage.mkdir()
write_record(stage, {"config": {"study": "x"}, "code_hash": "h", "files": ["t.txt"]})
(stage / "t.txt").write_text("new", encoding="utf-8")
publish(stage, out)
print((out / "t.txt").read_text(), (out / "notes.md").read_text(), read_record(out)["files"])
print(sorted(p.name for p in out.parent.iterdir()))
"""


@pytest.mark.skipif(not _unshare_works(), reason="needs unshare -Urm (a mount namespace)")
def test_results_of_an_overlays_lower_layer_are_replaced(tmp_path):
    lower, upper, work, merged = (tmp_path / n for n in ("lower", "upper", "work", "merged"))
    for d in (upper, work, merged):
        d.mkdir()
    (lower / "X" / "trials").mkdir(parents=True)  # the image's results, with a note of the user
    record = '{"config": {"study": "x"}, "code_hash": "g", "files": ["t.txt"]}'
    (lower / "X" / "run.json").write_text(record, encoding="utf-8")
    (lower / "X" / "t.txt").write_text("old", encoding="utf-8")
    (lower / "X" / "notes.md").write_text("mine", encoding="utf-8")
    opts = f"lowerdir={lower},upperdir={upper},workdir={work},userxattr"
    script = f'mount -t overlay overlay -o {opts} "$1" || exit 99; exec "$2" -c "$3" "$1"'
    p = _unshared(script, merged, sys.executable, _OVERLAY_PUBLISH, timeout=120)
    if p.returncode == 99:
        pytest.skip(f"no overlay mount here: {p.stderr.strip()}")
    assert p.returncode == 0, p.stderr
    assert p.stdout.splitlines() == ["new mine ['t.txt']", "['X']"], p.stdout


# * ``sim report`` over results on a read-only file system (a read-only mount of a clone or
#   of a colleague's results) ended "Read-only file system: .../.README.md.<pid>.tmp", a
#   name the user never saw: removing the temporary that was never made fails with EROFS
#   there, and that error replaced the one naming README.md.

_READ_ONLY_WRITE = """
import sys
from pathlib import Path
from sim.mc.storage import atomic_path
ro = Path(sys.argv[1])
try:
    with atomic_path(ro / "README.md") as tmp:
        tmp.write_text("x", encoding="utf-8")
except OSError as e:
    print(e.errno, e.filename)
"""


@pytest.mark.skipif(not _unshare_works(), reason="needs unshare -Urm (a mount namespace)")
def test_a_write_on_a_read_only_file_system_names_the_file(tmp_path):
    import errno

    ro = tmp_path / "ro"
    ro.mkdir()
    script = 'mount -t tmpfs -o ro tmpfs "$1" || exit 99; exec "$2" -c "$3" "$1"'
    p = _unshared(script, ro, sys.executable, _READ_ONLY_WRITE, timeout=120)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == f"{errno.EROFS} {ro / 'README.md'}", p.stdout


# * A folder of the user's named ``trials`` (``~/trials/run1``, or a home reached through a
#   link to ``/data/trials/u``, now that the links are followed) was taken for another run's
#   chunk store, and every ``--out`` inside it refused. A run's ``trials/`` holds its
#   ``part-<p>/`` folders; that is what is refused.


def test_a_folder_of_the_users_named_trials_is_not_a_runs_dataset(tmp_path):
    from sim.mc.config import ConfigError
    from sim.mc.outputs import check_out

    record = {"config": {"study": "brown_table1"}, "code_hash": "0"}
    (tmp_path / "trials").mkdir()
    check_out(tmp_path / "trials" / "run1", "run1", record, False)  # no error: the user's
    (tmp_path / "trials" / "part-0").mkdir()  # a run's chunk store (its run.json gone)
    with pytest.raises(ConfigError, match="lies inside"):
        check_out(tmp_path / "trials" / "run1", "run1", record, False)


# * A results folder on a file system that cannot lock files (an NFS mount whose lock service
#   is down: flock fails with ENOLCK) was "cannot write to <folder>: No locks available"
#   (the folder can be written), and left an empty staging directory there. It now says the
#   folder cannot hold a lock, and leaves nothing.


def test_a_file_system_that_cannot_lock_is_named_and_left_clean(tmp_path, capsys, monkeypatch):
    import errno
    import fcntl
    import types

    import sim.mc.storage as storage
    from sim.cli import main
    from tests.oneline import one_line

    def flock(fd, op):
        raise OSError(errno.ENOLCK, os.strerror(errno.ENOLCK))

    fake = types.SimpleNamespace(flock=flock, LOCK_EX=fcntl.LOCK_EX, LOCK_NB=fcntl.LOCK_NB)
    monkeypatch.setattr(storage, "fcntl", fake)
    study = str(ROOT / "studies" / "brown_table1.toml")
    out = tmp_path / "o"
    rc = main(["run", study, "--trials", "40", "--no-figures", "--quiet", "--out", str(out)])
    one_line(capsys, rc, f"cannot lock a file in {tmp_path}", os.strerror(errno.ENOLCK))
    assert sorted(tmp_path.iterdir()) == []  # no staging directory left


# * ``--out DIR/`` (a shell completes a directory with its slash) ended "results in DIR//".


def test_out_with_a_trailing_slash_is_named_once_slashed(tmp_path, capsys):
    from sim.cli import main

    study = str(ROOT / "studies" / "brown_table1.toml")
    out = f"{tmp_path / 'o'}//"
    assert main(["run", study, "--trials", "40", "--no-figures", "--quiet", "--out", out]) == 0
    assert capsys.readouterr().out == f"brown_table1: results in {tmp_path / 'o'}/\n"
    assert (tmp_path / "o" / "run.json").is_file()


# * ``make verify`` with its scratch directory on a file system that is full (or a write cut
#   short by ``ulimit -f``): the re-run's "No space left on device" was recorded as a failed
#   reproduction ("brown_table1: FAILED; nothing compared", exit 1, and a FAILED row in
#   reproducibility.parquet without --no-record); with --trials it was "the re-run refused
#   its options". Now one line naming the system's error, exit 2.


@pytest.mark.parametrize("extra", [[], ["--trials", "400"]])
def test_verify_whose_rerun_cannot_write_is_not_a_failed_reproduction(tmp_path, extra):
    import resource

    def small_files():  # (in the verify process and the re-run it starts)
        resource.setrlimit(resource.RLIMIT_FSIZE, (1024, resource.RLIM_INFINITY))

    cmd = [sys.executable, "-m", "sim.report.verify", "--results", str(ROOT / "results")]
    cmd += ["--studies", str(ROOT / "studies"), "--study", "brown_table1", "--no-record"]
    cmd += ["--scratch", str(tmp_path / "scr"), *extra]
    p = subprocess.run(
        cmd,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
        preexec_fn=small_files,
    )
    lines = [ln for ln in p.stderr.splitlines() if not ln.startswith("sim verify: re-running")]
    assert p.returncode == 2 and len(lines) == 1, p.stderr
    assert lines[0].startswith("sim verify: error: brown_table1: the re-run could not run here:")
    assert "File too large" in lines[0], lines[0]
