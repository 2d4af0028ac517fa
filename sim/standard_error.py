"""A note of a run on standard error (``sim: resuming ...``, ``sim: note: ...``) that never
ends the run: a caller of the Python API whose ``sys.stderr`` is closed (a ``StringIO`` it
closed), ``None`` (``pythonw``) or broken (a pipe whose reader left, a notebook's stream gone)
had its run refused by the note's write (``ValueError: I/O operation on closed file``, a
traceback from the suite's ``print``), or the note written to standard output (``print``
to ``None``). Such a note is dropped, as Python drops a warning it cannot write; a line the
stream's encoding cannot show is raised as before (the commands refuse such names first)."""

from __future__ import annotations

import sys

__all__ = ["say"]


def say(line: str) -> None:
    """``line`` on standard error, if it can be written."""
    err = sys.stderr
    if err is None:
        return
    try:
        print(line, file=err)
    except UnicodeError:
        raise
    except (OSError, ValueError, AttributeError):  # closed, broken, or no write()
        pass
