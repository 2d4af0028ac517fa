"""The lines of ``python -m sim.batch`` on standard output: each study's as its run ends, and
the closing line (:func:`summary`), written through :class:`_Stdout`, which keeps the first
failed write instead of raising it in a run's thread; and each run's standard error, its lines
named by its study file (:class:`_Named`)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

__all__ = ["summary"]


def summary(files: list[Path], done: dict[str, tuple[int, float, float]], code: int) -> str:
    """The batch's closing line, after its last run: how many runs were made and, with
    ``--stale-only``, how many studies were up to date; when a run failed, how many and which
    (the study files' names) and the batch's exit code. A batch of many studies ended with the
    last run's own lines, and a failure among them was found by scrolling back."""
    up = len(files) - len(done)
    current = f", {up} up to date" if up else ""
    runs = f"{len(done)} run{'s' * (len(done) != 1)}"
    bad = [f.name for f in files if f.stem in done and done[f.stem][0] != 0]
    if not bad:
        return (
            f"sim.batch: {runs} done{current}" if done else f"sim.batch: {up} up to date, none run"
        )
    return (
        f"sim.batch: {runs}, {len(done) - len(bad)} done, {len(bad)} failed "
        f"({', '.join(bad)}){current}; exit {code}"
    )


class _Stdout:
    """``print`` to standard output for :func:`run_all`'s lines, which keeps the first failed
    write (``> /dev/full``; ``| head -1``, a broken pipe) instead of raising it in a run's
    thread: that was a traceback while the other runs went on; now every run ends, the
    timings are written and the driver ends with one line (a broken pipe: quietly)."""

    def __init__(self) -> None:
        self.error: OSError | None = None

    def __call__(self, text: str) -> None:
        if self.error is None:
            try:
                print(text, flush=True)
            except UnicodeEncodeError:  # a name its encoding cannot show (the files' and
                enc = getattr(sys.stdout, "encoding", None) or "ascii"  # --results' are refused
                self(text.encode(enc, "backslashreplace").decode(enc))  # before)
            except OSError as e:
                self.error = e
                try:  # what is left in the buffer is dropped, not retried at exit
                    os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
                except (OSError, ValueError):
                    pass


class _Named:
    """Standard error of one study's run in a batch: every line starts with the study
    file's name, so that a failure among many runs says which study failed."""

    def __init__(self, stream, name: str):
        self.stream, self.name, self.start = stream, name, True

    def write(self, text: str) -> int:
        for part in text.splitlines(keepends=True):
            self.stream.write(f"{self.name}: {part}" if self.start else part)
            self.start = part.endswith("\n")
        return len(text)

    def flush(self) -> None:
        self.stream.flush()
