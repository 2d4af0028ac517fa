"""How the command line tells an operating-system error in its one line: whether standard
output itself failed (``sim check > /dev/full``), whether the working directory is gone, and the
reason of an OSError in words (pyarrow raises some without one). Why a results directory
could not be read by show or report is :mod:`sim.cli_tables`'s."""

import linecache
import os

__all__ = ["cwd_exists", "from_stdout", "os_reason"]


def cwd_exists() -> bool:
    try:
        os.getcwd()
    except OSError:
        return False
    return True


def from_stdout(e: OSError) -> bool:
    """Whether ``e`` came from printing to standard output (``sim check > /dev/full``): such
    a write fails without a file name, and the line said only "No space left on device"
    (after a run's results had been written). Judged by the innermost line it was raised
    on: a ``print`` to standard output, or ``sys.stdout`` itself."""
    tb = e.__traceback__
    while tb is not None and tb.tb_next is not None:
        tb = tb.tb_next
    if tb is None:
        return False
    line = linecache.getline(tb.tb_frame.f_code.co_filename, tb.tb_lineno)
    return ("print(" in line and "file=" not in line) or "sys.stdout" in line


def os_reason(e: OSError) -> str:
    """The reason of an OSError in words: its strerror, or (pyarrow raises
    ``FileNotFoundError(path)`` without one) the name of its kind."""
    if e.strerror:
        return e.strerror
    if isinstance(e, FileNotFoundError):
        return "No such file or directory"
    if len(e.args) == 1 and isinstance(e.args[0], str):  # OSError(path): the path is all
        return type(e).__name__
    return str(e) or type(e).__name__
