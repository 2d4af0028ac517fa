"""Parquet result files with provenance, written atomically.

Every file carries, in its schema metadata under ``sim.provenance``, a JSON object with
the resolved study configuration, the root seed, package versions and the git commit
of the code that produced it. Writes go to a temporary file in the same directory and
are renamed into place, so a reader never sees a half-written file. No timestamps are
stored, so the same code and config give byte-identical files.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from functools import lru_cache
from pathlib import Path
from typing import Any, Mapping

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

__all__ = ["provenance", "write_table", "read_table", "read_provenance", "atomic_path"]

_KEY = b"sim.provenance"
from .codehash import NOT_STUDY_CODE  # library files no study result depends on


@lru_cache(maxsize=None)
def git_commit(study: str | None = None) -> str:
    """The last commit that changed the code or definition of ``study`` (its modules, see
    :mod:`sim.codehash`, its study file and ``pyproject.toml``; without a study: all of
    ``sim/`` but the benchmark, and ``studies/``), ``-dirty`` if they have uncommitted changes.
    A commit of results, or of another study's code, does not change it, so re-running gives
    byte-identical files."""
    root = Path(__file__).resolve().parent.parent
    if study is None:
        paths = ["sim", "studies", "pyproject.toml",
                 *(f":(exclude)sim/{f}" for f in NOT_STUDY_CODE)]
    else:
        from .codehash import study_files

        paths = [p.relative_to(root).as_posix() for p in study_files(study)]
        paths += [f"studies/{study}.toml", "pyproject.toml"]
    try:
        head = subprocess.run(["git", "log", "-1", "--format=%H", "--", *paths], cwd=root,
                              capture_output=True, text=True, timeout=10)
        if head.returncode != 0 or not head.stdout.strip():
            return "unknown"
        dirty = subprocess.run(["git", "status", "--porcelain", "--", *paths], cwd=root,
                               capture_output=True, text=True, timeout=10).stdout.strip()
        return head.stdout.strip() + ("-dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def code_hash(study: str | None = None) -> str:
    """sha256 of the code ``study`` depends on (:func:`sim.codehash.study_code_hash`), or,
    without a study, of the library's source (every ``sim/**/*.py`` but the benchmark)."""
    import hashlib

    if study is not None:
        from .codehash import study_code_hash

        return study_code_hash(study)
    root = Path(__file__).resolve().parent
    h = hashlib.sha256()
    for f in sorted(root.rglob("*.py")):
        if f.relative_to(root).as_posix() in NOT_STUDY_CODE:
            continue
        h.update(str(f.relative_to(root)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:16]


def versions() -> dict[str, str]:
    """Versions of Python and of every package a result can depend on (``not installed`` for
    the optional ones: without numba the NumPy engine runs)."""
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": sys.version.split()[0]}
    for pkg in ("numpy", "scipy", "pyarrow", "matplotlib", "emcee", "numba"):
        try:
            out[pkg] = version(pkg)
        except PackageNotFoundError:
            out[pkg] = "not installed"
    return out


def provenance(cfg: Mapping[str, Any], **extra: Any) -> dict[str, Any]:
    """Provenance record for a run: resolved config, seed, versions, git commit."""
    return {"study": cfg.get("study"), "config": dict(cfg), "seed": cfg.get("seed"),
            "versions": versions(), "git_commit": git_commit(cfg.get("study")),
            "code_hash": code_hash(cfg.get("study")), **extra}


def _jsonable(o: Any) -> Any:
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o)}")


class atomic_path:
    """Context manager yielding a temporary path that is renamed to ``path`` on success."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.tmp = self.path.with_name(f".{self.path.name}.{os.getpid()}.tmp")

    def __enter__(self) -> Path:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        return self.tmp

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            os.replace(self.tmp, self.path)
        else:
            self.tmp.unlink(missing_ok=True)


def write_table(path: str | Path, columns: Mapping[str, Any] | pa.Table,
                prov: Mapping[str, Any]) -> Path:
    """Write ``columns`` (name -> 1-D array/list, or a pyarrow Table) to Parquet."""
    table = columns if isinstance(columns, pa.Table) else pa.table(
        {k: (np.asarray(v) if not isinstance(v, list) else v) for k, v in columns.items()})
    meta = dict(table.schema.metadata or {})
    meta[_KEY] = json.dumps(prov, sort_keys=True, default=_jsonable).encode()
    table = table.replace_schema_metadata(meta)
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp, compression="zstd")
    return Path(path)


def read_table(path: str | Path) -> pa.Table:
    return pq.read_table(path)


def read_provenance(path: str | Path) -> dict[str, Any]:
    meta = pq.read_schema(path).metadata or {}
    return json.loads(meta.get(_KEY, b"{}"))
