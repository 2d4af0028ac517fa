"""How a program of the suite ends: its standard output flushed while a failure can still be
said in one line.

Standard output to a file or a pipe is block-buffered: what a command printed last (``sim
check``'s whole listing, ``--help``, ``make verify``'s comparisons) was written only when Python
flushed it at exit, where a full disk (``> /dev/full``) or a reader that left (``| head -1``)
was Python's "Exception ignored in: <_io.TextIOWrapper name='<stdout>'>" and exit 120. And
argparse drops an OSError of its own write (``--help > /dev/full`` under ``PYTHONUNBUFFERED=1``,
as in many containers, ended silently with exit 0). :func:`finish` runs a program's main and
flushes: a failed write is one line naming standard output and exit 2, a reader that left
nothing and 141 (as a program killed by SIGPIPE). Outside the studies' code (and its hash):
only the programs' entry points use it.
"""

from __future__ import annotations

import codecs
import io
import os
import sys

__all__ = [
    "ascii_punctuation",
    "finish",
    "flush_stdout",
    "stdout_failed",
    "stdout_unwritten",
    "open_standard_streams",
    "unshown",
]

#: the suite's own characters in what it prints (an interval's "0.00–1.00", the dash of
#: ``sim show --markdown``'s "**holds** — ...", which was refused as a name of the user's
#: would be: "cannot show '\u2014'"), and their ASCII
ASCII_FOR = {"\u2013": "-", "\u2014": "--", "\u00b1": "+/-", "\u2264": "<=", "\u2265": ">="}

#: a failed write to standard output that its writer could not raise (see stdout_unwritten)
_unwritten: list[OSError] = []


def stdout_unwritten(e: OSError) -> None:
    """Record ``e``, a write to standard output that failed where it is dropped (argparse's
    ``--help`` and ``--version``), for :func:`flush_stdout` to say."""
    _unwritten[:] = [e]


def flush_stdout(prog: str, code: int) -> int:
    """Flush standard output now and return the exit code to end with (see the module's
    docstring); ``code`` stands when it already says a failure."""
    out = sys.stdout
    try:
        if out is None:  # >&-: print() wrote nowhere (argparse's --help: said, exit 2)
            if _unwritten:
                _unwritten.clear()
                _said(f"{prog}: error: standard output is closed (>&-): nothing to print to")
                return code or 2
            return code
        if _unwritten:  # a write that failed where it could not be raised (argparse's --help)
            raise _unwritten.pop()
        out.flush()
        return code
    except ValueError:  # closed by the caller: nothing left to write
        return code
    except OSError as e:
        return stdout_failed(prog, e, code)


def stdout_failed(prog: str, e: OSError, code: int) -> int:
    """The exit code after ``e``, a failed write to standard output, and its one line (none
    for a reader that left: 141); ``code`` stands when it already says a failure. What is
    left in the buffer is dropped, not tried again at exit."""
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):
        pass
    if isinstance(e, BrokenPipeError):
        return code or 141
    _said(f"{prog}: error: {e.strerror or type(e).__name__}: standard output")
    return code or 2


def _said(line: str) -> None:
    """``line`` on standard error, if it can be written (gone as well: nothing)."""
    try:
        print(line, file=sys.stderr, flush=True)
    except (OSError, ValueError, AttributeError):
        pass


def finish(prog: str, main) -> int:
    """``main()``'s exit code (a ``SystemExit`` of argparse's ``--help`` included) after
    :func:`flush_stdout`, for ``sys.exit``. Standard output closed (``>&-``) is refused
    before ``main`` runs, by every program alike: what it prints would be lost (``sim run``'s
    summary, ``sim report``'s path, ``sim.batch``'s count), as ``> /dev/full`` says after."""
    if sys.stdout is None:  # open_standard_streams: >&- at the start (>/dev/null prints nowhere)
        _said(f"{prog}: error: standard output is closed (>&-): nothing to print to")
        return 2
    try:
        code = main()
    except SystemExit as e:
        if not (e.code is None or isinstance(e.code, int)):  # a message: Python prints it
            raise
        code = e.code
    return flush_stdout(prog, code or 0)


def open_standard_streams() -> None:
    """A standard stream closed when the program starts (``2>&-``, ``>&-``, ``<&-``) is opened
    on the null device. Python leaves ``sys.stderr`` None then, and ``print(..., file=
    sys.stderr)`` writes to standard *output*: ``sim check STUDY --set trials=-1 2>&- >
    saved.toml`` wrote its error line into saved.toml, and ``python -m sim.batch 2>&-`` ended
    with exit 1 and no timings after its runs (``sys.stderr.write`` of a run's lines). And the
    lowest free descriptor goes to the next file opened (the run's lock file became descriptor
    1 or 2). Standard error now writes nowhere, as asked; ``sys.stdout`` stays None (``sim
    check`` and ``sim show`` refuse to print nowhere), its descriptor taken by the null device.
    Standard error is then :class:`_Stderr`, whose failed writes are dropped."""
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
            continue
        except OSError:
            pass
        try:
            null = os.open(os.devnull, os.O_RDWR)
            if null != fd:
                os.dup2(null, fd)
                os.close(null)
        except OSError:  # no descriptor to be had: left as it was
            continue
    err = sys.stderr
    try:
        if err is not None and (isinstance(err, _Stderr) or err.fileno() != 2):
            return  # already ours, or the caller's own stream (a test's capture)
    except (OSError, ValueError, AttributeError):
        return
    sys.stderr = _Stderr(
        io.BufferedWriter(io.FileIO(2, "w", closefd=False)),
        encoding=getattr(err, "encoding", None) or "utf-8",
        errors=getattr(err, "errors", None) or "backslashreplace",
        line_buffering=True,
        write_through=bool(getattr(err, "write_through", False)),
    )


class _Stderr(io.TextIOWrapper):
    """Standard error whose write the system refuses (``2>/dev/full``, a reader that left) is
    dropped: there is nowhere to say so, and the failure was the command's own: ``sim run``
    stopped at its first note ("results go to scratch/...") with exit 1, ``sim check``'s error
    line ended in exit 1, not 2, and ``make verify`` in exit 1 (a failed comparison) at its
    first "re-running" line. The descriptor is then pointed at the null device (the buffered
    text drains there), so the command runs on and ends with its own exit code."""

    def write(self, s: str) -> int:
        try:
            return super().write(s)
        except OSError:
            self._to_null()
            return len(s)

    def flush(self) -> None:
        try:
            super().flush()
        except OSError:
            self._to_null()

    def _to_null(self) -> None:
        try:
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, 2)
            os.close(null)
            super().flush()  # what the failed write left in the buffer: into the null device
        except (OSError, ValueError):
            pass


def ascii_punctuation() -> None:
    """Standard output whose encoding cannot show the suite's own characters
    (:data:`ASCII_FOR`: ``PYTHONIOENCODING=ascii``, or ``LC_ALL=C`` with ``PYTHONUTF8=0``)
    writes them in ASCII. ``sim run`` computed every trial and published its results, then
    ended with exit 2 on its closing summary's first interval ("the output (encoding ascii)
    cannot show '\\u2013'"), and ``sim show`` of any results failed so. A name of the user's
    that the encoding cannot show (a network's ``café``) is still refused by the command, in
    one line, as before; other characters go to the stream's own error handler."""
    out = sys.stdout
    try:
        "".join(ASCII_FOR).encode(out.encoding)
        return
    except UnicodeEncodeError:
        pass
    except (AttributeError, LookupError, TypeError):  # no stdout (>&-), a stream of the caller's
        return
    own = getattr(out, "errors", None) or "strict"
    name = f"sim-ascii-{own}"
    try:
        codecs.lookup_error(name)
    except LookupError:
        codecs.register_error(name, _ascii_or(own))
    try:
        out.reconfigure(errors=name)
    except (AttributeError, ValueError, OSError):
        pass


def unshown(text: str) -> str | None:
    """What standard output cannot show of ``text`` (a path or a name of the user's that a
    command prints when it ends), in the words of the commands' refusal, or None. Asked before
    the work: ``sim run --out 'dΩ'`` under ``PYTHONIOENCODING=ascii`` (or a Latin-1 locale)
    computed and published every trial, then ended with exit 2 on its closing line "results
    in ...", and ``python -m sim.batch`` and ``make verify`` with a traceback on a study's
    name."""
    out = sys.stdout
    try:
        text.encode(out.encoding, getattr(out, "errors", None) or "strict")
    except UnicodeEncodeError as e:
        what = ascii(e.object[e.start : e.end])
        return (
            f"the output (encoding {e.encoding}) cannot show {what} of {ascii(text)}: "
            "set PYTHONIOENCODING=utf-8"
        )
    except (AttributeError, LookupError, TypeError):  # no stdout, a stream of the caller's
        return None
    return None


def _ascii_or(own: str):
    """A codec error handler: a character of :data:`ASCII_FOR` as its ASCII, the characters
    up to the next such one as the stream's own handler ``own`` takes them."""

    def handler(e: UnicodeError):
        if not isinstance(e, UnicodeEncodeError):
            raise e
        if (c := e.object[e.start]) in ASCII_FOR:
            return ASCII_FOR[c], e.start + 1
        end = e.start + 1
        while end < e.end and e.object[end] not in ASCII_FOR:
            end += 1
        if own == "strict":
            raise UnicodeEncodeError(e.encoding, e.object, e.start, end, e.reason)
        return codecs.lookup_error(own)(
            UnicodeEncodeError(e.encoding, e.object, e.start, end, e.reason)
        )

    return handler
