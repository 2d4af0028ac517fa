"""Passing an interrupt on to child runs: what ``python -m sim.batch`` (its study runs) and
``make verify`` (its re-run) do when Ctrl-C, SIGTERM or SIGHUP reaches them.

Ctrl-C reaches every process of the terminal's group; SIGTERM or SIGHUP only the driver. So the
driver ignores further signals (a second one must not orphan the children), sends SIGTERM to
each live child (a ``sim run`` then cleans up as after Ctrl-C: its staging directory is kept
resumable, its workers end) and waits for each, killing one still alive after
:data:`GRACE_S` seconds.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Callable, Iterable

__all__ = [
    "STOP_SIGNALS",
    "GRACE_S",
    "stop_children",
    "child_text",
    "child_env",
    "die_with_parent",
    "ended",
]

#: the signals that end a driver (and each of its runs) as Ctrl-C does
STOP_SIGNALS = (signal.SIGTERM, signal.SIGHUP)

#: seconds an interrupted child run has to clean up before it is killed
GRACE_S = 30


#: the environment variable by which a driver asks its child runs to end with it
PARENT_ENV = "SIM_STOP_WITH_PARENT"


def child_env() -> dict:
    """The environment of a child run: the driver's, plus its pid in :data:`PARENT_ENV`, so
    that the child ends as after SIGTERM when the driver dies, even by ``kill -9`` (then
    nobody would stop it: it ran on and held its output's lock, and the same command run
    again was refused until it ended). Start the child from a thread that lives as long as
    the child runs (Linux signals the child when the thread that started it ends)."""
    return {**os.environ, PARENT_ENV: str(os.getpid())}


def die_with_parent() -> str | None:
    """In a child run started with :func:`child_env`: be sent SIGTERM when the driver dies
    (PR_SET_PDEATHSIG, Linux). None to go on; when the driver is gone already, why the child
    ends at once (one line: the variable left set in a shell, ``export
    SIM_STOP_WITH_PARENT=2``, ended every ``sim`` with status 130 and not a word)."""
    want = os.environ.pop(PARENT_ENV, "")
    # (ASCII digits: "²" is a digit to str.isdigit and a ValueError traceback to int)
    if not (want.isascii() and want.isdigit()) or not sys.platform.startswith("linux"):
        return None
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG = 1
    except (OSError, AttributeError):
        return None
    # (compared as text: int() of over 4,300 digits is a ValueError traceback)
    if want.lstrip("0") == str(os.getppid()):
        return None
    said = want if len(want) <= 20 else f"{want[:20]}... ({len(want):,} digits)"
    return (
        f"stopped: {PARENT_ENV}={said} names the program that started this run, and it has "
        "ended (a driver's variable, left set in your shell? unset it)"
    )


def ended(code: int) -> str:
    """How a child process ended, from its return code, for a message: "exited with 1", or
    "was killed by SIGKILL" (a negative code is the signal that ended it, as ``kill -9`` or
    the OOM killer's: it read "exited with -9")."""
    if code >= 0:
        return f"exited with {code}"
    try:
        return f"was killed by {signal.Signals(-code).name}"
    except ValueError:  # a real-time signal has no name
        return f"was killed by signal {-code}"


def child_text() -> dict:
    """How a driver reads the text a child run prints: in the encoding of the driver's own
    standard error, which the child (same environment, same locale) writes too. Python's
    default, the locale's encoding, is another one under ``PYTHONIOENCODING`` (``utf-16``:
    every character came out with NULs between), and a byte that is not text is replaced,
    not a traceback in a reader thread."""
    return {"encoding": getattr(sys.stderr, "encoding", None) or "utf-8", "errors": "replace"}


def stop_children(
    procs: Iterable[subprocess.Popen],
    drain: bool = False,
    first: Callable[[], None] | None = None,
    grace: float | None = None,
) -> None:
    """Ignore SIGINT, SIGTERM and SIGHUP from now on, call ``first`` (e.g. a flag that starts
    no more children), SIGTERM every live child of ``procs`` and wait for it (killed after
    ``grace`` seconds, default :data:`GRACE_S`). ``drain``: the caller reads no pipe of the
    children any more, so their pipes are read here (``communicate``) lest a child block on a
    full pipe; without it, reader threads of the caller do that and a wait suffices."""
    for s in (signal.SIGINT, *STOP_SIGNALS):
        signal.signal(s, signal.SIG_IGN)
    if first is not None:
        first()
    procs = list(procs)
    for proc in procs:
        if proc.poll() is None:
            proc.terminate()
    grace = GRACE_S if grace is None else grace
    for proc in procs:
        try:
            proc.communicate(timeout=grace) if drain else proc.wait(timeout=grace)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate() if drain else proc.wait()
