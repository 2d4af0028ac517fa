"""Reading a results directory's Parquet tables for ``sim show`` and ``sim report``.

The report is built from the tables alone, so a table dropped, replaced or edited by hand
(a column removed or renamed, a column's type changed) is found while the report reads it.
:func:`columns` and :func:`records` return the table as ``{column: values}`` or as rows, as
``pyarrow``'s ``to_pydict`` / ``to_pylist`` do, but:

* a file that is not a Parquet table raises :class:`TableError` naming the file;
* a column the report asks for and the table lacks raises :class:`TableError` naming the file
  and the column;
* every column read is remembered (:func:`last_read`), so an error the report code raises
  on a column's values (a number column retyped as text: ``Unknown format code 'f' for
  object of type 'str'``) is named with the file and column it was reading
  (:func:`damaged_message`).
"""

from __future__ import annotations

import re
import threading
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq

from sim.claims.region import REGION_VERDICTS
from sim.claims.rules import VERDICTS
from sim.mc.config import ConfigError
from sim.mc.message_text import key_text
from sim.mc.publish import changed_figure
from sim.mc.storage import read_provenance, read_record, read_table
from sim.mc.table_edits import edited_cell, missing_cell
from sim.mc.table_shape import (
    declared_problem,
    record_line,
    record_problem,
    recorded_shape,
    shape_problem,
    sum_problem,
)

__all__ = [
    "check_claims_table",
    "check_sweep_record",
    "checked_table",
    "TableError",
    "EditedTable",
    "columns",
    "records",
    "last_read",
    "forget",
    "damaged_message",
    "claims_damage",
    "mixed_run",
    "mixed_table",
    "older",
]

#: every verdict a claims table of the suite holds
KNOWN_VERDICTS = frozenset(VERDICTS) | frozenset(REGION_VERDICTS)

_LAST = threading.local()  # the (file, column) last read by this thread's report


class TableError(ValueError):
    """One table is not as sim wrote it: ``path`` the file, ``what`` the problem."""

    def __init__(self, path: Path, what: str):
        self.path, self.what = Path(path), what
        super().__init__(f"{path}: {what}")


class EditedTable(TableError):
    """A table not of the shape its own run recorded: edited after that run, whatever version
    of the suite's code made it (not a table an older version wrote otherwise)."""


def _note(path: Path, key: str, record: int | None = None) -> None:
    _LAST.where, _LAST.record = (path, key), record


def last_read() -> tuple[Path, str] | None:
    """The ``(file, column)`` this thread's report read last, or None."""
    return getattr(_LAST, "where", None)


def forget() -> None:
    """Start a directory's report: no column read yet (an error before the first is not
    blamed on another directory's table)."""
    _LAST.where, _LAST.record = None, None


class Columns(dict):
    """``{column: values}`` of one table; a missing column raises :class:`TableError`."""

    def __init__(self, path: Path, data: dict):
        super().__init__(data)
        self.path = path

    def __getitem__(self, key):
        value = super().__getitem__(key)
        _note(self.path, key)
        return value

    def __missing__(self, key):
        raise TableError(self.path, f"has no column {key!r}")

    def get(self, key, default=None):  # read and remembered as ``[key]`` is (not blamed on
        return self[key] if key in self else default  # the column read before it)


class Row(Columns):
    """One row of a table, ``{column: value}``, the table's ``index``-th (from 0); a missing
    column raises :class:`TableError`. A value read is remembered with its row: an error on
    it names the record, not only the column (a claims table's 15 rows hold one bad value)."""

    def __init__(self, path: Path, data: dict, index: int):
        super().__init__(path, data)
        self.index = index

    def __getitem__(self, key):
        value = dict.__getitem__(self, key)
        _note(self.path, key, self.index)
        return value


#: pyarrow's words when it could not start a thread of its pool (a memory limit just above
#: a run's peak: the thread's stack could not be mapped), which named the table unreadable
_THREAD = re.compile(r"thread|resource temporarily unavailable|cannot allocate memory", re.I)
#: a quoted span of pyarrow's words (the file it could not open, not the ' of "Couldn't"),
#: left out of the search: a damaged table under a directory named for threads was "not
#: enough memory". It ends at a quote followed by punctuation or the end (pyarrow's
#: ``'PATH': ...``, ``'PATH'.``): a path holding a quote of its own (``it's threads``,
#: ``runs' threads``) was cut there, and its ``threads`` searched
_QUOTED = re.compile(r"(?<![A-Za-z0-9])'.*?'(?=[:.,;)]|$)")


def memory_failure(e: BaseException) -> bool:
    """Whether pyarrow's ``e`` says memory, not the file: an allocation that failed, or a
    thread of its pool it could not start."""
    text = _QUOTED.sub("''", str(e))
    return isinstance(e, MemoryError) or (
        isinstance(e, pa.ArrowException) and bool(_THREAD.search(text))
    )


def cannot_read(key: str, f: Path, e: Exception) -> ConfigError:
    """The ConfigError for ``key`` of a file ``f`` pyarrow could not read (``e``); a
    :func:`memory_failure` is raised as the MemoryError it is (the commands name the memory
    and its limit), not blamed on the file."""
    first = str(e).splitlines()[0] if str(e) else type(e).__name__
    if memory_failure(e):
        raise MemoryError(f"reading {Path(f).name}: {first[:160]}") from None
    return ConfigError(key, f"{f} cannot be read: {first}")


def checked_table(path: str | Path, shaped: bool = True) -> pa.Table:
    """The table at ``path``; a file that is there but not Parquet, or not of the shape its
    run recorded (:func:`~sim.mc.table_shape.shape_problem`: a column retyped, renamed,
    blanked, a row added by hand; ``shaped``), raises :class:`TableError` (a missing or
    unreadable one raises the OSError, which the command reports with its reason). A table of
    a run that recorded no shape (an older version's) is checked for what its columns declare
    (:func:`~sim.mc.table_shape.declared_problem`: a number column as text)."""
    path = Path(path)
    try:
        table = read_table(path)
    except pa.ArrowException as e:
        cannot_read("", path, e)  # ulimit -v just above a run's peak: not the file's fault
        raise TableError(path, f"cannot be read ({str(e).splitlines()[0][:200]})") from None
    if not shaped:
        return table
    if (bad := record_problem(path)) is not None:  # not "an older version's": unchecked
        raise TableError(bad[0], f"{bad[1]}: edited by hand? its tables cannot be checked")
    if (recorded := recorded_shape(path)) is None:  # an older version's run: what it declares
        if (why := declared_problem(table)) is not None:
            raise TableError(path, why)
        if (why := sum_problem(path)) is not None:  # its table_shape removed: unchecked
            raise TableError(path, why)
    elif (why := shape_problem(table, recorded)) is not None:
        raise EditedTable(path, why)
    return table


def columns(path: str | Path) -> dict[str, list]:
    """The columns of the table at ``path`` (``to_pydict``), checked as the module says."""
    path = Path(path)
    return Columns(path, checked_table(path).to_pydict())


def records(path: str | Path, shaped: bool = True) -> list[dict[str, Any]]:
    """The rows of the table at ``path`` (``to_pylist``), checked as the module says (its
    shape only when ``shaped``: a claims table is first checked for what it holds)."""
    path = Path(path)
    return [Row(path, r, i) for i, r in enumerate(checked_table(path, shaped).to_pylist())]


def _under(path: Path, root: Path) -> str | None:
    """``path`` relative to ``root``, or None when it is not under it."""
    try:
        return str(Path(path).resolve().relative_to(Path(root).resolve()))
    except (OSError, ValueError):
        return None


def damaged_message(root: Path, e: Exception) -> str:
    """One line for ``sim show`` / ``sim report`` when reading the tables under ``root``
    failed with ``e``: the file (relative to ``root``) and what is wrong with it -- the
    column it lacks, or the column being read when the report failed on its values."""
    why = f"{type(e).__name__}: {e}".splitlines()[0][:240]
    lr = last_read()
    if isinstance(e, TableError):
        where, why = _under(e.path, root) or str(e.path), e.what
    elif lr is not None and _under(lr[0], root) is not None:  # (not a stale one elsewhere)
        at = getattr(_LAST, "record", None)
        row = "" if at is None else f" of record {at} (from 0)"
        where, why = _under(lr[0], root), f"column {lr[1]!r}{row}: {why}"
    else:
        return f"a table under {root} is not as sim wrote it ({why}); run its study again"
    return f"{where} under {root} is not as sim wrote it ({why}); run its study again"


def claims_damage(prov: dict, verdicts: list, claims: list | None = None) -> str | None:
    """What makes a claims table (its provenance, its ``verdict`` and ``claim`` columns) one
    the suite did not write, or None: a study that is not a name, no row (every study scores
    its claim book), a claim that is no one-line name (a line break split ``sim show``'s
    row), a claim listed twice (two tables concatenated: every count doubled), or a verdict
    outside the suite's vocabulary (a table edited by hand: a made-up verdict, a line break
    that would split a row)."""
    if not isinstance(prov.get("study"), str):
        return f"its provenance names no study ({prov.get('study')!r:.40})"
    if not verdicts:
        return "it holds no claim"
    seen: set = set()
    for c in claims or ():
        if not isinstance(c, str) or not c.isprintable() or not c.strip():  # a line break
            return f"it holds the claim {c!r:.60}, a name sim never writes"  # split a row
        if c in seen:
            return f"it lists the claim {c!r:.60} twice"
        seen.add(c)
    for v in verdicts:
        if v not in KNOWN_VERDICTS:
            return f"it holds the verdict {v!r:.40}, which sim never writes"
    return None


def older(prov: dict, names) -> str:
    """What follows "is not a claims table written by sim" for a table with provenance ``prov``
    and columns ``names``: `` of this version: ...`` for a claims table of an older version of
    the suite (its provenance names the study, but it has no ``verdict`` column: the results/
    of an old clone), else ``: ...`` naming what it lacks (its provenance, the study in it, the
    ``claim`` or ``verdict`` column), or ``""``."""
    if isinstance(prov, dict) and isinstance(prov.get("study"), str) and "holds" in names:
        return (
            " of this version: an older version's table (no 'verdict' column); run its study again"
        )
    if not prov:  # (the line named nothing: "... is not a claims table written by sim")
        return ": it carries no provenance (schema metadata 'sim.provenance': rewritten by a tool?)"
    if "study" not in prov:
        return ": its provenance names no study"
    lacks = sorted({"claim", "verdict"} - set(names))
    return f": it has no column {lacks[0]!r}" if lacks else ""


def check_claims_table(f: Path, key: str) -> None:
    """A results directory's claims table ``f`` must be one the suite wrote, of the study its
    ``run.json`` names (a :class:`ConfigError` for ``key``, naming the file, if not; nothing
    when there is no table; a sweep's top directory, its run record checked)."""
    if not f.is_file():  # a sweep's top without run.json was read unchecked: as a run's now
        sweep = f.parent / "sweep.parquet"
        if sweep.is_file() and (bad := record_problem(sweep, missing=True)) is not None:
            raise ConfigError(key, record_line(bad))
        return
    try:
        prov, names = read_provenance(f), pq.read_schema(f).names
    except (OSError, ValueError, pa.ArrowException) as e:
        raise cannot_read(key, f, e) from None
    if "study" not in prov or not {"claim", "verdict"} <= set(names):
        raise ConfigError(key, f"{f} is not a claims table written by sim{older(prov, names)}")
    try:
        cols = pq.read_table(f, columns=["claim", "verdict"])
        verdicts, claims = cols.column("verdict").to_pylist(), cols.column("claim").to_pylist()
    except (OSError, ValueError, pa.ArrowException) as e:
        raise cannot_read(key, f, e) from None
    damage = claims_damage(prov, verdicts, claims)
    if damage:
        raise ConfigError(key, f"{f} is not a claims table written by sim: {damage}")
    if (bad := record_problem(f, missing=True)) is not None:  # its tables were read unchecked
        raise ConfigError(key, record_line(bad))
    run = (read_record(f.parent) or {}).get("config")
    owner = run.get("study") if isinstance(run, dict) else None
    if isinstance(owner, str) and prov["study"] != owner:  # another study's table, copied in
        raise ConfigError(
            key, f"{f} is a table of {prov['study']!r}, not of this run's {owner!r} (run.json)"
        )
    if (mixed := mixed_run(f.parent)) is not None:
        raise ConfigError(key, mixed)
    try:  # (after the checks above: a table of another run is named as such, not by shape)
        checked_table(f)
    except TableError as e:
        raise ConfigError(key, f"{f} is not the claims table its run wrote: {e.what}") from None


def check_sweep_record(d: Path, key: str) -> None:
    """A sweep's directory ``d`` (``sweep.parquet``, no claims table of its own) must hold its
    run record, as a study's run must (:func:`check_claims_table`): with its ``run.json``
    deleted (or broken) beside a value edited by hand in ``sweep.parquet``, ``sim show`` and
    ``sim report`` printed the edited value as the sweep's, and ``sim report`` wrote it into
    the sweep's README.md, exit 0 (``Results.table("sweep")`` refused it). A :class:`ConfigError`
    for ``key`` naming the ``run.json``; nothing for a directory that is no sweep."""
    f = Path(d) / "sweep.parquet"
    if not f.is_file() or (Path(d) / "claims.parquet").is_file():
        return
    if (bad := record_problem(f, missing=True)) is not None:
        raise ConfigError(key, record_line(bad))


def _other_run(prov: Any, record: dict) -> str | None:
    """How a table's provenance differs from the run record's config and code, or None."""
    if not isinstance(prov, dict) or not prov:
        return "it carries no provenance"
    if "config" not in prov or "code_hash" not in prov:
        return "its provenance records no config and code hash: an older version's table"
    mine, theirs = prov["config"], record.get("config")
    if isinstance(mine, dict) and prov.get("sweep"):  # a sweep's table: its record adds the sweep
        mine = {**mine, "sweep": prov["sweep"]}
    if mine != theirs:
        mine, theirs = (x if isinstance(x, dict) else {} for x in (mine, theirs))
        keys = sorted(k for k in {*mine, *theirs} if mine.get(k) != theirs.get(k))
        more = f" and {len(keys) - 3} more" if len(keys) > 3 else ""
        return f"made with another config: {', '.join(map(key_text, keys[:3]))}{more}"
    if prov["code_hash"] != record.get("code_hash"):
        code = f"{prov['code_hash']!s:.20}, run.json's {record.get('code_hash')!s:.20}"
        return f"made by other code: code hash {code}"
    return None


def mixed_table(
    d: Path, names: list[str] | None = None, missing_ok: bool = True
) -> tuple[Path, str] | None:
    """The first table of the results directory ``d`` (``names``: only these, e.g.
    ``["points.parquet"]``) that is not of the run its ``run.json`` records, and how
    (:func:`mixed_run`); None when every one is."""
    record = read_record(d)
    if record is None:  # no run record: nothing to check against
        return None
    # a table the record does not list is none of the run's (sim.write_table of the user's, a
    # copy): left out, as Results and verify leave it (the whole directory was refused here)
    ran = record.get("table_sha256") if isinstance(record.get("table_sha256"), dict) else None
    for p in sorted(Path(d) / n for n in names) if names else sorted(Path(d).glob("*.parquet")):
        if not p.is_file() or (not names and ran is not None and p.name not in ran):
            continue
        try:
            prov = read_provenance(p)
        except (OSError, ValueError, pa.ArrowException):
            continue  # not Parquet: its reader names it
        why = _other_run(prov, record)
        if why is not None and not (missing_ok and not prov):
            return p, why
    return None


def mixed_run(d: Path, names: list[str] | None = None, missing_ok: bool = True) -> str | None:
    """Why the tables of the results directory ``d`` are not all of the run its ``run.json``
    records (one line), or None. Every table the suite writes carries the config and code hash
    of its run (its provenance), so a table copied in from another run -- an older version's
    results, another config's, two results directories merged by hand -- is named here, never
    read as this run's verdicts (``sim show``, ``sim report``, ``Results.table``) nor called
    current (``--stale-only``). A table with no provenance at all (rewritten by a tool that
    drops schema metadata) is passed when ``missing_ok`` (its numbers are read and checked as
    they are); a directory without a run record has nothing to check against (None). Without
    ``names`` its figures are checked too (:func:`~sim.mc.publish.changed_figure`: one
    replaced by hand; one missing is seen missing)."""
    found = mixed_table(d, names, missing_ok)
    if found is None and (cell := edited_cell(Path(d), names)) is not None:
        return cell  # a sweep's cell: its tables' sha256 are in the sweep's record
    if found is None and (names is None or "sweep.parquet" in names) and (cell := missing_cell(d)):
        return cell  # a sweep whose cell directory was deleted
    if found is None:
        figure = None if names else changed_figure(Path(d), missing_ok=True)
        return None if figure is None else f"{figure}: run its study again"
    return (
        f"{found[0]} is not a table of the run its run.json records ({found[1]}): the "
        "directory mixes results of two runs; run its study again"
    )
