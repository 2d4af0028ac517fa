"""The temporary directory of ``run(out=None)``: ``$TMPDIR/sim-<study>-<pid>-XXXXXXXX/``.

A run killed outright (SIGKILL, the out-of-memory killer) ran no cleanup: its directory, with
a staging directory whose path the caller was never told, stayed in ``$TMPDIR`` forever. The
process id in the name lets a later ``run(out=None)`` of the same study (:func:`temp_dir`)
remove such a directory when it can prove it is one of those: a directory (not a link) of
this user, named by this pattern, holding the marker :data:`MARK` whose text is the pid of
its name (a directory of the user's named so, ``sim-network-2026-november``, was removed with
what it held), whose process is gone (``os.kill(pid, 0)``: no such
process; a live one, this process, or another user's is never touched), whose ``.lock``
files no one holds, that holds no finished results (``<study>/run.json``: a run that
returned; its Results may still be read) and no chunks a failed run named in its exception
(:data:`KEPT`, written by :func:`sim.api_state.anonymous_dir`: ``run(out=...)`` resumes
them). Directories of other names (an older suite's, the user's) are never looked at.

A ``TMPDIR`` whose path the suite cannot record (a line break or another control character,
bytes that are not UTF-8) is refused before the run, naming it: the run computed every chunk,
then ``Results`` refused its own directory ("path: must be a path ..."). The other
variables of the environment a run reads are checked by :func:`check_env`.
"""

from __future__ import annotations

import os
import re
import shutil
import stat
import tempfile
from pathlib import Path

from sim.env_vars import environment_problem
from sim.mc.config import ConfigError
from sim.mc.dead_dirs import lock_held
from sim.mc.outputs import name_problem
from sim.mc.pids import pid_alive
from sim.mc.progress import check_environment as _check_tqdm
from sim.mc.storage import RECORD

__all__ = ["KEPT", "MARK", "check_env", "temp_dir"]

#: the marker of a temporary directory whose finished chunks a failed run named to the caller
KEPT = ".sim-kept"
#: the marker of a run's temporary directory: its text is the pid of the run that made it
MARK = ".sim-run"


def _alive(pid: int) -> bool:
    """False only when no process ``pid`` exists (this process, another user's: alive)."""
    return pid == os.getpid() or pid_alive(pid)


def _clear_dead(tmp: Path, study: str) -> None:
    """Remove the directories of killed runs of ``study`` in ``tmp`` (see the module doc);
    anything unsure is left."""
    name = re.compile(rf"sim-{re.escape(study)}-(\d+)-[a-z0-9_]{{8}}")
    try:
        names = os.listdir(tmp)
    except OSError:
        return
    for n in names:
        m = name.fullmatch(n)
        if not m or _alive(int(m[1])):
            continue
        d = tmp / n
        try:
            st = os.lstat(d)
            if not stat.S_ISDIR(st.st_mode) or st.st_uid != os.getuid() or not _marked(d, m[1]):
                continue
            if os.path.lexists(d / study / RECORD) or os.path.lexists(d / KEPT) or lock_held(d):
                continue
            shutil.rmtree(d)
        except OSError:  # removed meanwhile, unreadable: left as it is
            continue


def _marked(d: Path, pid: str) -> bool:
    """Whether ``d`` holds the marker a run writes (a regular file, its text ``pid``)."""
    mark, st = d / MARK, os.lstat(d / MARK)
    return stat.S_ISREG(st.st_mode) and st.st_size <= 20 and mark.read_bytes() == pid.encode()


def temp_dir(study: str) -> Path:
    """A new ``$TMPDIR/sim-<study>-<pid>-XXXXXXXX/`` for a run of ``study``, after the
    directories of killed runs of it are cleared; OSError when none can be made, ConfigError
    naming ``out`` when its path cannot be recorded (module docstring)."""
    tmp = Path(tempfile.gettempdir())
    if (why := name_problem(str(tmp))) is not None:
        raise ConfigError(
            "out",
            f"is None, and the temporary directory {str(tmp)!r} (TMPDIR) {why}: "
            "set TMPDIR, or name an output directory",
        )
    _clear_dead(tmp, study)
    d = Path(tempfile.mkdtemp(prefix=f"sim-{study}-{os.getpid()}-"))
    try:
        (d / MARK).write_text(str(os.getpid()), encoding="ascii")
    except BaseException:  # a full disk, Ctrl-C: not left behind unmarked
        shutil.rmtree(d, ignore_errors=True)
        raise
    return d


def check_env() -> None:
    """Raise :class:`ConfigError` naming a variable of the environment the suite, tqdm or numba
    cannot read (``TQDM_NCOLS=abc``, ``SIM_NO_JIT=0``, ``NUMBA_OPT=fast``), or a ``ulimit -v``
    or ``-d`` under what the suite needs (a run failed in its middle), as the commands
    refuse it when they start (:func:`sim.threads.refuse_bad_environment`): ``sim.load``
    refuses it, not the middle of a run."""
    _check_tqdm()
    if (problem := environment_problem()) is not None:  # ulimit -v/-d too, as they start
        raise ConfigError(None, problem)
