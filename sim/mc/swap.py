"""The swap of a run's old results for its new ones: :func:`exchange` (one step where the
system can), and the lock of a run that publishes, ``<out>/.lock``, held from before the swap
until the run's record in ``<out>`` is final.

A run locks its staging directory ``.<out>.partial`` for its life (:class:`StageLock`); the
swap at its end frees that name while the run still works on ``<out>``: the old results were
moved to the staging directory's name (where a second run took them for its own unfinished
run, resumed them and published them, after which the first wrote its record over the
second's tables: a ``run.json`` of one config over the tables of another, exit 0 for both), and
the run's last record was written into ``<out>`` after a second run had published there. So
the publishing run locks ``<out>/.lock`` of the old results before the swap (it comes to the
staging directory's name with them) and keeps the lock of its staging directory, which is
``<out>/.lock`` after the swap, until its record is final; a run that finds ``<out>/.lock``
held is refused as one that finds the staging directory locked (:func:`refuse_if_publishing`).
A directory with no run record of its own that holds a running run's staging directory (a
run into a directory inside it) is refused naming that run (:func:`refuse_if_running_under`).
The kernel drops the locks of a killed run: a ``.lock`` file left behind blocks nothing.
"""

from __future__ import annotations

import ctypes
import errno
import fcntl
import os
import stat
from collections import deque
from pathlib import Path

from sim.mc.config import ConfigError
from sim.mc.storage import LOCK, RECORD, Locked, NotALock, StageLock

__all__ = [
    "holder",
    "hold_old",
    "refuse_if_publishing",
    "refuse_if_running_under",
    "busy_words",
    "exchange",
    "libc",
]


def holder(lock: Path) -> tuple[bool, int | None]:
    """Whether a process holds the lock ``lock`` (tested through a read-only descriptor: a
    shared lock, dropped at once; never through a link), and its pid."""
    try:
        fd = os.open(lock, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return False, None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return False, None
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            try:
                return True, int(os.read(fd, 32).decode().strip() or 0) or None
            except (OSError, ValueError):
                return True, None
        return False, None
    finally:
        os.close(fd)


def busy_words(shown: str, pid: int | None) -> str:
    """What a run refused because another one writes ``shown`` says."""
    who = f"pid {pid}" if pid else "another process"
    return (
        f"{shown} is being written by a running sim ({who}); wait for it to finish or choose "
        "another --out"
    )


def refuse_if_publishing(out: Path, shown: str) -> None:
    """Refuse ``out`` while another run publishes into it (its ``.lock`` held)."""
    held, pid = holder(out / LOCK)
    if held and pid != os.getpid():
        raise ConfigError("--out", busy_words(shown, pid))


#: the entries :func:`refuse_if_running_under` looks at, at most (a home directory of
#: millions of files was walked in full before its refusal: minutes; 10,000 take ~50 ms)
LOOK_AT = 10_000


def refuse_if_running_under(out: Path, shown: str) -> list[str]:
    """Refuse ``out`` (no run record of its own, not empty) while a run writes under it, a run
    into a directory inside it (its staging directory's ``.lock`` held): it was "holds files
    but no sim run record", naming no run, as that run went on. Looks at no more than
    :data:`LOOK_AT` entries, breadth first, and no link or mounted file system inside ``out`` (the
    refusal that follows holds without the rest: a run deeper than that is not named). Returns the names directly under ``out`` (the run record
    aside) of those looked at, sorted, for the refusal to name."""
    todo, seen, first = deque([out]), 0, []
    while todo and seen < LOOK_AT:
        top = todo.popleft()
        try:
            with os.scandir(top) as it:
                for e in it:
                    seen += 1
                    if top is out and e.name != RECORD:
                        first.append(e.name)
                    if e.name == LOCK and (held := holder(Path(e.path)))[0]:
                        where = Path(top).relative_to(out)
                        raise ConfigError(
                            "--out", busy_words(f"{shown} holds {where}, which", held[1])
                        )
                    if e.is_dir(follow_symlinks=False) and not os.path.ismount(e.path):
                        todo.append(Path(e.path))
                    if seen >= LOOK_AT:
                        break
        except OSError:
            continue
    return sorted(first)


def hold_old(out: Path, shown: str) -> StageLock | None:
    """Lock ``<out>/.lock`` of the results a publish replaces (None: no lock file can be made
    there, as before; a run holding it is refused)."""
    lock = StageLock(out)
    try:
        return lock.acquire()
    except Locked as e:
        raise ConfigError("--out", busy_words(shown, e.pid)) from None
    except (NotALock, OSError):
        return None


#: renameat2(2)'s flag that swaps two paths in one step (Linux 3.15, glibc 2.28)
_RENAME_EXCHANGE, _AT_FDCWD = 2, -100


def exchange(a: Path, b: Path) -> bool:
    """Swap the directories ``a`` and ``b`` in one step where the system can (False: it
    cannot, and nothing was done). Moving the old results aside and the new ones in by two
    renames left ``out`` absent for an instant, in which ``sim report`` or ``make verify`` in
    another terminal found no results of that study (and a README.md written into it then
    made an empty directory in its place, which the second rename could not replace)."""
    fn = getattr(libc(), "renameat2", None)
    if fn is None:
        return False
    fn.argtypes = (ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint)
    enc = [os.fsencode(str(p)) for p in (a, b)]
    if fn(_AT_FDCWD, enc[0], _AT_FDCWD, enc[1], _RENAME_EXCHANGE) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP, errno.EPERM, errno.EXDEV):
        return False  # an older kernel, a file system without it (a FUSE mount, NFS; EXDEV:
        # an overlay, whose directories of a lower layer cannot be renamed)
    raise OSError(err, os.strerror(err), str(b))


def libc():
    try:
        return ctypes.CDLL(None, use_errno=True)
    except OSError:
        return None
