"""The classes of the sweep doors24a (issue 26: the suite on a machine shared by several
people: a clone read-only to its user, results directories of other users, group-shared
folders, sticky ``/tmp``-like folders), one case each; each failed on the code before its fix.
The harness that found them (a private mount namespace, a read-only bind of the clone, the
commands run as other users by ``setpriv``) lives outside the project. The tests simulate
the other user (a descriptor that may not write, another effective uid), so that they run
without privileges:

* a read-only clone (another user's checkout) with no writable ``HOME`` nor cache directory:
  every study with a compiled kernel ended in exit 3, "RuntimeError: cannot cache function
  '_start': no locator available for file ..." (numba's disk cache had nowhere to go); the
  kernel is now compiled uncached (:func:`sim.lsq.compile.compiled`);
* a run's lock file was made with mode 0644 whatever the umask: in a group's setgid folder
  (``umask 002``) a member could not resume another member's interrupted run ("cannot write
  to <folder>: Permission denied"); its mode is now the umask's (:class:`sim.mc.storage.StageLock`);
* the staging directory of another user's run, live or interrupted, was "cannot write to
  <the parent>: Permission denied": the wrong directory, and no word of the live process; now
  the running sim is named (its pid and user), or the unfinished run and its owner
  (:func:`sim.mc.outputs._not_lockable`);
* re-running another user's results in a sticky folder (``/tmp``, a shared results folder)
  computed every chunk, then ended "Operation not permitted: OUT" and left a staging directory
  of its own beside them; now refused before any work (:func:`sim.mc.outputs.check_out`);
* a file the suite could not write (a read-only results directory, another user's) was named
  by its temporary, ``.README.md.9762.tmp``, a name the user never saw; now by the file
  (:class:`sim.mc.storage.atomic_path`).
"""

from __future__ import annotations

import errno
import logging
import os
import subprocess
import sys
from pathlib import Path

import pytest
from oneline import SIM_ERROR, one_line

from sim.cli import main
from sim.mc.storage import LOCK, StageLock, atomic_path

ROOT = Path(__file__).resolve().parent.parent
PLATE = str(ROOT / "studies" / "network_plate.toml")
SMALL = ["--trials", "40", "--chunk", "2", "--no-figures", "--quiet"]


def _kernel_of_this_test(a, b):  # compiled by the test below, a kernel of its own
    return a * b + 1.0


def test_a_kernel_compiles_where_numba_has_nowhere_to_cache(monkeypatch):
    """A read-only clone (a tree of another user's, ``chmod -R a-w``, a read-only bind) with
    ``HOME`` unwritable: numba finds no locator for its disk cache and raised at compile
    time; brown_table1 ended "internal error ... cannot cache function"."""
    pytest.importorskip("numba")
    from numba.core import caching

    from sim.lsq import compile as compiling

    monkeypatch.delenv("SIM_NO_JIT", raising=False)
    monkeypatch.setattr(caching.CacheImpl, "_locator_classes", [])  # nowhere to cache
    monkeypatch.setattr(compiling, "_kernels", {})
    monkeypatch.setattr(compiling, "_callers", {})
    kernel = compiling.compiled(_kernel_of_this_test)
    assert kernel(3.0, 4.0) == 13.0


def test_a_group_member_may_resume_a_run_in_a_group_folder(tmp_path):
    """``umask 002`` in a setgid group folder: every file of a run was group-writable but its
    lock file (mode 0644 given explicitly), so another member's same command could not take
    the lock of the interrupted run to resume it."""
    old = os.umask(0o002)
    try:
        lock = StageLock(tmp_path / ".out.partial").acquire()
    finally:
        os.umask(old)
    try:
        assert (tmp_path / ".out.partial" / LOCK).stat().st_mode & 0o777 == 0o664
    finally:
        lock.release()


def _not_ours(monkeypatch, lock: Path) -> None:
    """The lock file ``lock`` as another user's: opening it to write is refused (EACCES)."""
    real = os.open

    def fake(path, flags, *args, **kwargs):
        if str(path) == str(lock) and flags & (os.O_RDWR | os.O_WRONLY):
            raise PermissionError(errno.EACCES, "Permission denied", str(path))
        return real(path, flags, *args, **kwargs)

    monkeypatch.setattr(os, "open", fake)


def test_another_users_live_run_into_the_same_out_is_named(tmp_path, monkeypatch, capsys):
    """Two users, one ``--out``: the second was told "cannot write to <parent>: Permission
    denied", as if the folder were the problem, not the first user's run still writing."""
    stage = tmp_path / ".o.partial"
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys; from sim.mc.storage import StageLock; "
            f"StageLock({str(stage)!r}).acquire(); print('ready', flush=True); sys.stdin.read()",
        ],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout.readline() == "ready\n"
        _not_ours(monkeypatch, stage / LOCK)
        rc = main(["run", PLATE, *SMALL, "--out", str(tmp_path / "o")])
    finally:
        holder.stdin.close()
        holder.wait(timeout=60)
    one_line(
        capsys, rc, f"is being written by a running sim (pid {holder.pid} of user", prefix=SIM_ERROR
    )
    assert not (tmp_path / "o").exists()


def test_another_users_unfinished_run_is_named_with_its_owner(tmp_path, monkeypatch, capsys):
    """An interrupted run of another user's (its staging directory and lock not ours to
    write) was "cannot write to <parent>: Permission denied", naming neither."""
    stage = tmp_path / ".o.partial"
    StageLock(stage).acquire().release()
    _not_ours(monkeypatch, stage / LOCK)
    monkeypatch.setattr(os, "geteuid", lambda: os.getuid() + 4242)  # and owned by another
    rc = main(["run", PLATE, *SMALL, "--out", str(tmp_path / "o")])
    one_line(
        capsys,
        rc,
        f"{stage} holds an unfinished run of another user (",
        "choose another --out",
        prefix=SIM_ERROR,
    )
    assert sorted(p.name for p in stage.iterdir()) == [LOCK]


def test_another_users_results_in_a_sticky_folder_are_refused_before_the_run(
    tmp_path, monkeypatch, capsys
):
    """``--overwrite`` of results another user made in a sticky folder (``/tmp``): every chunk
    was computed, then the rename failed ("Operation not permitted: OUT") and a staging
    directory of this user's was left beside them."""
    shared = tmp_path / "shared"
    shared.mkdir()
    out = shared / "o"
    assert main(["run", PLATE, *SMALL, "--out", str(out)]) == 0
    shared.chmod(0o1777)
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*")}
    capsys.readouterr()
    monkeypatch.setattr(os, "geteuid", lambda: os.getuid() + 4242)  # another user
    rc = main(["run", PLATE, *SMALL, "--set", "seed=5", "--overwrite", "--out", str(out)])
    one_line(capsys, rc, f"{out} cannot be replaced by this run", "sticky bit", prefix=SIM_ERROR)
    assert sorted(p.name for p in shared.iterdir()) == ["o"]
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*")} == before


def test_a_file_that_cannot_be_written_is_named_not_its_temporary(tmp_path):
    """``sim report`` in a results directory of another user's: "Permission denied:
    results/agnard_block/.README.md.9762.tmp"."""
    target = tmp_path / "README.md"
    with pytest.raises(PermissionError) as caught:
        with atomic_path(target) as tmp:
            raise PermissionError(errno.EACCES, "Permission denied", str(tmp))
    assert caught.value.filename == str(target)
    assert list(tmp_path.iterdir()) == []


def _unreadable(monkeypatch, module, name: str, d: Path) -> None:
    """``module.name`` (a reader of the directory ``d``) as on another user's directory of
    mode 0700: Permission denied (root reads every directory, so the test says it)."""

    def refuse(*args, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied", str(d))

    monkeypatch.setattr(module, name, refuse)


def test_another_users_unreadable_results_are_one_line_in_the_cli_and_the_api(
    tmp_path, monkeypatch, capsys
):
    """``--out`` of another user's results made under ``umask 077``: ``sim run`` said
    "Permission denied: OUT" and the Python API raised PermissionError from the output check
    (every refusal of ``run()`` is a ConfigError naming ``out``)."""
    import sim
    from sim.mc import outputs

    out = tmp_path / "theirs"
    out.mkdir()
    (out / "run.json").write_text("{}")
    _unreadable(monkeypatch, outputs, "read_record", out)
    rc = main(["run", PLATE, *SMALL, "--overwrite", "--out", str(out)])
    one_line(capsys, rc, f"--out: {out} cannot be read (Permission denied", prefix=SIM_ERROR)
    handle = sim.load(PLATE, trials=40, chunk=2)
    with pytest.raises(sim.ConfigError, match="out: .* cannot be read"):
        handle.run(out=out, overwrite=True, quiet=True, figures=False)


def test_verify_with_a_scratch_directory_of_another_user_is_one_line(tmp_path, monkeypatch, capsys):
    """``make verify VERIFY_FLAGS="--scratch DIR"`` where ``DIR/<study>`` is another user's
    (mode 0700): a traceback ending "PermissionError: [Errno 13] Permission denied"."""
    from sim.report.verify import cli, rerun

    _unreadable(monkeypatch, rerun, "_target", tmp_path / "network_plate")
    argv = ["--results", str(ROOT / "results"), "--study", "network_plate"]
    rc = cli.main([*argv, "--trials", "400", "--scratch", str(tmp_path)])
    one_line(
        capsys, rc, f"Permission denied: {tmp_path / 'network_plate'}", prefix="sim verify: error: "
    )


def _kernel_of_the_full_disk_test(a, b):  # a kernel of its own (compiled once per key)
    return a - b


def test_a_kernel_runs_when_numba_cannot_write_its_cache(monkeypatch):
    """A read-only clone with ``HOME`` on a full disk: numba's cache index could not be
    written and brown_table1 ended "sim: error: No space left on device", naming nothing."""
    pytest.importorskip("numba")
    from numba.core import caching

    from sim.lsq import compile as compiling

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.delenv("SIM_NO_JIT", raising=False)
    monkeypatch.setattr(caching.Cache, "save_overload", full)
    monkeypatch.setattr(compiling, "_kernels", {})
    monkeypatch.setattr(compiling, "_callers", {})
    assert compiling.compiled(_kernel_of_the_full_disk_test)(5.0, 2.0) == 3.0


def test_a_full_home_is_not_reported_by_the_sim_command():
    """``HOME`` on a full disk: ``sim run`` printed matplotlib's "Could not save font_manager
    cache [Errno 28] No space left on device" (from its font_manager logger, which the
    filter on the "matplotlib" logger does not see) before its results, exit 0."""
    import sim.__main__  # noqa: F401 - the sim command's filters

    log = logging.getLogger("matplotlib.font_manager")
    rec = log.makeRecord(
        log.name,
        logging.WARNING,
        __file__,
        1,
        "Could not save font_manager cache %s",
        (OSError(28, "No space left on device"),),
        None,
    )
    assert not log.filter(rec)
    other = log.makeRecord(log.name, logging.WARNING, __file__, 1, "findfont: %s", ("x",), None)
    assert log.filter(other)


def test_a_study_file_that_may_not_be_read_is_one_line_in_the_api(tmp_path, monkeypatch):
    """A colleague's study file of mode 0600: ``sim.load`` raised PermissionError from
    pathlib (every refusal of ``load()`` is a ConfigError naming the file)."""
    import sim

    mine = tmp_path / "mine.toml"
    mine.write_bytes(Path(PLATE).read_bytes())
    real = Path.read_bytes

    def refuse(self):
        if self == mine:  # root reads every file: the test says it
            raise PermissionError(errno.EACCES, "Permission denied", str(self))
        return real(self)

    monkeypatch.setattr(Path, "read_bytes", refuse)
    with pytest.raises(sim.ConfigError, match=f"{mine} cannot be read \\(Permission"):
        sim.load(mine)
