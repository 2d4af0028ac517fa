"""The shape of each table a run wrote, recorded in its ``run.json`` (``table_shape``) and
checked by every reader of the results (``sim show``, ``sim report``, ``Results.table``).

A table edited by hand (with pandas, DuckDB, a spreadsheet's export) still parses, and the
readers read it as the run's: a text column retyped as true/false printed ``True`` where the
paper's source stood, a null printed ``None``, a number column written as text was printed as
the text, a column renamed from ``_mm`` to ``_um`` was printed in the wrong unit, a row
duplicated was counted twice. The shape of a table is what such edits change and a faithful
rewrite (other row groups, dictionary encoding, a wider text type, another integer width)
keeps:

* its number of rows;
* each column's name and kind (the Arrow type, with a dictionary read as its values, every
  text type as ``string``, every integer width as ``int``);
* per column, how many of its values are null, and per floating column how many are NaN and
  how many infinite (a key column's value blanked or set to NaN by hand);
* per column, a digest of its values in their order (:func:`values_digest`: a dictionary read
  as its values, any text type as text, any integer width as a 64-bit integer), so that a
  value edited by hand in a table of the same shape (a verdict turned from ``holds`` to
  ``fails``, a number changed, rows reordered) is not read as its run's.

:func:`shape_problem` says, in a few words naming the column, how a table differs from the
shape its run recorded; results of a version that recorded none (or a record edited into
another form) are not checked.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from sim.mc import tolerance
from sim.mc.path_names import STAGE_SUFFIX
from sim.mc.storage import RECORD, code_hash, read_record, regular_text

__all__ = [
    "SHAPE_KEY",
    "NUMBERS",
    "kind",
    "shape",
    "record_line",
    "record_problem",
    "recorded_shape",
    "shape_problem",
    "sum_problem",
    "values_digest",
    "declared_problem",
]

#: the key of the run record that holds every table's shape, by its path under the results
SHAPE_KEY = "table_shape"
#: the kinds of a number column (:func:`kind`)
NUMBERS = frozenset({"int", "double", "float", "halffloat"})
#: what a number column may be (``null``: a column of no value at all, as pyarrow types it)
_NUMBERISH = NUMBERS | {"null"}
#: the tolerance kinds declared only with number columns (:mod:`sim.mc.tolerance`)
_NUMBER_RULES = frozenset({"arithmetic", "axial", "circular", "mc", "chain"})


def kind(t: pa.DataType) -> str:
    """A column's kind: its Arrow type, a dictionary as its values, every text type as
    ``string``, every integer width as ``int``, a list by the kind of its items."""
    if pa.types.is_dictionary(t):
        return kind(t.value_type)
    if pa.types.is_string(t) or pa.types.is_large_string(t):
        return "string"
    if pa.types.is_integer(t):
        return "int"
    if pa.types.is_list(t) or pa.types.is_large_list(t):
        return f"list<{kind(t.value_type)}>"
    return str(t)


def _count(mask: Any) -> int:
    return int(pc.sum(mask).as_py() or 0)


def values_digest(col: pa.ChunkedArray) -> str:
    """16 hex digits of the sha256 of a column's values in their order, the same for every
    faithful rewrite of them (a dictionary encoding, another text type or integer width,
    other row groups, another NaN's bits): which rows are null, then the values."""
    if pa.types.is_dictionary(col.type):
        col = pa.chunked_array([c.dictionary_decode() for c in col.chunks], col.type.value_type)
    t, h = col.type, hashlib.sha256()
    h.update(np.packbits(col.is_null().to_numpy(zero_copy_only=False).astype(bool)).tobytes())
    try:
        if pa.types.is_floating(t):
            a = col.fill_null(0).to_numpy()
            h.update(np.where(np.isnan(a), np.nan, a).tobytes())
        elif pa.types.is_integer(t):
            h.update(col.fill_null(0).cast(pa.int64()).to_numpy().tobytes())
        elif pa.types.is_boolean(t):
            h.update(col.fill_null(False).to_numpy(zero_copy_only=False).astype(bool).tobytes())
        else:
            raise TypeError(t)
    except (TypeError, ValueError, pa.ArrowException):  # text, lists, an int over int64's range
        h.update(_as_text(col))
    return h.hexdigest()[:16]


def _as_text(col: pa.ChunkedArray) -> bytes:
    """A column's values as JSON bytes, or, for values Python cannot hold (a timestamp of
    nanoseconds put in by hand: "not safely convertible to microseconds"), its Arrow bytes.
    The shape of every table is taken before its columns' kinds are compared: such a column
    ended ``sim show`` on pyarrow's words and ``Results.table`` on a traceback."""
    try:
        return json.dumps(col.to_pylist(), default=repr).encode("utf-8", "surrogatepass")
    except (TypeError, ValueError, OverflowError, RecursionError, pa.ArrowException):
        sink = pa.BufferOutputStream()
        one = pa.table({"c": col.combine_chunks()})
        with pa.ipc.new_stream(sink, one.schema) as w:
            w.write_table(one)
        return sink.getvalue().to_pybytes()


def shape(table: pa.Table) -> dict:
    """``{"rows": n, "columns": {name: kind}, "nulls"|"nan"|"inf": {name: count}, "values":
    {name: digest}}`` of a table (the counts only where not zero)."""
    cols: dict[str, str] = {}
    counts: dict[str, dict[str, int]] = {"nulls": {}, "nan": {}, "inf": {}}
    for i, name in enumerate(table.column_names):
        col = table.column(i)
        cols[name] = kind(col.type)
        found = {"nulls": col.null_count}
        if pa.types.is_floating(col.type):
            found["nan"], found["inf"] = _count(pc.is_nan(col)), _count(pc.is_inf(col))
        for what, k in found.items():
            if k:
                counts[what][name] = k
    values = {name: values_digest(table.column(i)) for i, name in enumerate(table.column_names)}
    counted = {k: v for k, v in counts.items() if v}
    return {"rows": table.num_rows, "columns": cols, **counted, "values": values}


def _spots(path: Path) -> list[tuple[Path, str]]:
    """``(directory, key)`` of each run record that may cover the table ``path``: its own
    directory's, and for a sweep's cell (``cells/<label>/x.parquet``) the sweep's. The cell
    is found where its directory really is: a relative path ("./x.parquet") has no parents,
    and a symbolic link to a cell (``latest -> sweep/cells/cell0000_r0``) has other ones (its
    tables were refused, "latest/run.json is missing (deleted by hand?)")."""
    spots = [(path.parent, path.name)]
    cell = Path(os.path.realpath(path.parent))
    if cell.parent.name == "cells":
        spots.append((cell.parent.parent, f"cells/{cell.name}/{path.name}"))
    return spots


#: :func:`record_problem`'s word for a run record that is not there at all
MISSING = "missing"


def record_problem(path: str | Path, missing: bool = False) -> tuple[Path, str] | None:
    """``(run.json, what is wrong with it)`` when the run record of the table ``path`` is
    there but is no run record, or (``missing``: asked by the readers of a results directory,
    ``sim show``, ``sim report``, verify, ``Results.table``) is not there at all
    (:data:`MISSING`), else None. Such a
    ``run.json`` -- invalid JSON left by an editor, a FIFO, a directory, unreadable -- let
    every reader take the tables unchecked, as of a version that recorded no shapes: a value
    edited by hand beside it was printed as the run's. So did a ``run.json`` deleted: every
    version of the suite that wrote a claims table the readers take (one with a ``verdict``
    column) wrote its ``run.json`` beside it, so a results directory without one is not an
    older version's, it is one whose record was removed."""
    spots = _spots(Path(path))
    for root, key in spots:
        if (doc := read_record(root)) is not None:
            return (root / RECORD, why) if (why := _unlisted(doc, root, key)) else None
        if os.path.lexists(rec := root / RECORD):
            return rec, _unrecorded(rec)
    if not missing:
        return None
    sweep = len(spots) > 1 and os.path.lexists(spots[-1][0] / "sweep.parquet")  # else its own
    return (spots[-1 if sweep else 0][0] / RECORD, MISSING)


def _unlisted(rec: dict, root: Path, key: str) -> str | None:
    """What is wrong when ``rec``, a record of this code's run (sealed: not a staging
    directory's), recorded the shape of the table ``key`` but its ``files`` does not name it
    (emptied or made null by hand), else None. Such a record was read as the run's, and
    ``sim report`` re-filled its ``files`` with README.md alone: the run's own files then read
    as the user's, and a re-run refused its own export."""
    files = rec.get("files")
    shapes = rec.get(SHAPE_KEY)
    if not isinstance(shapes, dict) or key not in shapes or _staging(root):
        return None
    if isinstance(files, list) and key in files:
        return None
    if not _this_code(rec):
        return None
    return f"its files list does not name {key}, which its run wrote"


def record_line(bad: tuple[Path, str]) -> str:
    """The one line for a :func:`record_problem`."""
    if bad[1] == MISSING:
        return (
            f"{bad[0]} is missing (deleted by hand?), so the tables beside it cannot be "
            "checked against their run; run the study again"
        )
    return (
        f"{bad[0]} is not a run record ({bad[1]}: edited by hand?), so its tables cannot be "
        "checked against their run; run the study again"
    )


def _unrecorded(rec: Path) -> str:
    """What is wrong with ``rec``, a ``run.json`` that :func:`read_record` does not read."""
    try:
        text = regular_text(rec).removeprefix("\ufeff")
        doc = json.loads(text)
    except UnicodeDecodeError:
        return "not UTF-8 text"
    except OSError as e:
        return e.strerror or str(e).removeprefix(f"{rec} ")
    except ValueError as e:
        return f"not JSON: {getattr(e, 'msg', e)} (line {getattr(e, 'lineno', '?')})"
    except RecursionError:
        return "JSON nested too deeply"
    del doc
    return "not an object holding its config and code_hash"


#: the fields of a run record that the run's tables are checked by, and their types
_SEALED = (("table_sha256", dict), (SHAPE_KEY, dict), ("files", list))


def sum_problem(path: str | Path) -> str | None:
    """For a table whose run record holds no shape of it but its sha256 (``table_sha256``:
    a record of the versions between the two, or one whose ``table_shape`` was removed by
    hand): how the file differs (its sha256), else None. Such a table was read unchecked: a
    value edited by hand was printed as the run's."""
    path = Path(path)
    for root, key in _spots(path):
        if (rec := read_record(root)) is None:
            continue
        sums = rec.get("table_sha256")
        if (lost := _lost(rec)) and _this_code(rec) and not _staging(root):  # every one
            # written by this code's sim.mc.publish.seal: an older version's record may lack them, one of this code's
            # was edited (read unchecked: table_shape and table_sha256 made null, or removed
            # with files, which told an older version's record apart)
            return (
                f"its run record holds {lost}, which this version's runs record (removed by hand?)"
            )
        want = sums.get(key) if isinstance(sums, dict) else None
        if not isinstance(want, str):
            return _unsealed(rec, root, key)
        h = hashlib.sha256()
        with open(path, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
        if h.hexdigest() != want:
            return "its sha256 is not the one its run recorded, which holds no shape of it"
        return None
    return None


def _lost(rec: dict) -> str | None:
    """``"neither table_sha256 nor table_shape"`` (``", nor files"``) when ``rec`` holds
    neither a table's sha256 nor its shape (removed, or made null), else None: with one of
    them its tables are checked (a record of the versions between the two has no shape)."""
    lost = [k for k, t in _SEALED if not isinstance(rec.get(k), t)]
    if lost[:2] != ["table_sha256", SHAPE_KEY]:
        return None
    return "neither table_sha256 nor table_shape" + (", nor files" if len(lost) > 2 else "")


def _unsealed(rec: dict, root: Path, key: str) -> str | None:
    """Why the table ``key`` of a run record of this code (``rec``, not a staging one) that
    holds neither its sha256 nor its shape is not read (None: an older version's record, or a
    file of the user's that a publish carried in). :func:`sim.mc.publish.seal` records both
    for every table; a record whose ``table_sha256`` and ``table_shape`` were emptied by hand
    (``{}``: the fields kept, their entries gone) had its tables read unchecked, a value
    edited beside it printed as the run's."""
    if not _this_code(rec) or _staging(root):
        return None
    carried, files = rec.get("carried"), rec.get("files")
    if isinstance(carried, list) and key in carried:
        return None
    if isinstance(files, list) and key not in files:  # added beside the run's files, or the
        return (  # record's lists emptied of it too: read unchecked as the run's
            f"its run record lists no {key} among the files its run wrote (added or "
            "removed by hand?)"
        )
    return (
        f"its run record holds neither a sha256 nor a shape of {key}, which this version's "
        "runs record for every table (removed by hand?)"
    )


def _staging(root: Path) -> bool:
    """Whether ``root`` is a run's staging directory (``.<name>.partial``), whose record is
    sealed only at publish: a sweep reads its own ``sweep.parquet`` there before (refused as
    a forged record of this code's, "removed by hand?", and the sweep failed)."""
    return root.name.startswith(".") and root.name.endswith(STAGE_SUFFIX)


def _this_code(rec: dict) -> bool:
    """Whether the run record ``rec`` is of a run of this code (its ``code_hash`` this code's
    hash of its study): such a run recorded every table's sha256 and shape."""
    study = rec.get("config", {}).get("study") if isinstance(rec.get("config"), dict) else None
    try:
        return isinstance(study, str) and rec.get("code_hash") == code_hash(study)
    except (OSError, ValueError, SyntaxError):  # a source of ours unreadable: not known
        return False


def recorded_shape(path: str | Path) -> dict | None:
    """The shape the run record of ``path``'s results directory recorded for it (a table of
    a sweep's cell, ``cells/<label>/x.parquet``, is in the sweep's record), or None."""
    for root, key in _spots(Path(path)):
        rec = read_record(root)
        if rec is not None:
            shapes = rec.get(SHAPE_KEY)
            found = shapes.get(key) if isinstance(shapes, dict) else None
            return found if _is_shape(found) else None
    return None


def _is_shape(s: Any) -> bool:
    """Whether ``s`` is a shape as :func:`shape` makes it (a record edited into another form,
    or of a version that recorded none, is not one: its table is not checked)."""
    if not isinstance(s, dict) or not _count_of(s.get("rows")):
        return False
    cols = s.get("columns")
    if not isinstance(cols, dict) or not all(isinstance(v, str) for v in cols.values()):
        return False
    return all(
        isinstance(s.get(k, {}), dict) and all(_count_of(v) for v in s.get(k, {}).values())
        for k in ("nulls", "nan", "inf")
    )


def _count_of(v: Any) -> bool:
    """A count a table can hold (an int of 10**400 in an edited record was printed whole)."""
    return type(v) is int and 0 <= v < 2**63


_WORDS = {"nulls": "null", "nan": "NaN", "inf": "infinite"}


def shape_problem(table: pa.Table, recorded: dict | None) -> str | None:
    """How ``table`` differs from the shape its run ``recorded`` (a few words naming the
    column: ``column 'x' is string where its run wrote double``), or None (the same, or
    nothing recorded to check it against)."""
    if not _is_shape(recorded):
        return None
    names = table.column_names
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        return f"it has the column {twice[0]!r} twice"
    now, want = shape(table), recorded["columns"]
    gone = [c for c in want if c not in now["columns"]]
    new = [c for c in now["columns"] if c not in want]
    if gone:
        instead = f" (it has {new[0]!r} in its place: renamed by hand?)" if new else ""
        return f"has no column {gone[0]!r}{instead}"
    if new:
        return f"column {new[0]!r} is not one its run wrote"
    for c, k in want.items():
        if now["columns"][c] != k:
            return f"column {c!r} is {now['columns'][c]} where its run wrote {k}"
    if now["rows"] != recorded["rows"]:
        return f"has {now['rows']:,} rows where its run wrote {recorded['rows']:,}"
    for what, word in _WORDS.items():
        have, had = now.get(what, {}), recorded.get(what, {})
        for c in want:
            if have.get(c, 0) != had.get(c, 0):
                return (
                    f"column {c!r} holds {have.get(c, 0):,} {word} value(s) where its run "
                    f"wrote {had.get(c, 0) or 'none'}"
                )
    # the values (a record of a version that recorded no digests: not checked)
    digests = recorded.get("values")
    for c in want if isinstance(digests, dict) else ():
        if isinstance(digests.get(c), str) and now["values"][c] != digests[c]:
            return (
                f"the values of column {c!r} are not those its run wrote (edited by hand, or "
                "its rows reordered?)"
            )
    return None


def declared_problem(table: pa.Table) -> str | None:
    """For a table whose run recorded no shape (an older version's results): a column declared
    with a rule for numbers (its tolerance, :mod:`sim.mc.tolerance`) that holds no numbers
    (retyped as text by hand), in a few words naming it, or None."""
    try:
        specs = tolerance.decode(table.schema.metadata)
    except (ValueError, RecursionError):  # metadata edited into no JSON: not checked
        return None
    if not isinstance(specs, dict):
        return None
    for i, c in enumerate(table.column_names):
        spec = specs.get(c)
        k = kind(table.column(i).type)
        if isinstance(spec, dict) and spec.get("kind") in _NUMBER_RULES and k not in _NUMBERISH:
            return f"column {c!r} is {k} where sim writes numbers"
    return None
