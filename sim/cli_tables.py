"""Why a results directory could not be read by ``sim show`` or ``sim report``, in the
command's one line: a table not as sim wrote it, or results of another version of the
suite's code (:mod:`sim.cli_errors` tells the operating system's errors)."""

from pathlib import Path

from sim.mc.file_kind import odd_file
from sim.report.read import EditedTable, TableError, damaged_message, last_read
from sim.stale import other_code, remade

__all__ = ["lost_table", "not_as_written", "older_lacks"]


def not_as_written(d: Path, e: Exception) -> str:
    """show and report read the Parquet tables only: one that fails to read as its study's
    table was replaced or edited by hand (named with its column by the reader), or was
    written by another version of the suite (results of an older clone: then said so, of the
    failing table's own results directory when its run record says so)."""
    msg = damaged_message(d, e)
    if isinstance(e, EditedTable):  # not its run's shape, which that run recorded: an edit
        return msg
    own = _table_dir(d, e)
    if own is not None and other_code(own) == str(own):  # the table's own run is older:
        # it is as that version wrote it ("not as sim wrote it" blamed a hand edit)
        return msg.replace(
            "is not as sim wrote it (", "was made by another version of the suite's code ("
        ).replace("; run its study again", f": {remade(own)}")
    older = other_code(d)
    if older:  # the likely cause: a table this version reads as it writes it now
        msg += f" ({older} was made by another version of the suite's code: {remade(d)})"
    return msg


def older_lacks(d: Path, e: FileNotFoundError) -> str | None:
    """The line for a table this version reads that is missing from results ``d`` (or one
    directly under it) made by another version of the suite's code, which did not write it
    (``sim report`` over an older clone's results said only "No such file or directory:
    .../brown_dilution/region_inputs.parquet"); None otherwise (a table removed by hand)."""
    name = e.filename or (e.args[0] if len(e.args) == 1 else None)  # pyarrow's: the path only
    if not isinstance(name, str) or not name:
        return None
    try:  # (a link that loops: RuntimeError before Python 3.13, which raises OSError)
        parts = Path(name).resolve().relative_to(Path(d).resolve()).parts
    except (ValueError, OSError, RuntimeError):
        return None
    own = Path(d) / parts[0] if len(parts) > 1 else Path(d)
    if other_code(own) != str(own):
        return None
    return (
        f"{own} was made by another version of the suite's code (it has no {parts[-1]}, which "
        f"this version reads): {remade(own)}"
    )


def lost_table(e: FileNotFoundError) -> str | None:
    """The line for a table show or report could not open (``e``, pyarrow's, names the path
    only) when something other than a regular file stands there: a FIFO, a device, a link
    that leads nowhere or loops ("No such file or directory" named a file that is there, and
    a link that loops ended in a traceback); None otherwise (a table removed by hand: the
    plain line names it)."""
    name = e.filename or (e.args[0] if len(e.args) == 1 else None)
    if not isinstance(name, str) or not name or (what := odd_file(name)) is None:
        return None
    return f"{name} is {what}, not a table the suite wrote; run its study again"


def _table_dir(d: Path, e: Exception) -> Path | None:
    """The results directory (``d`` or one directly under it) of the table whose reading
    failed with ``e``, or None when no table is named."""
    lr = last_read()
    f = e.path if isinstance(e, TableError) else (lr[0] if lr else None)
    if f is None:
        return None
    try:
        parts = Path(f).resolve().relative_to(Path(d).resolve()).parts
    except (ValueError, OSError, RuntimeError):  # (a link that loops, before Python 3.13)
        return None
    return Path(d) / parts[0] if len(parts) > 1 and (Path(d) / parts[0]).is_dir() else Path(d)
