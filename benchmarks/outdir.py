"""Which files of an ``--out`` directory the benchmark may replace (issue 26: a command only
creates or replaces files the suite wrote).

The benchmark writes fixed names (:data:`WRITES`); one of them that already exists is its own
when it says so: a table whose provenance names the study ``bench``, the page whose first line
is the page's heading (:data:`benchmarks.page.HEADING`), a figure beside a table of the
benchmark's with its stem, and the scratch chunk store ``million_trials.tmp`` holding only
``part-*/chunk-*.parquet`` files (an interrupted ``brown`` section's, with the temporary
``.chunk-*.parquet.<pid>.tmp`` of a chunk being written when its child process was killed: the
OOM killer, ``kill -9``; such a store refused every later benchmark until removed by hand).

:class:`OutLock` holds ``--out`` for the life of a benchmark: a second one into the same
directory stops at once, naming the first (two at once replaced each other's chunk store and
wrote their tables and figures over each other's).
"""

from __future__ import annotations

import errno
import fcntl
import json
import os
import re
from pathlib import Path

import pyarrow.parquet as pq

from benchmarks.page import HEADING

__all__ = ["WRITES", "OutLock", "full_measurement", "not_written_here"]

TABLES = ("bench", "engines", "studies", "rerun", "scaling", "store", "startup")
FIGURES = {"bench.png": "bench", "engines.png": "engines", "scaling.png": "scaling"}
STORE = "million_trials.tmp"
WRITES = (*(f"{t}.parquet" for t in TABLES), *FIGURES, "README.md", STORE)


#: a chunk file of the store, or the temporary of one being written (:class:`atomic_path`)
_CHUNK = re.compile(r"chunk-\d+\.parquet|\.chunk-\d+\.parquet\.\d+\.tmp")


def _bench_config(path: Path) -> dict | None:
    """The config a table of the benchmark records (``study``, ``quick``), or None."""
    try:
        meta = pq.read_schema(path).metadata or {}
        prov = json.loads(meta.get(b"sim.provenance", b"{}"))
    except (OSError, ValueError):
        return None
    config = prov.get("config") if isinstance(prov, dict) else None
    return config if isinstance(config, dict) and config.get("study") == "bench" else None


def _bench_table(path: Path) -> bool:
    return _bench_config(path) is not None


def full_measurement(out: Path) -> str | None:
    """The name of the first table in ``out`` of a full benchmark (not ``--quick``), or None:
    a smoke run replaced the committed measurements of ``results/bench`` (``make bench
    BENCH_FLAGS=--quick``, whose ``BENCH_OUT`` is that by default) with its tiny sizes'."""
    for t in TABLES:
        config = _bench_config(out / f"{t}.parquet") if (out / f"{t}.parquet").is_file() else None
        if config is not None and config.get("quick") is False:
            return f"{t}.parquet"
    return None


def _bench_page(path: Path) -> bool:
    try:
        with path.open("rb") as f:
            first = f.readline(4096)
    except OSError:
        return False
    return first.decode("utf-8", "replace").rstrip("\r\n") == HEADING


def _bench_store(path: Path) -> bool:
    if path.is_symlink() or not path.is_dir():
        return False
    for p in path.rglob("*"):
        rel = p.relative_to(path).parts
        if p.is_symlink():
            return False
        if len(rel) == 1 and not (p.is_dir() and rel[0].startswith("part-")):
            return False
        if len(rel) == 2 and not (p.is_file() and _CHUNK.fullmatch(rel[1])):
            return False
        if len(rel) > 2:
            return False
    return True


def not_written_here(out: Path) -> str | None:
    """The name of the first file the benchmark would replace in ``out`` that it did not
    write, or None."""
    if not out.is_dir():
        return None
    for name in WRITES:
        p = out / name
        if not p.exists() and not p.is_symlink():
            continue
        if name == STORE:
            ours = _bench_store(p)
        elif name == "README.md":
            ours = p.is_file() and not p.is_symlink() and _bench_page(p)
        elif name in FIGURES:
            beside = out / f"{FIGURES[name]}.parquet"
            ours = p.is_file() and not p.is_symlink() and _bench_table(beside)
        else:
            ours = p.is_file() and not p.is_symlink() and _bench_table(p)
        if not ours:
            return name
    return None


class OutLock:
    """An exclusive ``flock`` on the ``--out`` directory itself (no lock file is left in it:
    ``results/bench`` is committed), dropped by the kernel when the process ends. The holder
    is named by its pid from ``/proc/locks`` where the system has one."""

    def __init__(self, out: Path):
        self.out = Path(out)
        self.fd: int | None = None

    def __enter__(self) -> "OutLock":
        self.out.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.out, os.O_RDONLY | os.O_DIRECTORY)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as e:
            holder = _holder(fd) if e.errno in (errno.EWOULDBLOCK, errno.EAGAIN) else None
            os.close(fd)
            if e.errno not in (errno.EWOULDBLOCK, errno.EAGAIN):
                raise
            who = f" (pid {holder})" if holder else ""
            raise RuntimeError(
                f"--out: {self.out} is being written by another benchmark{who}: wait for it "
                "to end, or give another --out"
            ) from None
        self.fd = fd
        return self

    def __exit__(self, *exc) -> None:
        if self.fd is not None:
            os.close(self.fd)  # closing the descriptor drops the lock
            self.fd = None


def _holder(fd: int) -> int | None:
    """The pid of the process that holds a FLOCK on the file of ``fd`` (Linux), or None."""
    st = os.fstat(fd)
    inode = f"{os.major(st.st_dev):02x}:{os.minor(st.st_dev):02x}:{st.st_ino}"
    try:
        with open("/proc/locks", encoding="ascii", errors="replace") as f:
            for line in f:
                parts = line.split()
                if "FLOCK" in parts and inode in parts and "->" not in parts:
                    return int(parts[parts.index(inode) - 1])
    except (OSError, ValueError, IndexError):
        return None
    return None
