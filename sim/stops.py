"""Stop signals in the two places where Python would drop them or die of them.

**An interrupt Python cannot raise.** The commands turn Ctrl-C and SIGTERM into
``KeyboardInterrupt``; raised inside a C callback (numba's ``_raw_object_cache_notify``, any
``ctypes`` callback), an at-fork hook or a ``__del__``, Python cannot hand it to the caller: it
printed "Exception ignored in: ... KeyboardInterrupt", dropped it, and the run went on to exit 0.
While :func:`keep_lost_interrupts` is open (every command, and :func:`sim.execute.execute` for
every door), such an interrupt is recorded silently instead, and the next check point,
:func:`check_interrupt`, raises it: the chunk loop of the Monte-Carlo runner at each chunk, a
run before it publishes its results, a command before it returns its exit code.

**A signal after the command ended.** Once a command has returned its exit code, the program
still shuts Python down (atexit callbacks, then the teardown of NumPy, SciPy, numba and
pyarrow: a few tenths of a second), and Python resets its handlers to the defaults on the way:
Ctrl-C there killed ``sim run --workers 2`` by SIGINT (exit -2, no line) after it had printed
its results, or printed a traceback from an atexit callback. :func:`run_program` ends the
program with the command's own exit code then: the command's work is done and its output is
complete, so there is nothing left to stop or to resume (a run's results are published, its
line printed); a signal there ends the process at once with that code, and is ignored during
Python's last teardown (so it cannot turn a finished run into a death by signal).
"""

from __future__ import annotations

import atexit
import os
import signal
import sys
import threading
from contextlib import contextmanager

__all__ = [
    "keep_lost_interrupts",
    "check_interrupt",
    "run_program",
    "in_main_thread",
    "exit_status",
    "ended_as_ctrl_c",
]

#: interrupts recorded by the hook of :func:`keep_lost_interrupts`, not yet raised
_lost: list[str] = []
#: how many :func:`keep_lost_interrupts` are open (the outermost forgets a pending interrupt)
_open: list[int] = [0]


def _recording(previous):
    def hook(u) -> None:
        if isinstance(u.exc_type, type) and issubclass(u.exc_type, KeyboardInterrupt):
            _lost.append(str(u.err_msg or "an interrupt Python could not raise"))
            return  # silently: the command says "interrupted" in its own one line
        previous(u)

    hook.records_interrupts = True
    return hook


#: the hook that was there before the outermost :func:`keep_lost_interrupts` opened
_previous: list = []
_guard = threading.Lock()


@contextmanager
def keep_lost_interrupts():
    """While open, an unraisable ``KeyboardInterrupt`` is recorded (not printed) for
    :func:`check_interrupt`; every other unraisable exception goes to the hook that was there
    before, which is put back when the last one open closes. Counted, not nested: runs of the
    Python API in two threads of the caller's overlap (one ends before the other), and each
    putting back the hook it found left the suite's hook in the caller's process for good."""
    with _guard:
        if _open[0] == 0:
            _previous[:] = [sys.unraisablehook]
            sys.unraisablehook = _recording(sys.unraisablehook)
        _open[0] += 1
    try:
        yield
    finally:
        with _guard:
            _open[0] -= 1
            if _open[0] == 0:
                sys.unraisablehook = _previous.pop()
                _lost.clear()  # not raised by now: the command ended otherwise (its own line)


def check_interrupt() -> None:
    """Raise ``KeyboardInterrupt`` if an interrupt was dropped by Python since the last check
    (see :func:`keep_lost_interrupts`); it is raised once."""
    if _lost:
        _lost.clear()
        raise KeyboardInterrupt


#: the exit code of the program once its command has returned (see :func:`run_program`)
_ended: list[int] = []
#: the signals whose handler is :func:`_program_handler` (the caller left them at the default)
_taken: list[int] = []


def _program_handler(signum, frame):
    """A stop signal to a program of the suite: while its command runs, ``KeyboardInterrupt``
    (as Ctrl-C's default handler, and the commands' SIGTERM handlers, raise it); once the
    command has returned, the end of the process with the command's exit code."""
    if not _ended:
        raise KeyboardInterrupt
    for f in (sys.stdout, sys.stderr):
        try:
            f.flush()
        except Exception:  # noqa: BLE001 - a closed or broken stream: nothing more to say
            pass
    os._exit(_ended[0])


def _ignore_during_teardown() -> None:
    """The last atexit callback (registered before any library's): Python's teardown that
    follows resets the handlers to the defaults, under which a signal kills the process."""
    if _ended:
        for s in _taken:
            signal.signal(s, signal.SIG_IGN)


atexit.register(_ignore_during_teardown)


def _interrupt(signum, frame):
    raise KeyboardInterrupt


@contextmanager
def ended_as_ctrl_c():
    """While open, SIGTERM and SIGHUP (at their default handler) end the command as Ctrl-C
    does, by KeyboardInterrupt: its children stopped and its temporaries removed (a SIGTERM
    ended ``make bench`` at once, without a word, its child still writing). The handlers of
    SIGINT, SIGTERM and SIGHUP are put back after (an in-process caller keeps its own); in
    another thread than the main one nothing is set (Python lets only the main thread)."""
    signals = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP) if in_main_thread() else ()
    old = {s: signal.getsignal(s) for s in signals}
    for s in signals[1:]:
        if old[s] is signal.SIG_DFL:
            signal.signal(s, _interrupt)
    try:
        yield
    finally:
        for s, h in old.items():
            if h is not None:
                signal.signal(s, h)


def in_main_thread() -> bool:
    """Whether this thread may set signal handlers (Python lets only the main thread): a
    command's ``main`` called from a thread of the caller's (a notebook's background job)
    ended in "ValueError: signal only works in main thread" when it set or put them back."""
    return threading.current_thread() is threading.main_thread()


def exit_status(code) -> int:
    """The status ``sys.exit(code)`` ends the process with: also what a command's ``main``
    returns for argparse's ``--help`` or ``--version`` (``SystemExit(e.code)``), since a
    ``main`` called in a notebook raised SystemExit into the caller."""
    if code is None:
        return 0
    return code if isinstance(code, int) else 1


def run_program(prog: str, main, loaded) -> int:
    """Run ``main()`` (a command's ``main``) as the program ``prog`` and return its exit code
    for ``sys.exit``. ``loaded``: what :func:`sim.threads.interrupt_while_loading` returned;
    the stop signals it took over (those the caller left at their defaults) get
    :func:`_program_handler`, so a signal after ``main`` returned ends the process with
    ``main``'s code (see the module's docstring); one that lands as ``main`` returns gives
    ``<prog>: interrupted`` and 130."""
    _taken[:] = loaded(then=_program_handler)
    try:
        try:
            code = main()
        except SystemExit as e:  # argparse's --help: its code stands as well
            _ended[:] = [exit_status(e.code)]
            raise
        _ended[:] = [exit_status(code)]
    except KeyboardInterrupt:
        _ended[:] = [130]
        os.write(2, f"{prog}: interrupted\n".encode())
        code = 130
    return code
