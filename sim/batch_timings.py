"""The ``--timings`` file of ``python -m sim.batch``, held by one batch at a time.

Two batches given the same ``--timings`` each wrote their own timings at their end: the last
write won without a word, and the other batch's studies were gone from the file. The second
batch is now refused before anything runs, in one line naming the other's pid. The lock is an
``flock`` on ``.<name>.lock`` next to the file (the kernel drops it when the process dies,
even on ``kill -9``), which holds the holder's pid and is removed at the end; a file of that
name holding anything but a pid is the user's, and is refused rather than written."""

from __future__ import annotations

import errno
import fcntl
import os
import re
import stat
from pathlib import Path

__all__ = ["TimingsLock"]

#: what a lock file of this module holds: a pid (or nothing, when its holder just made it)
_PID = re.compile(rb"\d{0,20}\n?")


class TimingsLock:
    """An exclusive lock on a ``--timings`` file for the life of a batch."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.lock = self.path.parent / f".{self.path.name}.lock"
        self.fd: int | None = None

    def acquire(self) -> str | None:
        """Take the lock: None, or why it cannot be taken (one line)."""
        for _ in range(3):  # the holder removed the file between our open and flock: again
            why = self._try()
            if why != "again":
                return why
        return f"{self.lock} keeps being replaced; another sim.batch writes {self.path}"

    def _try(self) -> str | None:
        flags = os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK
        try:
            fd = os.open(self.lock, flags, 0o666)
        except OSError as e:
            if e.errno in (errno.ELOOP, errno.EISDIR, errno.ENXIO):
                return f"{self.lock} is not a lock file of sim.batch; move it away"
            return f"cannot write {self.lock}: {e.strerror or e}"
        try:
            st = os.fstat(fd)
            held = os.read(fd, 64) if stat.S_ISREG(st.st_mode) else b"x"
            if st.st_nlink > 1 or not _PID.fullmatch(held):
                return f"{self.lock} is not a lock file of sim.batch; move it away"
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                who = f"pid {int(held)}" if held.strip() else "a process"
                return (
                    f"another sim.batch ({who}) writes {self.path}; wait for it to finish or "
                    "name another file"
                )
            try:
                same = os.stat(self.lock, follow_symlinks=False).st_ino == st.st_ino
            except OSError:
                same = False
            if not same:
                return "again"
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
            self.fd, fd = fd, -1
            return None
        except OSError as e:  # ENOLCK (NFS without its lock service), a full disk
            return f"cannot lock {self.lock}: {e.strerror or e}"
        finally:
            if fd >= 0:
                os.close(fd)

    def release(self) -> None:
        """Remove the lock file, when it is still the one this lock holds, and drop the lock.
        (A lock file removed by hand while a batch ran, another batch took a new one: the
        first, ending, removed the second's, and a third ran beside the second.)"""
        if self.fd is None:
            return
        try:
            ours = os.fstat(self.fd)
            there = os.stat(self.lock, follow_symlinks=False)
            if (there.st_dev, there.st_ino) == (ours.st_dev, ours.st_ino):
                self.lock.unlink()
        except OSError:  # gone, or a directory made read-only meanwhile: nothing to remove
            pass
        os.close(self.fd)
        self.fd = None
