"""The temporary scratch directory of ``make verify`` without ``--scratch``:
``$TMPDIR/sim-verify-<pid>-XXXXXXXX/``, holding the marker :data:`MARK` (its pid).

Verify removes it when it ends, however it ends but one: killed outright (``kill -9``, the
out-of-memory killer) it runs no cleanup, and the directory, with the re-runs' results (tens
of megabytes), stayed in ``$TMPDIR`` for good, under a name no one was told. A later verify
(:func:`scratch_dir`) removes such a directory when it can prove it is one of those: a
directory (not a link) of this user, named by this pattern, holding the marker whose text is
the pid of its name, whose process is gone (``os.kill(pid, 0)``: no such process; a live one,
this process, or another user's is never touched) and whose ``.lock`` files no one holds (a
re-run of it still ending). A directory of another name (an older verify's
``sim-verify-XXXXXXXX``, the user's) or without the marker is never removed.
"""

from __future__ import annotations

import os
import re
import shutil
import stat
import tempfile
from pathlib import Path

from sim.mc.dead_dirs import lock_held
from sim.mc.pids import pid_alive

__all__ = ["MARK", "scratch_dir"]

#: the marker of a verify's temporary scratch directory: its text is the verify's pid
MARK = ".sim-verify"
_NAME = re.compile(r"sim-verify-(\d+)-[a-z0-9_]{8}")


def _left_by_a_dead_verify(d: Path, pid: int) -> bool:
    """Whether ``d`` is the temporary scratch directory of a verify ``pid`` that is gone."""
    if pid == os.getpid() or pid_alive(pid):
        return False
    st = os.lstat(d)
    if not stat.S_ISDIR(st.st_mode) or st.st_uid != os.getuid():
        return False
    mark = d / MARK
    if not mark.is_file() or mark.is_symlink() or mark.read_text(encoding="ascii") != str(pid):
        return False
    return not lock_held(d)


def clear_dead(tmp: Path) -> list[Path]:
    """Remove the temporary scratch directories that killed verifies left in ``tmp`` (see the
    module doc); anything unsure is left. Returns those removed."""
    try:
        names = os.listdir(tmp)
    except OSError:
        return []
    gone = []
    for n in names:
        m = _NAME.fullmatch(n)
        try:
            if m and _left_by_a_dead_verify(tmp / n, int(m[1])):
                shutil.rmtree(tmp / n)
                gone.append(tmp / n)
        except (OSError, ValueError):  # removed meanwhile, unreadable, not ASCII: left
            continue
    return gone


def scratch_dir() -> str:
    """A new temporary scratch directory of this verify, marked, after those of killed
    verifies are cleared (:func:`clear_dead`)."""
    tmp = Path(tempfile.gettempdir())
    clear_dead(tmp)
    d = tempfile.mkdtemp(prefix=f"sim-verify-{os.getpid()}-")
    try:
        (Path(d) / MARK).write_text(str(os.getpid()), encoding="ascii")
    except BaseException:  # a full disk, Ctrl-C: not left behind unmarked
        shutil.rmtree(d, ignore_errors=True)
        raise
    return d
