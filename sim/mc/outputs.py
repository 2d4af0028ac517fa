"""Results directories the suite owns: the output checks, the locked staging directory, and
publishing a finished run.

Nothing the suite did not write is ever deleted or replaced: ``--out`` must be new, empty, or
an earlier results directory (its ``run.json``), and not inside another run's directory; a run
works in a locked staging directory ``.<out>.partial/`` (resumed after a kill, named when
damaged) that replaces ``<out>`` only when everything succeeded, keeping the files there that
the suite did not write. ``run.json`` records the config, the code hash, every file the run
wrote and each chunk file's sha256 (sealing and publishing: :mod:`sim.mc.publish`).
"""

from __future__ import annotations

import errno
import os
import pwd
import shutil
import stat
from pathlib import Path

from sim.mc.config import ConfigError, config_changes
from sim.mc.path_names import STAGE_SUFFIX, name_problem, stage_dir
from sim.mc.paths import is_chunk_store, link_problem, mount_point, mounts_under
from sim.mc.record_text import finish_words, record_problem
from sim.mc.storage import LOCK, Locked, NotALock, StageLock, read_record, write_record
from sim.mc.swap import busy_words, holder, refuse_if_publishing, refuse_if_running_under
from sim.mc.sweep import reordered

__all__ = [
    "check_out",
    "prepare_stage",
    "drop_stage",
    "name_problem",
    "stage_dir",
    "swap_dir",
]


def _name_max(d: Path) -> int:
    """The file system's longest file name (bytes) in ``d`` or its nearest existing parent."""
    for p in (d, *d.parents):
        if p.is_dir():
            try:
                return os.pathconf(p, "PC_NAME_MAX")
            except (OSError, ValueError):
                break
    return 255


def results_dirs(results: Path) -> list[Path]:
    """The entries directly under ``results`` that may hold a study's results: every one but
    a run's hidden working directories (its staging :func:`stage_dir`, ``.<name>.partial``,
    and :func:`swap_dir`, ``.<name>.old.<pid>``), which hold unfinished or replaced results
    (``sim report`` listed an interrupted run's staging directory as a study of its own)."""
    return [p for p in Path(results).iterdir() if not p.name.startswith(".")]


def swap_dir(out: Path) -> Path:
    """Where :func:`publish` keeps the old results of ``out`` during the swap: ``.<name>.old.<pid>``."""
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
        raise ConfigError(  # what to do said: the batch named --results, and nothing else
            "--out",
            f"{shown} is a symbolic link; sim never replaces it (choose another --out, or "
            "remove the link: what it leads to is kept)",
        )
    if not out.exists():  # café typed beside a café of the other Unicode form (doors25a):
        if (why := link_problem(out)) is not None:  # two results directories printed alike
            raise ConfigError("--out", f"{shown} {why}")
        return
    if not out.is_dir():
        raise ConfigError(
            "--out",
            f"{shown} is a file, not a results directory; sim never "
            "replaces it (choose another --out)",
        )
    refuse_if_publishing(out, shown)
    if mount_point(out):  # renamed at the run's end: EBUSY after every chunk was computed
        raise ConfigError(
            "--out",
            f"{shown} is a mount point, which the system does not let a run replace at its end: "
            "choose a directory inside it",
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
    try:  # another user's directory (umask 077): the API raised PermissionError here
        old = read_record(out)
        filled = any(out.iterdir())
    except OSError as e:
        raise ConfigError(
            "--out", f"{shown} cannot be read ({e.strerror}; another user's?): choose another --out"
        ) from None
    if old is not None and (mounts := mounts_under(out)):
        raise ConfigError(
            "--out",
            f"{shown} holds a mount point, {mounts[0]}: the run replaces its output directory, "
            "which would move that file system aside and empty it; unmount it or move it away",
        )
    if old is None:
        if filled:
            names = refuse_if_running_under(out, shown)  # a bounded look (R45), no walk
            held = f" (it holds {names[0]!r}{' and more' if names[1:] else ''})" if names else ""
            raise ConfigError(
                "--out",
                f"{shown} holds files but {record_problem(out)}; "  # a damaged one named
                f"sim never replaces it, with or without --overwrite{held}",
            )
        _check_replaceable(out, shown)
        return
    if _same(old, record) or overwrite:
        _check_replaceable(out, shown)
        return
    raise ConfigError(
        "--out", f"{shown} holds results of {_differs(old, record)}; use --overwrite to replace it"
    )


def _check_replaceable(out: Path, shown: str) -> None:
    """Refuse, before any work, an existing ``out`` that this user may not replace at the
    run's end (a rename in its parent): a parent not writable by this user, or one with the
    sticky bit (``/tmp``, a shared results folder) when neither ``out`` nor the parent is this
    user's. The run of another user's results computed every chunk, then ended "Operation not
    permitted: OUT" and left its staging directory beside them."""
    parent = out.parent
    try:
        st = parent.stat()
        owner = out.stat().st_uid
    except OSError:
        return  # (what cannot be read is named where it is read)
    me = os.geteuid()
    ids = os.access in os.supports_effective_ids
    if not os.access(parent, os.W_OK | os.X_OK, effective_ids=ids):
        why = f"you may not write in {parent}"
    elif st.st_mode & stat.S_ISVTX and me != 0 and me not in (owner, st.st_uid):
        why = f"it is {_owner(out)}'s, and {parent} has the sticky bit: only they may rename it"
    else:
        return
    raise ConfigError(
        "--out",
        f"{shown} cannot be replaced by this run ({why}; a run replaces its output directory at "
        "its end): choose another --out",
    )


def _differs(old: dict, record: dict) -> str:
    """How the run record ``old`` differs from this run's: another study is named (it was
    "a different config", and --overwrite then replaced brown_table1's results with a
    network's), else a different config or code version."""
    mine = record["config"].get("study")
    theirs = old.get("config", {}).get("study") if isinstance(old.get("config"), dict) else None
    if theirs != mine:
        return f"another study ({theirs!r}; this run is {mine!r})"
    ca, cb = old.get("config"), record["config"]
    if not isinstance(ca, dict):
        return "a different config"
    if ca == cb:
        order = reordered(old, record)
        return f"a different config: {order}" if order else "a different code version"
    return f"a different config: {config_changes(ca, cb)}"


def _check_not_nested(out: Path, shown: str) -> None:
    """Refuse an output directory inside another run's results or staging directory (its
    ``run.json``, its ``.partial`` staging directory or its ``trials/`` dataset): a re-run of
    that study would replace it, and chunk files there would join that run's trials. So is
    one inside the output of a run still working (its staging directory beside it). The
    directories are those the path names and those the system reaches through its links
    (``--out lnk/x`` with ``lnk`` a link into a run's ``trials/``)."""
    try:
        real = Path(os.path.realpath(out.parent))
    except (OSError, ValueError):
        real = out.parent
    for up in dict.fromkeys([*out.parents, real, *real.parents]):
        if up == up.parent:  # the root, or "." of a relative path (its real path follows)
            continue
        if (up / "run.json").is_file() or up.name.endswith(STAGE_SUFFIX) or is_chunk_store(up):
            raise ConfigError(
                "--out",
                f"{shown} lies inside {up}, which belongs to another run; choose a directory "
                "outside every results directory",
            )
        if (s := stage_dir(up)).is_dir() and not s.is_symlink():  # a run writing up (doors27b):
            raise ConfigError(  # it computed every chunk, then refused to replace up (this run
                "--out",  # had made it, "holds files but no sim run record")
                f"{shown} lies inside {up}, the output of a run that is running or unfinished "
                f"({s}); choose a directory outside every results directory",
            )


def _damage(stage: Path) -> str | None:
    """What is wrong with a staging directory's chunk store, if anything: a chunk path that is
    not a regular file (a directory, a link), or a part's path (``part-<p>``) that is not a
    directory (it was "File exists: .../trials/part-0", naming neither the damage nor its
    remedy), in the run's store or in a sweep cell's; a sweep's ``cells`` or one of its cells
    that is not a directory (it was "Not a directory: .../cells/cell0000_r0" or "File exists:
    .../cells/cell0001_r0")."""
    cells = stage / "cells"
    if cells.is_symlink() or (cells.exists() and not cells.is_dir()):
        return f"{cells} is not a directory"
    for p in sorted(cells.iterdir()) if cells.is_dir() else []:
        if p.is_symlink() or not p.is_dir():
            return f"{p} is not a directory"
    for t in _stores(stage):
        if t.is_symlink() or (t.exists() and not t.is_dir()):
            return f"{t} is not a directory"
        if t.is_dir():
            for p in sorted(t.glob("part-*")):
                if p.is_symlink() or not p.is_dir():
                    return f"{p} is not a directory"
            for p in sorted(t.rglob("*")):
                if p.is_symlink() or (p.name.startswith("chunk-") and not p.is_file()):
                    return f"{p} is not a chunk file"
    return None


def _same(a: dict | None, b: dict) -> bool:  # a sweep's keys reordered: other cells
    ok = bool(a) and a.get("config") == b["config"] and a.get("code_hash") == b["code_hash"]
    return ok and not reordered(a, b)


def _clear(stage: Path) -> None:
    """Remove everything in a staging directory we hold the lock of, but the lock file."""

    for p in stage.iterdir():
        if p.name == LOCK:
            continue
        if p.is_dir() and not p.is_symlink():
            shutil.rmtree(p)
        else:
            p.unlink()


def _stores(stage: Path) -> list[Path]:
    """The chunk stores of a staging directory: its ``trials/`` and, for a ``[sweep]``, each
    cell's ``cells/<label>/trials/`` (an interrupted sweep's finished cells were counted as
    no chunk at all, and its staging directory deleted: nothing to resume)."""
    cells = stage / "cells"
    inner = sorted(cells.glob("*/trials")) if cells.is_dir() and not cells.is_symlink() else []
    return [stage / "trials", *inner]


def _chunks(stage: Path) -> int:
    return sum(
        sum(1 for _ in t.rglob("chunk-*.parquet")) if t.is_dir() else 0 for t in _stores(stage)
    )


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
        raise ConfigError("--out", busy_words(shown, e.pid)) from None
    except NotALock as e:
        raise ConfigError(
            "--out",
            f"{e.path} is not a lock file of sim (a link, a pipe or a directory); move it away",
        ) from None
    except OSError as e:
        if lock.created:  # made by this call, holding only its lock file: no litter left
            shutil.rmtree(stage, ignore_errors=True)
        raise ConfigError("--out", _not_lockable(stage, out, shown, e)) from None
    try:
        refuse_if_publishing(out, shown)  # the staging name freed by its swap (sim.mc.swap)
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
            how = _differs(old, record)
            finish = (  # another code version: only that version can finish it, not this one
                "this version of the suite cannot finish it; "
                if how == "a different code version"
                else finish_words(old.get("config"), record["config"])
            )
            raise ConfigError(
                "--out",
                f"{stage} holds an unfinished run of {how}; {finish}use --overwrite to replace it",
            )
        for tmp in stage.rglob("*.tmp"):  # a write cut short by a kill
            tmp.unlink(missing_ok=True)
        carried = (read_record(stage) or {}).get("carried")  # see publish()
        write_record(stage, {**record, "carried": carried} if carried else record)
    except BaseException:
        drop_stage(stage, lock)
        raise
    return lock, resumed


def _owner(p: Path) -> str:
    """The user who owns ``p``, by name where the system knows it (else ``uid N``)."""
    try:
        uid = p.lstat().st_uid
    except OSError:
        return "another user"
    try:
        return pwd.getpwuid(uid).pw_name
    except (KeyError, OverflowError):
        return f"uid {uid}"


def _uid(p: Path) -> int | None:
    try:
        return p.lstat().st_uid
    except OSError:
        return None


def _not_lockable(stage: Path, out: Path, shown: str, e: OSError) -> str:
    """Why the staging directory could not be locked, in words: another user's run writing
    it now, or another user's unfinished run (its staging directory or lock file not ours to
    write: it was "cannot write to <parent>: Permission denied", naming the wrong directory
    and no process), else the directory that could not be written."""
    if e.errno in (errno.EACCES, errno.EPERM) and stage.is_dir() and not stage.is_symlink():
        held, pid = holder(stage / LOCK)
        if held:
            who = f"pid {pid}" if pid else "another process"
            return (
                f"{shown} is being written by a running sim ({who} of user "
                f"{_owner(stage / LOCK)}); "
                "wait for it to finish or choose another --out"
            )
        me, lock = os.geteuid(), _uid(stage / LOCK)
        if _uid(stage) == me and lock in (me, None):  # doors25a: it was "another user (me)"
            what = stage / LOCK if lock is not None else stage  # made read-only by its owner
            return (
                f"{what} is yours but cannot be written ({e.strerror}): chmod u+w it or remove it"
            )
        return (
            f"{stage} holds an unfinished run of another user ({_owner(stage)}) that you may "
            f"not write in ({e.strerror}): ask them to finish or remove it, or choose another "
            "--out"
        )
    nolock = e.errno in (errno.ENOLCK, errno.ENOTSUP, errno.ENOSYS)  # NFS without its lockd
    return f"cannot {'lock a file in' if nolock else 'write to'} {out.parent}: {e.strerror}"


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
