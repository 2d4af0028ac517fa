"""The progress bar (tqdm): trials done, trials per second, time left.

The bar fills by work, not by trials: each update counts its trials and the unit adjustments
they cost (:mod:`sim.mc.estimate`'s unit; one a trial where the caller gives none), so a part
of few long trials (an emcee chain, one trial of about 20 s) and one of many short ones
(20,000 trials of a millisecond) move it at the rate of their work: counted as trials alone,
brown_design's bar said 1,343 to 2,476 hours left of a run of 5 minutes. The time left is the
work left over the rate of work; the text shows the trials and their mean rate.

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
    "{desc} {percentage:3.0f}%|{bar}| {trials_done}/{trials_total} trials "
    "[{elapsed}<{remaining}, {trials_rate} trials/s{postfix}]"
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

        def format_dict(self):  # tqdm's, with the trials (its n and total count work)
            return {**tqdm.format_dict.fget(self), **getattr(self, "trials", {})}

        _bar.append(
            type(
                "Bar",
                (tqdm,),
                {
                    "monitor_interval": 0,
                    "_lock": threading.RLock(),
                    "format_dict": property(format_dict),
                },
            )
        )
    return _bar[0]


class Progress:
    """``with Progress(total, label) as p: p.update(n)``; ``chunks`` > 0 adds ``chunk i/N``.
    ``work``: the unit adjustments the ``total`` trials cost (default: one a trial), which
    :meth:`update` counts (``work=``, else the mean of a trial) and the bar fills by."""

    def __init__(
        self,
        total: int,
        label: str = "",
        quiet: bool = False,
        stream=None,
        min_interval: float = 0.2,
        chunks: int = 0,
        work: float | None = None,
    ):
        self.total = int(total)
        self.work_total = float(work) if work and work > 0 else float(self.total)
        self.work = 0.0
        self.label = label
        self.doing = ""  # what the run does now, where no trial is counted (set_doing)
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
            total=self.work_total,
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
            delay=1e9,  # drawn below, once its trials are set
        )
        self._trials()
        if self.enabled:
            self.bar.delay = 0
            self.bar.refresh()

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, *exc) -> None:
        self.bar.close()

    def _trials(self) -> None:
        """The bar's text: trials done of the total and their mean rate."""
        t = self.bar.format_dict["elapsed"] if self.enabled else 0.0
        r = self.done / t if t > 0 else 0.0
        rate = (f"{r:,.0f}" if r >= 100 else f"{r:.3g}") if r > 0 else "?"
        self.bar.trials = {
            "trials_done": f"{self.done:,}",
            "trials_total": f"{self.total:,}",
            "trials_rate": rate,
        }

    def set_doing(self, text: str) -> None:
        """Show ``text`` (what the run does where no trial is counted: an analytic part)
        after the bar's label, redrawn now; ``""`` removes it, and the rate of work (the time
        left) is measured from then on: the part's time, with no work counted, made the rate
        of the trials after it (brown_design's error budget, after a minute of its analytic
        parts) a fraction of theirs and the time left 20 times the real one."""
        self.doing = text
        if self.enabled:
            self.bar.set_description_str(f"{self.label}: {text}" if text else self.label, False)
            self._trials()
            self.bar.refresh()
            if not text:
                self.bar.last_print_n, self.bar.last_print_t = self.bar.n, self.bar._time()

    def lower(self, trials: int, work: float | None = None) -> None:
        """Take ``trials`` (costing ``work``, else the mean) off the totals: trials the
        estimate counted and the run does not need (an adaptive stage that stopped early)."""
        work = trials * self.work_total / max(self.total, 1) if work is None else work
        self.total = max(self.total - int(trials), self.done)
        self.work_total = max(self.work_total - float(work), self.work)
        if self.enabled:
            self.bar.total = self.work_total
            self._trials()
            self.bar.refresh()

    def update(self, n: int, chunks: int = 0, work: float | None = None) -> None:
        """Count ``n`` trials (and ``chunks`` chunks) costing ``work`` unit adjustments (by
        default the mean of a trial)."""
        work = n * self.work_total / max(self.total, 1) if work is None else float(work)
        self.done += int(n)
        self.work += work
        self.chunks_done += int(chunks)
        if not self.enabled:
            return
        # an estimate that was short: grow, never overflow
        self.total = max(self.total, self.done)
        if self.work > self.work_total:
            self.work_total = self.bar.total = self.work
        if self.chunks:
            self.bar.set_postfix_str(f"chunk {self.chunks_done}/{self.chunks}", refresh=False)
        self._trials()
        self.bar.update(work)
        if self.done >= self.total:  # the last frame says 100 % (tqdm skips one too soon)
            self.bar.refresh()


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
