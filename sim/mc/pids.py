"""Whether a process is alive: the one test behind every "left by a process that is gone"
decision (a stale temporary ``.<name>.<pid>.tmp``, replaced results ``.<out>.old.<pid>``, a
killed ``run(out=None)``'s ``$TMPDIR/sim-<study>-<pid>-...``)."""

from __future__ import annotations

import os

__all__ = ["pid_alive", "writer_gone"]


def pid_alive(pid: int) -> bool:
    """Whether process ``pid`` exists (another user's process counts as alive; so does a pid
    no process can have, which is never one of ours to clear)."""
    if pid <= 0:
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (OSError, OverflowError):  # EPERM: someone else's; a pid beyond the C int
        return True
    return True


def writer_gone(pid: int) -> bool:
    """Whether what process ``pid`` left is its remains: no process ``pid``, or this process's
    own pid (a container's every command has the same)."""
    return pid == os.getpid() or not pid_alive(pid)
