"""Sealing and publishing a finished run's staging directory (:mod:`sim.mc.outputs` checks
the output and keeps the staging directory).

:func:`seal` records in ``run.json`` every file the run wrote and each chunk file's and
figure's sha256 (:func:`damaged_chunks` and :func:`changed_figure` check a finished directory
against them); :func:`publish` replaces
``<out>`` by the staging directory, carrying over every entry of the old results that the
suite did not write (a user's notes, links, FIFOs: copied as what they are, never opened),
and refuses when the new run writes a file of a carried entry's name.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import os
import re
import shutil
from itertools import count
from pathlib import Path

from sim.mc.config import ConfigError
from sim.mc.export_edits import EXPORT_KEY, changed_exports, changed_words, export_sums
from sim.mc.file_kind import odd_file
from sim.mc.outputs import swap_dir
from sim.mc.paths import mounts_under
from sim.mc.pids import writer_gone
from sim.mc.runner import ChunkStore
from sim.mc.storage import LOCK, read_record, read_table, write_record
from sim.mc.swap import exchange as _exchange
from sim.mc.swap import hold_old
from sim.mc.swap import libc as _libc  # noqa: F401 - tests ask it whether renameat2 exists
from sim.mc.table_shape import SHAPE_KEY, shape
from sim.standard_error import say

__all__ = ["seal", "publish", "damaged_chunks", "changed_figure", "drawn", "file_sha256"]


def _files(d: Path) -> list[str]:
    """The regular files under ``d`` (relative, POSIX), but the run record and the lock."""
    return sorted(
        p.relative_to(d).as_posix()
        for p in d.rglob("*")
        if p.is_file() and not p.is_symlink() and p.name not in ("run.json", LOCK)
    )


def seal(stage: Path, store: ChunkStore | None) -> None:
    """Before publishing: drop chunk files this run neither wrote nor read (left over or copied
    in), and record in ``run.json`` every file the run wrote and each chunk file's, figure's
    and table's sha256 (a later run keeps a file it did not write; a reader checks content)."""
    if store is not None:
        for p in store.strays():
            p.unlink()
    rec = read_record(stage)
    if rec is None:  # the staging directory removed or moved away while the run worked
        raise ConfigError("--out", f"{stage} lost its run record while the run worked; run again")
    carried = set(rec.get("carried") or [])  # the user's files a publish copied in: not ours
    files = [f for f in _files(stage) if f not in carried]
    chunks = {f: file_sha256(stage / f) for f in files if f.startswith("trials/")}
    figures = {f: file_sha256(stage / f) for f in files if f.endswith(".png")}
    tops = [f for f in files if re.fullmatch(r"(cells/[^/]+/)?[^/]+\.parquet", f)]  # table_edits
    tables = {f: file_sha256(stage / f) for f in tops}
    # and every table's shape (a sweep's cells' too): its readers tell a table edited by hand
    shapes = {f: shape(read_table(stage / f)) for f in files if _a_table(f)}
    record = {**rec, "files": files, "chunk_sha256": chunks, "figure_sha256": figures}
    record[EXPORT_KEY] = export_sums(stage, files)  # the GNU Gama export: edited, it is kept
    write_record(stage, {**record, "table_sha256": tables, SHAPE_KEY: shapes})


def _a_table(f: str) -> bool:
    """A table of the results (not a chunk of the ``trials/`` dataset)."""
    return f.endswith(".parquet") and "trials" not in f.split("/")[:-1]


def _recorded_figures(out: Path) -> dict | None:
    """The run record's ``figure_sha256`` of ``out``, or None (no record, or one of a version
    that recorded no figure hashes: its figures are not checked)."""
    rec = read_record(out)
    want = rec.get("figure_sha256") if rec else None
    return want if isinstance(want, dict) else None


#: bytes beyond any figure a run draws (the largest shipped one is 0.4 MB; a 20,000-point
#: network's a few MB): a file this large is not the run's figure, and is not read through
#: (a link to a disk image made ``sim show`` hash gigabytes before its first line)
FIGURE_BYTES = 64 << 20


def _run_drew(p: Path, sha256) -> bool:
    """Whether the file ``p`` (read through a link) has the recorded ``sha256``; OSError
    where it cannot be read. A file larger than :data:`FIGURE_BYTES` is not read."""
    if not isinstance(sha256, str) or p.stat().st_size > FIGURE_BYTES:
        return False
    return file_sha256(p) == sha256


def changed_figure(out: Path, missing_ok: bool = False) -> str | None:
    """Which figure of a finished results directory is not the one its run drew (its sha256,
    read through a symbolic link, differs from the run record's ``figure_sha256``: replaced
    or edited by hand; or missing, unless ``missing_ok``), in a few words, or None. A report
    embeds the figures as they are: a hand-made picture beside the run's tables was read as
    the run's, where a missing one is seen missing. Results of runs that recorded no figure
    hashes (older versions) are not checked."""
    for f, h in sorted((_recorded_figures(out) or {}).items()):
        # a name the run could not have written (absolute, "..", not a PNG): the record was
        # edited, and its path would read a file outside the results (/proc/self/mem)
        if f.startswith("/") or ".." in f.split("/") or not f.endswith(".png") or "\0" in f:
            return (
                f"{out / 'run.json'} names a figure outside its directory: {f!r} (edited by hand?)"
            )
        p = out / f
        if not p.is_file():
            odd = odd_file(p)  # a FIFO in its place: not "missing", and refused where a
            if missing_ok and not odd:  # missing one is let be (it was passed as missing)
                continue
            return (
                f"{p} is {odd}, not the figure its run drew"
                if odd
                else f"{p} is missing (the run drew it)"
            )
        try:
            same = _run_drew(p, h)
        except OSError as e:  # a read that fails (EIO) has no file name of its own to say
            return f"{p} cannot be read ({e.strerror or type(e).__name__})"
        if not same:
            return f"{p} is not the figure its run drew (its sha256 differs: replaced by hand?)"
    return None


def drawn(out: Path, name: str) -> bool:
    """Whether ``out/name`` is a figure the run of ``out`` drew, for a report to embed: a file
    there that its run record lists in ``figure_sha256`` with the sha256 recorded there (a PNG
    put beside the tables of a ``--no-figures`` run, or a sweep's ``sweep.png`` replaced by
    hand, was embedded as the run's). Results of runs that recorded no figure hashes (older
    versions) embed what is there."""
    if not (out / name).is_file():
        return False
    want = _recorded_figures(out)
    if want is None:
        return True
    try:
        return _run_drew(out / name, want.get(name))
    except OSError:
        return False


def damaged_chunks(out: Path) -> str | None:
    """What is wrong with the per-trial chunk files of a finished results directory, against
    the sha256 of each that its run recorded (``run.json`` ``chunk_sha256``), or None when
    they are exactly the run's: a chunk missing, changed or added by hand. Chunks that cannot
    be checked (no run record, or a record without their hashes: edited by hand, or written
    before runs hashed their chunks) are refused too: unchecked trials are never read."""
    rec = read_record(out)
    if rec is None:
        return f"{out / 'run.json'} is missing or not a run record, so the chunks cannot be checked"
    want = rec.get("chunk_sha256")
    if not isinstance(want, dict) or not all(isinstance(v, str) for v in want.values()):
        return f"{out / 'run.json'} does not map the chunk files to their sha256 (edited by hand?)"
    have = sorted(
        f
        for p in (out / "trials").rglob("*")
        if not p.is_dir() and not _litter(f := p.relative_to(out).as_posix())
    )
    for f in sorted(set(want) | set(have)):
        if f not in have:
            return f"{out / f} is missing; run the study again"
        if f not in want:
            # no run removes a file it did not write: re-running would not help
            return f"{out / f} is not one of the run's chunk files (added by hand?): move it away"
        if not (out / f).is_file() or (out / f).is_symlink() or file_sha256(out / f) != want[f]:
            return (
                f"{out / f} is not the file the run wrote (its sha256 differs); run the study again"
            )
    return None


def _litter(f: str) -> bool:
    """Whether ``f`` (under ``trials/``) is a file that the chunk dataset's reader skips, as
    pyarrow's does: a name or a folder of its path starting with ``.`` or ``_`` (a file
    manager's ``.DS_Store``, a notebook's ``.ipynb_checkpoints/``). Opening the folder in
    Finder made ``Results.table("trials")`` refuse the run's chunks as "added by hand"."""
    return any(part.startswith((".", "_")) for part in f.split("/")[1:])


def file_sha256(p: Path) -> str:
    """The sha256 of the file ``p``, read in blocks of 1 MiB."""
    h = hashlib.sha256()
    with open(p, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _foreign(out: Path) -> list[str]:
    """Entries in an earlier results directory that its run did not write (a user's notes, a
    symbolic link, a FIFO, an empty directory, given with a trailing ``/``): they are carried
    into the new results. Results recorded before runs listed their files count as wholly
    written by the suite."""
    rec = read_record(out)
    if not rec or "files" not in rec:
        return []
    if not isinstance(rec["files"], list) or not all(isinstance(f, str) for f in rec["files"]):
        raise ConfigError(
            "--out",
            f"{out / 'run.json'} does not list the files its run wrote (edited by hand?): "
            "move the directory away, or delete it, and run again",
        )
    mine = set(rec["files"]) - set(changed_exports(out, rec))  # an export edited by hand
    keep = []
    for root, dirs, files in os.walk(out):  # a link to a directory is an entry, not followed
        r = Path(root)
        for n in files + [d for d in dirs if (r / d).is_symlink()]:
            f = (r / n).relative_to(out).as_posix()
            if f not in mine and f not in ("run.json", LOCK) and not _left_temporary(f, mine):
                keep.append(f)  # (run.json, .lock: its own, not a copy's inside)
        if r != out and not dirs and not files:
            keep.append(r.relative_to(out).as_posix() + "/")
    return sorted(keep)


#: the temporary of a file the suite writes (:class:`sim.mc.storage.atomic_path`)
_TEMPORARY = re.compile(r"(.*/)?\.([^/]+)\.(\d+)\.tmp")


def _left_temporary(f: str, mine: set) -> bool:
    """Whether ``f`` is the temporary of one of the run's own files (``README.md``) that a
    process killed while writing it left: not the user's, so not carried (``sim report``
    killed mid-README, then ``sim run --overwrite``, carried ``.README.md.<pid>.tmp``)."""
    m = _TEMPORARY.fullmatch(f)
    if m is None or f"{m.group(1) or ''}{m.group(2)}" not in mine | {"run.json"}:
        return False
    return writer_gone(int(m.group(3)))


def _carry(src: Path, dst: Path) -> None:
    """Copy a user's entry ``src`` of an earlier results directory to ``dst`` as what it is: a
    regular file by a hard link (the same file: a log the command itself is writing, ``sim run
    ... --out DIR > DIR/log.txt``, was copied before the run printed a word and its lines went
    into the old file, removed with the old results), else its bytes; a symbolic link's
    target (not followed), an empty directory, and a FIFO, socket or device by a hard link
    (never opened: a FIFO would block)."""
    dst.parent.mkdir(parents=True, exist_ok=True)
    if src.is_symlink():
        os.symlink(os.readlink(src), dst)
    elif src.is_dir():
        dst.mkdir(exist_ok=True)
    elif src.is_file():
        try:
            os.link(src, dst, follow_symlinks=False)
        except OSError:  # another user's file (protected_hardlinks), a mount: its bytes
            shutil.copy2(src, dst)
    else:
        try:
            os.link(src, dst, follow_symlinks=False)
        except OSError as e:
            raise ConfigError(
                "--out",
                f"{src} was not written by sim and cannot be kept ({e.strerror}); move it away "
                "and run again",
            ) from None


def _clash(stage: Path, f: str) -> str | None:
    """The part of the foreign file ``f`` (relative) that the new run's files in ``stage``
    take: ``f`` itself, or a directory of its path that the run writes as a file (a user's
    ``network.png/notes.txt``), else None."""
    parts = Path(f).parts
    for i in range(1, len(parts)):
        q = stage.joinpath(*parts[:i])
        if q.exists() and not q.is_dir():
            return Path(*parts[:i]).as_posix()
    q = stage / f
    if f.endswith("/"):  # an empty directory: only a file of that name takes it
        return f.rstrip("/") if q.exists() and not q.is_dir() else None
    return f if q.exists() or q.is_symlink() else None


def _free_swap(out: Path) -> Path:
    """Where :func:`publish` moves the old results: :func:`swap_dir`, or a new entry in it when
    a run of the same pid (a container's) left old files there it could not remove."""
    old = swap_dir(out)
    if old.is_dir() and not old.is_symlink():
        taken = {p.name for p in old.iterdir()}
        return old / next(f"{out.name}.{k}" for k in count(1) if f"{out.name}.{k}" not in taken)
    return old  # (anything else in the way: os.replace names it)


def _remove_record_last(old: Path) -> None:
    """Remove the replaced results ``old`` (what cannot be removed stays), its run record
    last: a run killed while removing them leaves a directory that still names itself as
    the suite's (or an empty one), which the next publish of that output removes."""
    if old.is_dir() and not old.is_symlink():
        try:
            for p in old.iterdir():
                if p.is_dir() and not p.is_symlink():
                    shutil.rmtree(p, ignore_errors=True)
                elif p.name != "run.json":
                    p.unlink()
            (old / "run.json").unlink(missing_ok=True)
        except OSError:
            pass  # what cannot be removed stays (publish names it)
    shutil.rmtree(old, ignore_errors=True)


def _remove_in_place(out: Path) -> None:
    """Remove the results ``out`` that cannot be moved aside, their run record last and only
    when everything else is gone (an error names what could not be removed): a run killed
    meanwhile leaves results that still name themselves as the suite's, which the next
    publish removes, never a directory of files without a record, which no run replaces."""
    for p in out.iterdir():
        if p.is_dir() and not p.is_symlink():
            shutil.rmtree(p)
        elif p.name != "run.json":
            p.unlink()
    (out / "run.json").unlink(missing_ok=True)
    out.rmdir()


def _drop_stale_swaps(out: Path, mine: Path | None) -> None:
    """Remove the replaced results of ``out`` that an earlier run killed while publishing
    left behind (``.<name>.old.<pid>`` of a process no longer alive, or of this pid: a
    container's): only a directory holding a run record, or an empty one, and only when
    every file of the user's in it is in ``out``: copied there before it was moved aside, or,
    when a run of another config replaced the unfinished one, now (else it is named)."""
    pat = re.compile(re.escape(f".{out.name}.old.") + r"(\d+)")
    for d in out.parent.iterdir():
        m = pat.fullmatch(d.name)
        if not m or d == mine or d.is_symlink() or not d.is_dir():
            continue
        if not writer_gone(int(m.group(1))):
            continue  # another run may be removing it now
        if read_record(d) is not None:
            lost: list[str] = []
            try:
                lost = [f for f in _foreign(d) if not _present(out / f)]
                for f in lost:  # moved aside before the copies were published: bring them
                    if _clash(out, f) is None:
                        _carry(d / f, out / f)
                lost = [f for f in lost if not _present(out / f)]
            except ConfigError:  # its record does not say which files are the user's
                lost = ["run.json"]
            except OSError:  # kept, and named below
                lost = [f for f in lost if not _present(out / f)] or ["run.json"]
            if lost:
                say(
                    f"sim: note: {d} holds results replaced by a run that was killed, with "
                    f"{d / lost[0]}, which is not in {out}: move what you need out of it",
                )
                continue
            _remove_record_last(d)
        elif not any(d.iterdir()):
            d.rmdir()


def _present(p: Path) -> bool:
    return p.is_symlink() or p.exists()


def publish(stage: Path, out: Path) -> None:
    """Replace ``out`` (checked: ours or absent) by the finished staging directory, keeping the
    files in ``out`` that the suite did not write; ``<out>/.lock`` is held throughout (the old
    results' and then the staging directory's, :mod:`sim.mc.swap`) and removed at the end."""
    held = hold_old(out, str(out)) if out.is_dir() and not out.is_symlink() else None
    try:
        _publish(stage, out)
    finally:
        with contextlib.suppress(OSError):  # (EIO, EACCES: a published run does not fail for
            (out / LOCK).unlink(missing_ok=True)  # it; the next run ignores it) still held
        if held is not None:
            held.release()


def _publish(stage: Path, out: Path) -> None:
    for tmp in stage.rglob("*.tmp"):
        tmp.unlink(missing_ok=True)
    keep = _foreign(out) if out.is_dir() else []
    rec = read_record(stage)
    if rec is None:  # unreadable now (EIO), or removed: an AttributeError ended the run (exit 3)
        raise ConfigError(
            "--out", f"{stage / 'run.json'} cannot be read as the run's record; run again"
        )
    for f in set(rec.get("carried") or []) & set(keep):  # copied by a publish cut short
        q = stage / f
        if (q.is_symlink() or q.exists()) and not q.is_dir():
            q.unlink()  # (the user's own is still in out): copied again below
    clash = [c for f in keep if (c := _clash(stage, f))]
    if clash and (what := changed_exports(out).get(clash[0])):
        raise ConfigError("--out", changed_words(out, clash[0], what))
    if clash:
        raise ConfigError(
            "--out",
            f"{out / clash[0]} was not written by sim but the new run writes a file of that "
            "name; move it away and run again",
        )
    # named before copying: a resume after a kill here knows the copies for copies; and the
    # results this run replaces, by their run record's sha256: a kill right after the swap
    # below leaves them in the staging directory, where the next run must know them for what
    # they are (:mod:`sim.mc.left_behind`), not for an unfinished run of another config
    try:
        replaced = file_sha256(out / "run.json") if read_record(out) is not None else None
    except OSError:  # (read a moment ago) a mark the run does without
        replaced = None
    if keep or replaced:
        marks = {"carried": keep, "replaced": replaced}
        write_record(stage, {**rec, **{k: v for k, v in marks.items() if v}})
    for f in keep:
        _carry(out / f, stage / f)
    old = _free_swap(out) if out.exists() else None
    if old is None:
        os.replace(stage, out)
    elif _exchange(stage, out):  # out now holds the new results, stage the old ones
        try:
            os.replace(stage, old)
        except OSError:  # (EIO) the new results are published: the old ones are removed
            old = stage  # where they are, below (an error here ended the published run in
            # exit 2, and left them as an unfinished run of another config that blocked the
            # next run without --overwrite)
    else:
        try:
            os.replace(out, old)
        except OSError as e:
            if e.errno != errno.EXDEV or mounts_under(out):  # (never empty a mount in it)
                raise
            # out cannot be renamed: a directory of an overlay's lower layer (the project in a
            # container's image: "Invalid cross-device link" after every chunk was computed,
            # at each try). Removed instead: what the user put there is copied in the staging
            # directory, and a kill now leaves that finished run to be published by the next.
            _remove_in_place(out)
            old = None
        os.replace(stage, out)
    _drop_stale_swaps(out, old)
    if old is not None:
        _remove_record_last(old)
    if replaced and not (stage.exists() or stage.is_symlink()):  # the old results are no
        # longer where the mark is looked for: dropped, so that a run made over identical
        # results has the record of the same run made fresh (a kill before this keeps it)
        with contextlib.suppress(OSError):
            write_record(out, {**rec, **({"carried": keep} if keep else {})})
    if old is None:
        return
    if old.exists() or old.is_symlink():  # a file or directory of the old results that this
        # user may not remove: they are not lost, but say where (a hidden directory)
        left = next(iter(sorted(old.rglob("*"), key=lambda q: -len(q.parts))), old)
        say(
            f"sim: note: the replaced results are kept in {old} ({left} could not be removed)",
        )
