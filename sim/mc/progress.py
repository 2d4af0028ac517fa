"""The progress bar (tqdm): trials done, trials per second, time left.

Drawn on standard error only when it is a terminal or a Jupyter notebook's output (and not
``quiet``); silent otherwise, so logs and CI output stay clean. A run shares one bar over all its parts (see
:class:`sim.studies.RunContext`), whose total comes from the run's estimate
(:mod:`sim.mc.estimate`).
"""

from __future__ import annotations

import io
import os
import sys
import threading
from contextlib import contextmanager

from sim.mc.config import ConfigError
from sim.threads import tqdm_variables_problem

__all__ = ["Progress", "check_environment", "phase", "set_quiet"]

_FORMAT = (
    "{desc} {percentage:3.0f}%|{bar}| {n_fmt}/{total_fmt} trials "
    "[{elapsed}<{remaining}, {rate_fmt}{postfix}]"
)


def check_environment() -> None:
    """Raise :class:`ConfigError` naming the ``TQDM_<option>`` variables tqdm cannot read.
    tqdm is imported only by a bar (here or in :class:`Progress`), not by importing the suite:
    ``import sim.api`` with ``TQDM_NCOLS=abc`` set ended in a traceback from ``tqdm.utils``."""
    if (problem := tqdm_variables_problem()) is not None:
        raise ConfigError(None, problem)


def _terminal(stream) -> bool:
    """Whether ``stream`` is a terminal; a closed one (a notebook's ``sys.stderr`` replaced by
    a closed ``StringIO``) is not: its ``isatty`` raised ValueError, which failed the run."""
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


def _notebook(stream) -> bool:
    """Whether ``stream`` is a Jupyter kernel's (ipykernel's ``OutStream``): not a terminal,
    but its front end redraws a line ended by a carriage return, so a bar asked for there
    (the API's ``run(quiet=False)``) is drawn; it drew nothing, a long run with no sign."""
    return type(stream).__module__.startswith("ipykernel.")


def _columns(stream) -> int | None:
    """The width of the terminal ``stream`` is (0 for a pseudo-terminal whose size was never
    set), or None where it cannot be asked."""
    try:
        return os.get_terminal_size(stream.fileno()).columns
    except (AttributeError, ValueError, OSError, io.UnsupportedOperation):
        return None


def _rows(stream) -> int | None:
    """The height of the terminal ``stream`` is (0 after ``stty rows 0``), or None."""
    try:
        return os.get_terminal_size(stream.fileno()).lines
    except (AttributeError, ValueError, OSError, io.UnsupportedOperation):
        return None


#: the bar's width where the terminal gives none (0 columns: tqdm drew no bar at all) and
#: the widest it is drawn (at 2,000 columns each redraw was a line of 5.8 kB)
DEFAULT_COLUMNS, MAX_COLUMNS = 80, 200

_bar: list = []


def _bar_class():
    """tqdm without its monitor thread. tqdm starts one with its first bar (a disabled one
    too) and leaves it running for the life of the process; in the process of a script of the
    Python API it made the next ``run(workers=2)`` see a second thread and start its workers
    by ``forkserver`` (:func:`sim.mc.executors._start_method`), which runs the caller's
    script again in the fork server: a script without ``if __name__ == "__main__"`` started
    a second run of its own into the same directory and the caller's run failed. Its lock is
    a thread lock of its own: tqdm's default adds a ``multiprocessing.RLock``, whose making
    fixes the process's start method, so that after any run the caller's own
    ``multiprocessing.set_start_method("spawn")`` failed ("context has already been set");
    the suite's bars are drawn by the run's process alone, never by its workers."""
    if not _bar:
        from tqdm import tqdm

        _bar.append(type("Bar", (tqdm,), {"monitor_interval": 0, "_lock": threading.RLock()}))
    return _bar[0]


class Progress:
    """``with Progress(total, label) as p: p.update(n)``; ``chunks`` > 0 adds ``chunk i/N``."""

    def __init__(
        self,
        total: int,
        label: str = "",
        quiet: bool = False,
        stream=None,
        min_interval: float = 0.2,
        chunks: int = 0,
    ):
        self.total = int(total)
        self.chunks = int(chunks)
        self.chunks_done = 0
        self.done = 0
        stream = stream if stream is not None else sys.stderr
        # a terminal that cannot move the cursor back (TERM=dumb: an editor's shell buffer)
        # would show every redraw: no bar there
        notebook = not quiet and _notebook(stream)
        terminal = not quiet and _terminal(stream) and os.environ.get("TERM") != "dumb"
        self.enabled = terminal or notebook
        check_environment()
        cols = _columns(stream) if terminal else None
        # a terminal of 0 rows (stty rows 0): tqdm took its height for -1 rows, the bar's own
        # line outside them, and drew nothing: a fixed width, and rows enough for one bar
        flat = terminal and _rows(stream) == 0
        fixed = notebook or flat or (cols is not None and not 0 < cols <= MAX_COLUMNS)
        width = (min(cols or 0, MAX_COLUMNS) or DEFAULT_COLUMNS) if fixed else None
        width = min(cols - 1, MAX_COLUMNS) if flat and cols and cols > 1 else width  # as tqdm's
        self.bar = _bar_class()(
            total=self.total,
            desc=label,
            file=stream,
            disable=not self.enabled,
            mininterval=min_interval,
            unit=" trials",
            bar_format=_FORMAT,
            leave=False,
            ncols=width,
            dynamic_ncols=not fixed,
            nrows=2 if flat else None,  # tqdm keeps the last row for "(more hidden)"
        )

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, *exc) -> None:
        self.bar.close()

    def update(self, n: int, chunks: int = 0) -> None:
        self.done += int(n)
        self.chunks_done += int(chunks)
        if not self.enabled:
            return
        if self.done > self.bar.total:  # an estimate that was short: grow, never overflow
            self.bar.total = self.done
        if self.chunks:
            self.bar.set_postfix_str(f"chunk {self.chunks_done}/{self.chunks}", refresh=False)
        self.bar.update(int(n))


#: whether the command runs with ``--quiet`` (set by the entry point before a study file is
#: checked: the check of a large network factorises it, before any run context exists)
_QUIET = [False]


def set_quiet(quiet: bool) -> None:
    """Silence (or not) the setup phases :func:`phase` shows for the rest of the process."""
    _QUIET[0] = bool(quiet)


#: the phases shown now, outermost first (a step inside another replaces its line, and the
#: outer one's comes back when it ends)
_SHOWN: list = []


def _show(stream, text: str) -> bool:
    try:
        stream.write("\r\x1b[K" + text)
        stream.flush()
        return True
    except (OSError, ValueError):
        return False


@contextmanager
def phase(label: str, show: bool = True, quiet: bool | None = None, stream=None):
    """Show ``label ...`` on standard error while the block runs, erased when it ends: the
    steps before a run's first progress bar (building, checking, factorising a network of
    tens of thousands of points takes a minute). Shown only where the bar would be (a terminal
    that can move the cursor, not ``quiet``: the argument, else :func:`set_quiet`'s) and when
    ``show`` (the caller's estimate says the step takes more than a couple of seconds)."""
    stream = stream if stream is not None else sys.stderr
    quiet = _QUIET[0] if quiet is None else quiet
    on = show and not quiet and _terminal(stream) and os.environ.get("TERM") != "dumb"
    if on:
        cols = _columns(stream) or DEFAULT_COLUMNS
        on = _show(stream, f"{label} ..."[: max(min(cols, MAX_COLUMNS) - 1, 1)])
    if on:
        _SHOWN.append((stream, f"{label} ..."[: max(min(cols, MAX_COLUMNS) - 1, 1)]))
    try:
        yield
    finally:
        if on:
            _SHOWN.pop()
            back = [t for st, t in _SHOWN if st is stream]
            _show(stream, back[-1] if back else "")
