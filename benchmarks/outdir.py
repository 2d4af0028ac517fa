"""Which files of an ``--out`` directory the benchmark may replace (issue 26: a command only
creates or replaces files the suite wrote).

The benchmark writes fixed names (:data:`WRITES`); one of them that already exists is its own
when it says so: a table whose provenance names the study ``bench``, the page whose first line
is the page's heading (:data:`benchmarks.page.HEADING`), a figure beside a table of the
benchmark's with its stem, and the scratch chunk store ``million_trials.tmp`` holding only
``part-*/chunk-*.parquet`` files (an interrupted ``brown`` section's).
"""

from __future__ import annotations

import json
from pathlib import Path

import pyarrow.parquet as pq

from benchmarks.page import HEADING

__all__ = ["WRITES", "not_written_here"]

TABLES = ("bench", "engines", "studies", "rerun", "scaling", "store")
FIGURES = {"bench.png": "bench", "engines.png": "engines", "scaling.png": "scaling"}
STORE = "million_trials.tmp"
WRITES = (*(f"{t}.parquet" for t in TABLES), *FIGURES, "README.md", STORE)


def _bench_table(path: Path) -> bool:
    try:
        meta = pq.read_schema(path).metadata or {}
        prov = json.loads(meta.get(b"sim.provenance", b"{}"))
    except (OSError, ValueError):
        return False
    return isinstance(prov, dict) and (prov.get("config") or {}).get("study") == "bench"


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
        if len(rel) == 2 and not (p.is_file() and rel[1].startswith("chunk-")):
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
