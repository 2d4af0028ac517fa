"""A note of a run on standard error (``sim: resuming ...``, ``sim: note: ...``) that never
ends the run: a caller of the Python API whose ``sys.stderr`` is closed (a ``StringIO`` it
closed), ``None`` (``pythonw``) or broken (a pipe whose reader left, a notebook's stream gone)
had its run refused by the note's write (``ValueError: I/O operation on closed file``, a
traceback from the suite's ``print``), or the note written to standard output (``print``
to ``None``). Such a note is dropped, as Python drops a warning it cannot write.

A note shows what it holds, as a one-line error does: its terminal control codes (a path's
``\\x1b[2J`` or bidi override) are written escaped (:func:`sim.escapes.printable`), and a
character the stream's encoding cannot write (a path's ``é`` to a strict-ASCII stderr,
``PYTHONIOENCODING=ascii:strict``) as a backslash escape (``\\xe9``): it raised
``UnicodeEncodeError``, a traceback in place of the note."""

from __future__ import annotations

import sys

from sim.escapes import printable

__all__ = ["say"]


def say(line: str) -> None:
    """``line`` on standard error, if it can be written, its control codes escaped and any
    character the stream cannot encode written as a backslash escape."""
    err = sys.stderr
    if err is None:
        return
    line = printable(line, lines=True)
    try:
        try:
            print(line, file=err)
        except UnicodeEncodeError:
            enc = getattr(err, "encoding", None) or "ascii"
            print(line.encode(enc, "backslashreplace").decode(enc, "replace"), file=err)
    except (OSError, ValueError, AttributeError, LookupError):  # closed, broken, no write()
        pass
