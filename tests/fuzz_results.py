"""RESULTS, a mutation kind of the fuzzer (tests/test_fuzz.py): a finished results directory
touched by hand, then read.

The SEQUENCE fuzzer's hand edits (tests/fuzz_sequence.py) delete a figure, touch a table's time
or add a file of the user's; they never change what a file of the run holds or is. A seeded case
here copies a finished run (the session's tiny ``network_plate``) to one fixed place, changes
one file the suite wrote (figures left to the sequence fuzzer) in one of these ways, and runs one
reader on it:

* BYTES: a bit flipped, a run of bytes overwritten, the file cut at a random length (to
  nothing, too), garbage appended, at a seeded offset (tables, ``run.json``, README.md, the
  exported ``network.xml``, a chunk of ``trials/``);
* KIND: the file replaced by a directory, a FIFO, a link to itself (a loop), a link that leads
  nowhere, a link to ``/dev/null``, or a link or hard link to an identical copy outside;
* TABLE: a table rewritten by pyarrow as a careful user would (its metadata kept): a column
  dropped, renamed or retyped, a row dropped, reversed or doubled, a number changed (beyond any
  tolerance, NaN, infinite, null), a text value changed, its metadata dropped, or the table
  replaced by another table of the run;
* RECORD: ``run.json`` with a key dropped or its value of another type, a sha256 or the
  config's ``trials`` changed, the study renamed, a second copy of a key, trailing garbage;
* TREE: ``trials/`` or one chunk removed, a chunk added beyond the run's.

The readers: ``sim show`` (plain or ``--markdown``), ``sim report --results``, the API's
``sim.Results(...).claims()`` and ``.table(name)``, and verify of the results against a copy
of the clean run (no re-run). Each runs in a forked child with a time bound (a FIFO opened by
a reader blocks for good) and must exit 0 or 2 with one line (verify: its comparison, or one
line), never a traceback; it changes nothing in the directory (``sim report`` only README.md
and REPORT.md, and the sha256 of README.md that ``run.json`` records: README.md names its
directory, so a copy's is rebuilt); and a reader that exits 0 prints what it prints of the clean run (else it read
the edit as the run's: silent nonsense), while verify never passes a table whose numbers were
changed beyond tolerance. ``FUZZ_CASES`` sets the number of cases (``make test`` 3: one case a three)."""

from __future__ import annotations

import hashlib
import json
import math
import os
import random
import shutil
import stat
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
from fuzz_sequence_run import lines, spawn

READERS = ["show", "markdown", "report", "claims", "table", "verify"]
KINDS = ["bytes"] * 3 + ["kind"] * 3 + ["table"] * 3 + ["record"] * 2 + ["tree"]


def _suite_files(d: Path) -> list[str]:
    """The files of the run (its record's ``files``) a case may change: no figure."""
    rec = json.loads((d / "run.json").read_text())
    return sorted(f for f in rec["files"] if not f.endswith(".png")) + ["run.json"]


def _tables(d: Path) -> list[str]:
    return sorted(p.name for p in d.glob("*.parquet"))


def _bytes(rng: random.Random, p: Path) -> str:
    data = bytearray(p.read_bytes())
    at = rng.randrange(max(1, len(data)))
    how = rng.choice(["flip", "run", "cut", "cut0", "append"])
    if how == "flip" and data:
        data[at] ^= 1 << rng.randrange(8)
    elif how == "run" and data:
        n = min(len(data) - at, rng.choice([2, 8, 64]))
        data[at : at + n] = bytes(rng.randrange(256) for _ in range(n))
    elif how == "cut":
        del data[at:]
    elif how == "cut0":
        data = bytearray()
    else:
        data += rng.choice([b"\0" * 9, b"PAR1", b"\n}\n", "é".encode()])
    p.write_bytes(bytes(data))
    return f"{how} at byte {at}"


def _kind(rng: random.Random, p: Path, outside: Path) -> str:
    how = rng.choice(["dir", "fifo", "loop", "dangling", "devnull", "link", "hardlink"])
    keep = outside / f"copy-{p.name}"
    if how in ("link", "hardlink"):
        shutil.copy(p, keep)
    p.unlink()
    if how == "dir":
        p.mkdir()
    elif how == "fifo":
        os.mkfifo(p)
    elif how == "loop":
        os.symlink(p.name, p)
    elif how == "dangling":
        os.symlink(outside / "nothing-here", p)
    elif how == "devnull":
        os.symlink("/dev/null", p)
    elif how == "link":
        os.symlink(keep, p)
    else:
        os.link(keep, p)
    return how


def _changed_column(rng: random.Random, t: pa.Table) -> tuple[pa.Table, str, bool]:
    """A value of one column changed: (table, description, beyond any tolerance)."""
    i = rng.randrange(t.num_columns)
    f, col = t.schema.field(i), t.column(i).to_pylist()
    rows = [r for r, v in enumerate(col) if v is not None]
    if not rows:
        return t, f"{f.name}: nothing to change", False
    r = rng.choice(rows)
    v = col[r]
    if isinstance(v, bool):
        col[r], big = not v, True
    elif isinstance(v, (int, float)):
        new = rng.choice([v * 1.5 + 1.0, math.nan, math.inf, None])
        big = new is None or not (isinstance(v, float) and math.isnan(v) and new != new)
        col[r] = int(new) if isinstance(v, int) and new is not None and math.isfinite(new) else new
    elif isinstance(v, str):
        col[r], big = rng.choice([v + "x", "", "line\nbreak"]), True
    else:
        return t, f"{f.name}: a {type(v).__name__} left as it is", False
    try:
        arr = pa.array(col, f.type)
    except (pa.ArrowException, TypeError, ValueError, OverflowError):
        arr = pa.array([str(x) for x in col])
        f = pa.field(f.name, arr.type)
    return t.set_column(i, f, arr), f"{f.name}[{r}]: {v!r} -> {col[r]!r}", big


def _table(rng: random.Random, d: Path, name: str) -> tuple[str, bool]:
    """A table rewritten with pyarrow, its metadata kept: (description, numbers changed)."""
    p = d / name
    t = pq.read_table(p)
    meta = t.schema.metadata
    how = rng.choice(["drop", "rename", "retype", "row", "reverse", "double", "value"] * 2)
    how = rng.choice([how, "nometa", "other"])
    big = True
    if how == "drop":
        c = rng.choice(t.column_names)
        t, how = t.drop_columns([c]), f"column {c} dropped"
    elif how == "rename":
        names = list(t.column_names)
        k = rng.randrange(len(names))
        names[k] = names[k] + "_"
        t, how = t.rename_columns(names), f"column {names[k][:-1]} renamed"
    elif how == "retype":
        k = rng.randrange(t.num_columns)
        col = pa.array(
            [None if v is None else str(v) for v in t.column(k).to_pylist()], pa.string()
        )
        t, how = t.set_column(k, t.column_names[k], col), f"column {t.column_names[k]} as text"
    elif how == "row" and t.num_rows:
        k = rng.randrange(t.num_rows)
        t, how = pa.concat_tables([t.slice(0, k), t.slice(k + 1)]), f"row {k} dropped"
    elif how == "reverse" and t.num_rows > 1:  # (take of no rows: no kernel for null columns)
        t, how = t.take(list(range(t.num_rows))[::-1]), "rows reversed"
    elif how in ("double", "row", "reverse"):
        t, how, big = pa.concat_tables([t, t]), "rows doubled", t.num_rows > 0
    elif how == "value":
        t, how, big = _changed_column(rng, t)
    elif how == "nometa":
        t, meta, big, how = t.replace_schema_metadata(None), None, False, "metadata dropped"
    else:
        others = [n for n in _tables(d) if n != name]
        src = rng.choice(others)
        shutil.copy(d / src, p)
        return f"replaced by {src}", True
    pq.write_table(t.replace_schema_metadata(meta), p)
    return f"{how}", big


def _record(rng: random.Random, d: Path) -> str:
    p = d / "run.json"
    rec = json.loads(p.read_text())
    how = rng.choice(["drop", "type", "sha", "trials", "study", "twice", "garbage"])
    key = rng.choice(sorted(rec))
    if how == "drop":
        del rec[key]
    elif how == "type":
        rec[key] = rng.choice([None, 5, "x", [], {}, True, [rec[key]]])
    elif how == "sha":
        sums = rec.get("table_sha256") or {}
        key = rng.choice(sorted(sums) or ["none"])
        if key in sums:
            sums[key] = sums[key][::-1]
    elif how == "trials" and isinstance(rec.get("config"), dict):
        rec["config"]["trials"] = rec["config"].get("trials", 0) + 20
    elif how == "study":
        rec["study"] = rng.choice(["brown_table1", "net work", ""])
    text = json.dumps(rec, indent=1)
    if how == "twice":  # a key given twice: json keeps the last
        text = text.replace("{", '{\n "' + key + '": "first",', 1)
    elif how == "garbage":
        text += rng.choice(["x", "\n{}", "\0"])
    p.write_text(text)
    return f"{how} {key}"


def _tree(rng: random.Random, d: Path) -> str:
    chunks = sorted((d / "trials").rglob("chunk-*.parquet"))
    how = rng.choice(["rm trials", "rm chunk", "extra chunk"])
    if how == "rm trials":
        shutil.rmtree(d / "trials")
    elif how == "rm chunk":
        rng.choice(chunks).unlink()
    else:
        shutil.copy(chunks[0], chunks[0].with_name("chunk-000999.parquet"))
    return how


def mutate(rng: random.Random, d: Path, outside: Path) -> tuple[str, bool]:
    """One seeded change of the run in ``d``: (description, numbers of a table changed)."""
    kind = rng.choice(KINDS)
    files = _suite_files(d)
    if kind == "table":
        name = rng.choice(_tables(d))
        how, big = _table(rng, d, name)
        return f"table {name}: {how}", big
    if kind == "record":
        return f"record: {_record(rng, d)}", False
    if kind == "tree":
        return f"tree: {_tree(rng, d)}", False
    f = rng.choice(files if rng.random() < 0.5 else _tables(d))  # the tables readers read
    p = d / f
    if kind == "kind":
        return f"kind {f}: {_kind(rng, p, outside)}", False
    return f"bytes {f}: {_bytes(rng, p)}", False


def snapshot(top: Path) -> dict[str, str]:
    """What stands under ``top``: a regular file's sha256, else its kind (never opened)."""
    got = {}
    for p in sorted(top.rglob("*")):
        st = p.lstat()
        if stat.S_ISREG(st.st_mode):
            got[str(p.relative_to(top))] = hashlib.sha256(p.read_bytes()).hexdigest()
        elif stat.S_ISLNK(st.st_mode):
            got[str(p.relative_to(top))] = "link " + os.readlink(p)
        else:
            got[str(p.relative_to(top))] = stat.filemode(st.st_mode)[0]
    return got


def _both(res: Path, outside: Path) -> dict[str, str]:
    """:func:`snapshot` of ``res`` and of ``outside`` (its names under ``outside/``), flat: the
    set of its items is the diff a failure prints (a nested dict for ``outside`` made that
    diff a TypeError, "unhashable type: 'dict'", which hid the case)."""
    return snapshot(res) | {f"outside/{k}": v for k, v in snapshot(outside).items()}


def _sans_readme(p: Path) -> object:
    """The run record ``p`` without its ``readme_sha256`` (which ``sim report`` sets when it
    rebuilds README.md), or its bytes when it is no JSON object (None: no regular file, which
    is never opened: a FIFO would block)."""
    try:
        if not stat.S_ISREG(p.lstat().st_mode):
            return None
        raw = p.read_bytes()
    except OSError:
        return None
    try:
        rec = json.loads(raw)
    except ValueError:
        return raw
    return {k: v for k, v in rec.items() if k != "readme_sha256"} if isinstance(rec, dict) else raw


def _same(a: pa.Table, b: pa.Table) -> bool:
    """Tables equal in columns and values (NaN equal to NaN), metadata aside."""
    if a.column_names != b.column_names or a.num_rows != b.num_rows:
        return False
    return repr(a.to_pydict()) == repr(b.to_pydict())


def _reader(which: str, d: Path, clean: Path, table: str, got: Path):
    """The forked child's target for the reader ``which`` (its answer written to ``got``)."""

    def target():
        import sys

        import sim
        from sim.cli import main

        if which in ("show", "markdown", "report"):
            argv = {
                "show": ["show", str(d)],
                "markdown": ["show", "--markdown", str(d)],
                "report": ["report", "--results", str(d.parent)],
            }[which]
            return main(argv)
        if which == "verify":
            from sim.report.verify.rerun import verify
            from sim.report.verify.rules import VerifyError

            try:
                [c] = verify(d.parent, d.parent.parent / "scratch", 1, None, False)
            except VerifyError as e:
                print(f"sim verify: error: {e}", file=sys.stderr)
                return 2
            got.write_text(json.dumps(c.ok))
            return 0
        try:
            r = sim.Results(d, "network")
            t = r.claims() if which == "claims" else r.table(table)
        except (sim.ConfigError, sim.StudyError) as e:
            print(f"sim.api: error: {e}", file=sys.stderr)
            return 2
        pq.write_table(t.replace_schema_metadata(None), got)
        return 0

    return target


def run_case(i: int, seed: int, tmp: Path, clean: Path, refs: References) -> str | None:
    """Case ``i`` of ``seed``: the violation, or None."""
    rng = random.Random(seed * 100_003 + 50_050 + i)
    case = tmp / "case"
    shutil.rmtree(case, ignore_errors=True)
    d = case / "res" / clean.name
    outside = case / "outside"
    outside.mkdir(parents=True)
    shutil.copytree(clean, d, symlinks=True)
    shutil.copytree(clean, case / "scratch" / clean.name, symlinks=True)  # verify's re-run
    table = rng.choice(_tables(d))
    reader = rng.choice(READERS)
    desc, big = mutate(rng, d, outside)
    story = f"results case {i} (seed {seed}): {desc}; {reader}" + (
        f" {table}" if reader == "table" else ""
    )
    before = _both(case / "res", outside)
    record = _sans_readme(d / "run.json")
    got = case / "got"
    code, so, se = spawn(case, _reader(reader, d, clean, table, got), case / "log", timeout=120)
    said = lines(se)
    if "Traceback" in so + se:
        return f"{story}: a traceback: {se[-500:]}"
    if code == "timeout":
        return f"{story}: no answer within 120 s"
    if code not in (0, 2) or (code == 2 and len(said) != 1):
        return f"{story}: exit {code}: {' | '.join(said)[:400]}"
    after = _both(case / "res", outside)
    if reader == "report":
        for f in ("REPORT.md", f"{clean.name}/README.md"):
            before.pop(f, None), after.pop(f, None)
        rec = f"{clean.name}/run.json"
        if rec in after and after[rec] != before.get(rec):
            after[rec] = before[rec] if _sans_readme(d / "run.json") == record else after[rec]
    if after != before:
        diff = sorted(str(x) for x in set(after.items()) ^ set(before.items()))[:3]
        return f"{story}: the reader changed what it read: {diff}"
    if code != 0:
        return None
    if reader == "verify":
        if big and json.loads(got.read_text()):
            return f"{story}: verify passed a table whose numbers were changed"
        return None
    if reader in ("claims", "table"):
        want = refs[reader if reader == "claims" else table]
        if not _same(pq.read_table(got), want):
            return f"{story}: exit 0 but the table read is not the run's"
        return None
    if so != refs[reader]:
        return f"{story}: exit 0 but printed other than for the run:\n{so[:600]}"
    return None


class References(dict):
    """What each reader gives of the clean run (copied beside the cases' place, its path in
    what a reader prints read as theirs), made when first asked for (a case whose reader
    refuses needs none)."""

    def __init__(self, tmp: Path, clean: Path):
        super().__init__()
        self.tmp, self.clean = tmp, clean

    def __missing__(self, which: str):
        case = self.tmp / "ref"
        shutil.rmtree(case, ignore_errors=True)
        d = case / "res" / self.clean.name
        shutil.copytree(self.clean, d, symlinks=True)
        if which.endswith(".parquet"):
            self[which] = pq.read_table(d / which).replace_schema_metadata(None)
        else:
            ref = _reader(which, d, self.clean, "", case / "got")
            code, so, se = spawn(case, ref, case / "log")
            assert code == 0, f"{which} of the clean run: exit {code}: {se[-400:]}"
            so = so.replace(str(case), str(self.tmp / "case"))  # as if read where a case is
            self[which] = pq.read_table(case / "got") if which == "claims" else so
        shutil.rmtree(case)
        return self[which]


def cases(n: int, seed: int, tmp: Path, clean: Path) -> list[str]:
    """Run ``n`` cases on a copy of the finished run ``clean``: their failures."""
    refs = References(tmp, clean)
    return [bad for i in range(n) if (bad := run_case(i, seed, tmp, clean, refs)) is not None]
