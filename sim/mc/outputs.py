"""Results directories the suite owns: the output checks, the locked staging directory, and
publishing a finished run.

Nothing the suite did not write is ever deleted or replaced: ``--out`` must be new, empty, or
an earlier results directory (its ``run.json``), and not inside another run's directory; a run
works in a locked staging directory ``.<out>.partial/`` (resumed after a kill, named when
damaged) that replaces ``<out>`` only when everything succeeded, keeping the files there that
the suite did not write. ``run.json`` records the config, the code hash, every file the run
wrote and each chunk file's sha256.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import sys
import unicodedata
from itertools import count
from pathlib import Path

from sim.mc.config import ConfigError
from sim.mc.runner import ChunkStore
from sim.mc.storage import LOCK, Locked, NotALock, StageLock, read_record, write_record

__all__ = [
    "check_out",
    "prepare_stage",
    "drop_stage",
    "seal",
    "publish",
    "damaged_chunks",
    "name_problem",
    "stage_dir",
    "swap_dir",
]


def name_problem(text: str) -> str | None:
    """Why a path given on the command line cannot name a file of the suite, in a few words
    (None: it can): empty or blank, a control character or a line break, a leading ``~``
    the shell left unexpanded, or bytes that are not UTF-8 text (a Latin-1 name, or any
    non-ASCII name in a C locale without UTF-8 mode, which Python keeps as surrogate escapes;
    the suite writes every path it records as UTF-8, so such a run would fail at its end)."""
    if not text.strip():
        return "is empty"
    if any(unicodedata.category(c) in ("Cc", "Zl", "Zp") for c in text):
        return "contains a control character or a line break"
    if any(unicodedata.category(c) == "Cs" for c in text):
        return "contains bytes that are not UTF-8 text (a non-UTF-8 name or locale)"
    if text.startswith("~"):  # --out=~/x: the shell expands no ~ after "=", and a directory
        return (  # named "~" was made here, which "rm -rf ~" would then mistake for home
            "starts with '~', which the shell did not expand (it does not after '='): use "
            "$HOME, or a space for the '=' (./~ names a file that starts with ~)"
        )
    return None


def _name_max(d: Path) -> int:
    """The file system's longest file name (bytes) in ``d`` or its nearest existing parent."""
    for p in (d, *d.parents):
        if p.is_dir():
            try:
                return os.pathconf(p, "PC_NAME_MAX")
            except (OSError, ValueError):
                break
    return 255


STAGE_SUFFIX = ".partial"


def stage_dir(out: Path) -> Path:
    """The run's staging directory next to ``out``: ``.<name>.partial`` (resumed after a kill)."""
    return out.parent / f".{out.name}{STAGE_SUFFIX}"


def results_dirs(results: Path) -> list[Path]:
    """The entries directly under ``results`` that may hold a study's results: every one but
    a run's hidden working directories (its staging :func:`stage_dir`, ``.<name>.partial``,
    and :func:`swap_dir`, ``.<name>.old.<pid>``), which hold unfinished or replaced results
    (``sim report`` listed an interrupted run's staging directory as a study of its own)."""
    return [p for p in Path(results).iterdir() if not p.name.startswith(".")]


def swap_dir(out: Path) -> Path:
    """Where :func:`publish` moves the old results of ``out`` while it swaps the new ones in:
    ``.<name>.old.<pid>``."""
    return out.parent / f".{out.name}.old.{os.getpid()}"


def _check_name_length(out: Path, shown: str) -> None:
    """The run works next to ``out`` in :func:`stage_dir` and swaps the old results through
    :func:`swap_dir`: both names must fit the file system (a study file name of 247
    characters passed, then failed naming the staging directory)."""
    longest = max(
        len(d.name.encode("utf-8", "surrogateescape")) for d in (stage_dir(out), swap_dir(out))
    )
    limit = _name_max(out.parent)
    if longest > limit:
        raise ConfigError(
            "--out",
            f"{shown}: its name needs {longest} bytes with the run's staging suffix, over the "
            f"file system's {limit}: choose a shorter --out (or study file name)",
        )


def check_out(out: Path, shown: str, record: dict, overwrite: bool) -> None:
    """Refuse an output path the suite did not write (with or without ``--overwrite``) and,
    without ``--overwrite``, results of a different config or code version."""

    if not out.name or out == out.parent:
        raise ConfigError("--out", f"{shown} is not a directory the suite can write into")
    _check_name_length(out, shown)
    _check_not_nested(out, shown)
    if out.is_symlink():
        raise ConfigError("--out", f"{shown} is a symbolic link; sim never replaces it")
    if not out.exists():
        return
    if not out.is_dir():
        raise ConfigError(
            "--out",
            f"{shown} is a file, not a results directory; sim never "
            "replaces it (choose another --out)",
        )
    try:  # the run replaces out: a shell inside it would be left in a deleted directory
        cwd, o = Path(os.getcwd()).resolve(), out.resolve()
    except (OSError, RuntimeError):
        cwd = o = None
    if cwd is not None and (cwd == o or o in cwd.parents):
        raise ConfigError(
            "--out",
            f"{shown} holds the working directory, and the run replaces it (the shell would be "
            f"left in a deleted directory): run from outside it (cd {o.parent})",
        )
    old = read_record(out)
    if old is None:
        if any(out.iterdir()):
            raise ConfigError(
                "--out",
                f"{shown} holds files but no sim run record (run.json); "
                "sim never replaces it, with or without --overwrite",
            )
        return
    if _same(old, record) or overwrite:
        return
    raise ConfigError(
        "--out", f"{shown} holds results of {_differs(old, record)}; use --overwrite to replace it"
    )


def _differs(old: dict, record: dict) -> str:
    """How the run record ``old`` differs from this run's: another study is named (it was
    "a different config", and --overwrite then replaced brown_table1's results with a
    network's), else a different config or code version."""
    mine = record["config"].get("study")
    theirs = old.get("config", {}).get("study") if isinstance(old.get("config"), dict) else None
    if theirs != mine:
        return f"another study ({theirs!r}; this run is {mine!r})"
    same = old.get("config") == record["config"]
    return "a different code version" if same else "a different config"


def _check_not_nested(out: Path, shown: str) -> None:
    """Refuse an output directory inside another run's results or staging directory (its
    ``run.json``, its ``.partial`` staging directory or its ``trials/`` dataset): a re-run of
    that study would replace it, and chunk files there would join that run's trials."""
    for up in out.parents:
        if up == up.parent:
            break
        if (up / "run.json").is_file() or up.name.endswith(STAGE_SUFFIX) or up.name == "trials":
            raise ConfigError(
                "--out",
                f"{shown} lies inside {up}, which belongs to another run; choose a directory "
                "outside every results directory",
            )


def _damage(stage: Path) -> str | None:
    """What is wrong with a staging directory's chunk store, if anything: a chunk path that is
    not a regular file (a directory, a link)."""
    t = stage / "trials"
    if t.is_symlink() or (t.exists() and not t.is_dir()):
        return f"{t} is not a directory"
    if t.is_dir():
        for p in sorted(t.rglob("*")):
            if p.is_symlink() or (p.name.startswith("chunk-") and not p.is_file()):
                return f"{p} is not a chunk file"
    return None


def _same(a: dict | None, b: dict) -> bool:
    return bool(a) and a.get("config") == b["config"] and a.get("code_hash") == b["code_hash"]


def _clear(stage: Path) -> None:
    """Remove everything in a staging directory we hold the lock of, but the lock file."""

    for p in stage.iterdir():
        if p.name == LOCK:
            continue
        if p.is_dir() and not p.is_symlink():
            shutil.rmtree(p)
        else:
            p.unlink()


def _chunks(stage: Path) -> int:
    t = stage / "trials"
    return sum(1 for _ in t.rglob("chunk-*.parquet")) if t.is_dir() else 0


def prepare_stage(stage: Path, out: Path, shown: str, record: dict, overwrite: bool):
    """Lock the staging directory and make it hold ``record``. Returns ``(lock, resumed)``."""

    if stage.is_symlink() or (stage.exists() and not stage.is_dir()):
        raise ConfigError(
            "--out",
            f"{stage} is in the way (not a staging directory of sim); sim never replaces it",
        )
    if (
        stage.is_dir()
        and read_record(stage) is None
        and not (stage / LOCK).exists()
        and any(stage.iterdir())
    ):
        raise ConfigError(
            "--out", f"{stage} holds files but no sim run record; sim never replaces it"
        )
    lock = StageLock(stage)
    try:
        lock.acquire()
    except Locked as e:
        who = f"pid {e.pid}" if e.pid else "another process"
        raise ConfigError(
            "--out",
            f"{shown} is being written by a running sim ({who}); wait "
            "for it to finish or choose another --out",
        ) from None
    except NotALock as e:
        raise ConfigError(
            "--out", f"{e.path} is not a lock file of sim (a link or a pipe); move it away"
        ) from None
    except OSError as e:
        raise ConfigError("--out", f"cannot write to {out.parent}: {e.strerror}") from None
    try:
        damage = _damage(stage) if stage.is_dir() else None
        if damage is not None:
            if not overwrite:
                raise ConfigError(
                    "--out",
                    f"the staging directory of {shown} is damaged ({damage}); "
                    "run again with --overwrite to replace it",
                )
            _clear(stage)
        old = read_record(stage)
        resumed = 0
        if old is not None and _same(old, record) and not old.get("failed"):
            resumed = _chunks(stage)
        elif old is not None and _same(old, record):
            resumed = _chunks(stage)  # a failed run of the same command: try again, resume
        elif old is None or old.get("failed") or overwrite:
            _clear(stage)  # ours (locked, a record or a lock file), and not resumable
        else:
            raise ConfigError(
                "--out",
                f"{stage} holds an unfinished run of {_differs(old, record)}; run that "
                "command again to finish it, or use --overwrite to replace it",
            )
        for tmp in stage.rglob("*.tmp"):  # a write cut short by a kill
            tmp.unlink(missing_ok=True)
        carried = (read_record(stage) or {}).get("carried")  # see publish()
        write_record(stage, {**record, "carried": carried} if carried else record)
    except BaseException:
        drop_stage(stage, lock)
        raise
    return lock, resumed


def drop_stage(stage: Path, lock, reason: str | None = None) -> None:
    """After a failure: remove a staging directory with no finished chunk; otherwise mark it
    failed (so the corrected command may replace it) and keep it for resumption."""

    try:
        if _chunks(stage) == 0:
            shutil.rmtree(stage, ignore_errors=True)
        elif reason is not None and (rec := read_record(stage)) is not None:
            write_record(stage, {**rec, "failed": reason})
    finally:
        lock.release()


def _files(d: Path) -> list[str]:
    """The regular files under ``d`` (relative, POSIX), but the run record and the lock."""
    return sorted(
        p.relative_to(d).as_posix()
        for p in d.rglob("*")
        if p.is_file() and not p.is_symlink() and p.name not in ("run.json", LOCK)
    )


def seal(stage: Path, store: ChunkStore | None) -> None:
    """Before publishing: drop chunk files this run neither wrote nor read (left over or copied
    in), and record in ``run.json`` every file the run wrote and each chunk file's sha256, so
    that a later run keeps a file it did not write and a reader can check a chunk's content."""
    if store is not None:
        for p in store.strays():
            p.unlink()
    rec = read_record(stage)
    if rec is None:  # the staging directory removed or moved away while the run worked
        raise ConfigError("--out", f"{stage} lost its run record while the run worked; run again")
    carried = set(rec.get("carried") or [])  # the user's files a publish copied in: not ours
    files = [f for f in _files(stage) if f not in carried]
    chunks = {f: _sha256(stage / f) for f in files if f.startswith("trials/")}
    write_record(stage, {**rec, "files": files, "chunk_sha256": chunks})


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
        p.relative_to(out).as_posix() for p in (out / "trials").rglob("*") if not p.is_dir()
    )
    for f in sorted(set(want) | set(have)):
        if f not in have:
            return f"{out / f} is missing; run the study again"
        if f not in want:
            # no run removes a file it did not write: re-running would not help
            return f"{out / f} is not one of the run's chunk files (added by hand?): move it away"
        if not (out / f).is_file() or (out / f).is_symlink() or _sha256(out / f) != want[f]:
            return (
                f"{out / f} is not the file the run wrote (its sha256 differs); run the study again"
            )
    return None


def _sha256(p: Path) -> str:
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
    mine = set(rec["files"])
    keep = []
    for root, dirs, files in os.walk(out):  # a link to a directory is an entry, not followed
        r = Path(root)
        for n in files + [d for d in dirs if (r / d).is_symlink()]:
            f = (r / n).relative_to(out).as_posix()
            if f not in mine and f not in ("run.json", LOCK):  # its own, not a copy's inside
                keep.append(f)
        if r != out and not dirs and not files:
            keep.append(r.relative_to(out).as_posix() + "/")
    return sorted(keep)


def _carry(src: Path, dst: Path) -> None:
    """Copy a user's entry ``src`` of an earlier results directory to ``dst`` as what it is: a
    regular file's bytes, a symbolic link's target (not followed), an empty directory, and a
    FIFO, socket or device by a hard link (never opened: a FIFO would block)."""
    dst.parent.mkdir(parents=True, exist_ok=True)
    if src.is_symlink():
        os.symlink(os.readlink(src), dst)
    elif src.is_dir():
        dst.mkdir(exist_ok=True)
    elif src.is_file():
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


def publish(stage: Path, out: Path) -> None:
    """Replace ``out`` (checked: ours or absent) by the finished staging directory, keeping the
    files in ``out`` that the suite did not write."""
    for tmp in stage.rglob("*.tmp"):
        tmp.unlink(missing_ok=True)
    keep = _foreign(out) if out.is_dir() else []
    rec = read_record(stage)
    for f in set(rec.get("carried") or []) & set(keep):  # copied by a publish cut short
        q = stage / f
        if (q.is_symlink() or q.exists()) and not q.is_dir():
            q.unlink()  # (the user's own is still in out): copied again below
    clash = [c for f in keep if (c := _clash(stage, f))]
    if clash:
        raise ConfigError(
            "--out",
            f"{out / clash[0]} was not written by sim but the new run writes a file of that "
            "name; move it away and run again",
        )
    if keep:  # named before copying: a resume after a kill here knows the copies for copies
        write_record(stage, {**rec, "carried": keep})
    for f in keep:
        _carry(out / f, stage / f)
    old = _free_swap(out) if out.exists() else None
    if old is not None:
        os.replace(out, old)
    os.replace(stage, out)
    (out / LOCK).unlink(missing_ok=True)  # we still hold it through the open descriptor
    if old is None:
        return
    shutil.rmtree(old, ignore_errors=True)
    if old.exists() or old.is_symlink():  # a file or directory of the old results that this
        # user may not remove: they are not lost, but say where (a hidden directory)
        left = next(iter(sorted(old.rglob("*"), key=lambda q: -len(q.parts))), old)
        print(
            f"sim: note: the replaced results are kept in {old} ({left} could not be removed)",
            file=sys.stderr,
        )
