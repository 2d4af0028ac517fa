"""Parquet result files with provenance, written atomically.

Every file carries, in its schema metadata under ``sim.provenance``, a JSON object with
the resolved study configuration, the root seed, package versions and the git commit
of the code that produced it. Writes go to a temporary file in the same directory and
are renamed into place, so a reader never sees a half-written file. No timestamps are
stored, so the same code and config give byte-identical files.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import hashlib
import json
import os
import platform
import re
import stat
import subprocess
import sys
from functools import lru_cache
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any, Mapping

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from sim.mc import tolerance
from sim.mc.codehash import (  # code no study result depends on
    NOT_STUDY_CODE,
    not_study_code,
    study_code_hash,
    study_files,
)
from sim.mc.finite import NonFiniteError, check_finite_table
from sim.mc.pids import writer_gone

__all__ = [
    "provenance",
    "write_table",
    "read_table",
    "read_provenance",
    "read_tolerances",
    "atomic_path",
    "umask_problem",
    "read_record",
    "regular_text",
    "StageLock",
    "NotALock",
    "NonFiniteError",
]

_KEY = b"sim.provenance"


@lru_cache(maxsize=None)
def git_commit(study: str | None = None) -> str:
    """The last commit that changed the code or definition of ``study`` (its modules, see
    :mod:`sim.mc.codehash`, its study file and ``pyproject.toml``; without a study: all of
    ``sim/`` but the benchmark, and ``studies/``), ``-dirty`` if they have uncommitted changes.
    A commit of results, or of another study's code, does not change it, so re-running gives
    byte-identical files."""
    root = Path(__file__).resolve().parents[2]
    if study is None:
        paths = [
            "sim",
            "studies",
            "pyproject.toml",
            *(f":(exclude)sim/{f}" for f in NOT_STUDY_CODE),
        ]
    else:
        paths = [p.relative_to(root).as_posix() for p in study_files(study)]
        paths += [f"studies/{study}.toml", "pyproject.toml"]
    try:
        head = subprocess.run(
            ["git", "log", "-1", "--format=%H", "--", *paths],
            cwd=root,
            capture_output=True,
            encoding="utf-8",  # not the locale's (git prints hashes; -X warn_default_encoding)
            errors="replace",  # a file name git prints in Latin-1, a wrapper's bytes
            timeout=10,
        )
        if head.returncode != 0 or not re.fullmatch(
            r"[0-9a-f]{40}|[0-9a-f]{64}", head.stdout.strip()
        ):
            return "unknown"  # no commit, or not what git prints (a wrapper's words)
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--", *paths],
            cwd=root,
            capture_output=True,
            encoding="utf-8",  # not the locale's (git prints hashes; -X warn_default_encoding)
            errors="replace",  # a file name git prints in Latin-1, a wrapper's bytes
            timeout=10,
        ).stdout.strip()
        return head.stdout.strip() + ("-dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError, ValueError):
        return "unknown"


def code_hash(study: str | None = None) -> str:
    """sha256 of the code ``study`` depends on (:func:`sim.mc.codehash.study_code_hash`), or,
    without a study, of the library's source (every ``sim/**/*.py`` but the benchmark)."""
    if study is not None:
        return study_code_hash(study)
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256()
    for f in sorted(root.rglob("*.py")):
        if not_study_code(f.relative_to(root).as_posix()):
            continue
        h.update(str(f.relative_to(root)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:16]


def versions() -> dict[str, str]:
    """Versions of Python and of every package a result can depend on (``not installed`` for
    the optional ones: without numba the NumPy engine runs)."""
    out = {"python": sys.version.split()[0]}
    for pkg in ("numpy", "scipy", "pyarrow", "matplotlib", "emcee", "numba", "tqdm"):
        try:
            out[pkg] = version(pkg)
        except PackageNotFoundError:
            out[pkg] = "not installed"
    return out


def config_hash(config: Mapping[str, Any] | None, code: str | None = None) -> str:
    """sha256 (16 hex digits) of a resolved configuration and a code hash: what a chunk file
    and a run record are checked against."""
    text = json.dumps({"config": config, "code": code}, sort_keys=True, default=_jsonable)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


#: the variables of the environment that choose a result's numerical path
PATH_VARIABLES = ("OPENBLAS_CORETYPE", "SIM_NO_JIT", "NUMBA_DISABLE_JIT")


def numerics() -> dict[str, str]:
    """The machine and numerical path a result was computed on (``make verify`` names both:
    docs/reproducibility.md): system, CPU architecture, and ``OPENBLAS_CORETYPE``,
    ``SIM_NO_JIT`` and ``NUMBA_DISABLE_JIT`` (the NumPy paths too) where set."""
    out = {"system": platform.system(), "machine": platform.machine()}
    out.update({k: os.environ[k] for k in PATH_VARIABLES if os.environ.get(k)})
    return out


def provenance(cfg: Mapping[str, Any], **extra: Any) -> dict[str, Any]:
    """Provenance record for a run: resolved config, seed, versions, machine, git commit."""
    return {
        "study": cfg.get("study"),
        "config": dict(cfg),
        "seed": cfg.get("seed"),
        "versions": versions(),
        "numerics": numerics(),
        "git_commit": git_commit(cfg.get("study")),
        "code_hash": code_hash(cfg.get("study")),
        **extra,
    }


def _jsonable(o: Any) -> Any:
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o)}")


def umask_problem() -> str | None:
    """Why the process's umask keeps the suite from its own files (None: it does not): one that
    masks the owner's bits (``umask 777``: a staging directory of mode 000 that no later run
    could enter, blocking it until deleted by hand; ``sim report`` replaced every README.md and
    REPORT.md by files no one may read, with exit 0). Read from /proc (setting it to read it
    would race other threads' files), else not judged."""
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            line = next((ln for ln in f if ln.startswith("Umask:")), "")
        mask = int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        return None
    if mask & 0o700 == 0:
        return None
    return (
        f"umask {mask:04o} denies the owner access to the files the suite writes; run with a "
        "umask such as 022 or 077"
    )


class atomic_path:
    """Context manager yielding a temporary path that is renamed to ``path`` on success."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.tmp = self.path.with_name(f".{self.path.name}.{os.getpid()}.tmp")

    def __enter__(self) -> Path:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        _drop_stale_temporaries(self.path)
        return self.tmp

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            try:
                os.replace(self.tmp, self.path)
            except OSError as e:  # e.g. a directory where the file goes: leave no temporary
                self._drop_tmp()  # behind, and name the file, not it
                raise _named(e, self.path) from None
            except BaseException:  # Ctrl-C or SIGTERM just before the rename: `sim report`
                self._drop_tmp()  # left .REPORT.md.<pid>.tmp in the results until a next write
                raise
        else:
            self._drop_tmp()
            if isinstance(exc, OSError) and exc.filename in (None, "", str(self.tmp)):
                # a failing write (ulimit -f: EFBIG, a full disk) says only "File too large";
                # pyarrow's says "Error writing bytes to file. Detail: [errno 27] ...": name
                # the file it was writing (not the temporary, ".README.md.9762.tmp", a name
                # the user never saw: a directory of another user's, read-only)
                raise _named(exc, self.path) from None

    def _drop_tmp(self) -> None:
        """Remove the temporary if it is there (on a read-only file system unlink fails with
        EROFS even for a name that is not: that error named ``.README.md.<pid>.tmp``)."""
        with contextlib.suppress(OSError):
            self.tmp.unlink(missing_ok=True)


def _named(e: OSError, path: Path) -> OSError:
    """``e`` again, with the file it was writing as its file name (its errno and words kept;
    pyarrow's "... Detail: [errno N] words" read as errno N and its words)."""
    num, words = e.errno, e.strerror
    m = re.search(r"\[errno (\d+)\] (.+)$", str(e))
    if m:
        num, words = num or int(m.group(1)), m.group(2)
    named = OSError(num or 0, words or str(e) or type(e).__name__, str(path))
    named.__traceback__ = e.__traceback__
    return named


def _drop_stale_temporaries(path: Path) -> None:
    """Remove the temporaries of ``path`` (``.<name>.<pid>.tmp``) that a process killed while
    writing it left (``sim report`` killed during a README.md stayed so for good, and a
    re-run carried it into the new results as the user's): those of a pid no longer alive,
    or of this pid (a container's every command)."""
    pat = re.compile(re.escape(f".{path.name}.") + r"(\d+)\.tmp")
    try:
        names = [n for n in os.listdir(path.parent) if pat.fullmatch(n)]
    except OSError:
        return
    for n in names:
        if not writer_gone(int(pat.fullmatch(n).group(1))):
            continue  # a live process writing it
        p = path.parent / n
        if p.is_file() and not p.is_symlink():
            with contextlib.suppress(OSError):  # (read-only: it stays; the write names the file)
                p.unlink(missing_ok=True)


def write_table(
    path: str | Path,
    columns: Mapping[str, Any] | pa.Table,
    prov: Mapping[str, Any],
    tolerances: Mapping[str, Mapping[str, Any]] | None = None,
) -> Path:
    """Write ``columns`` (name -> 1-D array/list, or a pyarrow Table) to Parquet.

    ``tolerances``: column -> the rule by which ``make verify`` compares a re-run with it (the
    kind of number it is, :mod:`sim.mc.tolerance`), stored in the schema metadata
    (``sim.tolerances``); a column without one is compared by the default of its type.

    Raises :class:`NonFiniteError` (nothing written) for an infinite value in a float column
    or a non-finite claim value or interval (see :func:`check_finite_table`), ValueError for
    a tolerance that names no column or is not a valid rule."""
    table = (
        columns
        if isinstance(columns, pa.Table)
        else pa.table(
            {k: (np.asarray(v) if not isinstance(v, list) else v) for k, v in columns.items()}
        )
    )
    check_finite_table(Path(path).name, table)
    meta = dict(table.schema.metadata or {})
    meta[_KEY] = json.dumps(prov, sort_keys=True, default=_jsonable).encode()
    if tolerances:
        meta[tolerance.TOLERANCE_KEY] = tolerance.encode(tolerance.validate(tolerances, table))
    table = table.replace_schema_metadata(meta)
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp, compression="zstd")
    return Path(path)


def read_table(path: str | Path) -> pa.Table:
    return pq.read_table(path)


def read_provenance(path: str | Path) -> dict[str, Any]:
    meta = pq.read_schema(path).metadata or {}
    try:
        return json.loads(meta.get(_KEY, b"{}"))
    except RecursionError:  # provenance nested too deeply: not ours, as garbage JSON is not
        raise ValueError(f"{path}: provenance nested too deeply") from None
    except ValueError as e:  # its bytes edited: it was the codec's or json's words alone
        why = f"byte 0x{e.object[e.start]:02x} is not UTF-8" if hasattr(e, "start") else e
        raise ValueError(f"its metadata sim.provenance is not as sim writes it ({why})") from None


def read_tolerances(path: str | Path) -> dict[str, dict]:
    """The tolerances declared with a table's columns ({} if none; :mod:`sim.mc.tolerance`)."""
    return tolerance.decode(pq.read_schema(path).metadata)


# --- the output directory: what the suite wrote, and who is writing it -----------------------

RECORD = "run.json"
LOCK = ".lock"


def regular_text(p: str | Path) -> str:
    """The UTF-8 text of the regular file ``p`` (a symlink followed). Anything else -- a FIFO
    nobody writes to, a device, a directory -- raises OSError without being opened, so a
    file put by hand where the suite keeps its own never blocks a command."""
    if not stat.S_ISREG(os.stat(p).st_mode):
        raise OSError(f"{p} is not a regular file")
    return Path(p).read_text(encoding="utf-8")


def read_record(d: str | Path) -> dict | None:
    """The run record (``run.json``) of a directory the suite wrote, or None (none, or not one
    of ours)."""
    try:
        rec = json.loads(regular_text(Path(d) / RECORD).removeprefix("\ufeff"))  # Notepad's
    except (OSError, ValueError, RecursionError):  # RecursionError: JSON nested too deeply
        return None
    return rec if isinstance(rec, dict) and "config" in rec and "code_hash" in rec else None


def write_record(d: str | Path, record: Mapping[str, Any]) -> None:
    """Write ``run.json`` atomically."""
    with atomic_path(Path(d) / RECORD) as tmp:
        tmp.write_text(
            json.dumps(record, sort_keys=True, indent=1, default=_jsonable), encoding="utf-8"
        )


class Locked(RuntimeError):
    """Another live process holds the lock; ``pid`` is its process id (or None)."""

    def __init__(self, pid: int | None):
        self.pid = pid
        super().__init__(f"locked by pid {pid}")


class NotALock(Exception):
    """A staging directory's ``.lock`` that is not a lock file of the suite (a symbolic or hard
    link to another file, a FIFO): locking wrote the pid through it, over a user's file."""

    def __init__(self, path: Path):
        super().__init__(str(path))
        self.path = path


class StageLock:
    """An exclusive ``flock`` on ``<stage>/.lock`` for the life of a run.

    The kernel drops the lock when the process dies (even ``kill -9``), so a stale lock file
    never blocks a later run. The holder's pid is written into the file for the message a
    second run prints.
    """

    def __init__(self, stage: str | Path):
        self.stage = Path(stage)
        self.fd: int | None = None
        self.created = False

    def acquire(self) -> "StageLock":
        self.created = not self.stage.exists()
        self.stage.mkdir(parents=True, exist_ok=True)
        # written into: never through a link to another file; its mode is the umask's, as for
        # every file of a run (0o644 kept a group's other members from resuming their runs)
        path = self.stage / LOCK
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK, 0o666)
        except OSError as e:
            if e.errno in (errno.ELOOP, errno.EISDIR):  # a symbolic link, a directory (doors25a:
                raise NotALock(path) from None  # "cannot write to <the parent>: Is a directory")
            raise
        self.fd = fd  # recorded before flock: an interrupt (Ctrl-C) after it, before this
        try:  # assignment, kept the lock for the process's life (a notebook's sim.load)
            st = os.fstat(fd)
            if not stat.S_ISREG(st.st_mode) or st.st_nlink > 1:  # a FIFO, a hard link
                raise NotALock(path)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                try:
                    pid = int(os.read(fd, 32).decode().strip() or 0) or None
                except (OSError, ValueError):
                    pid = None
                raise Locked(pid) from None
            os.ftruncate(fd, 0)
            os.write(fd, f"{os.getpid()}\n".encode())
        except BaseException:  # also an OSError: ENOLCK (NFS without its lock service)
            self.fd = None
            os.close(fd)
            raise
        return self

    def release(self, unlink: Path | None = None) -> None:
        """Drop the lock; ``unlink``: the lock file's current path, removed first (a finished
        run's lock file must not stay in its results)."""
        if self.fd is None:
            return
        if unlink is not None:
            (Path(unlink) / LOCK).unlink(missing_ok=True)
        os.close(self.fd)  # closing the descriptor releases the flock
        self.fd = None
