"""The results a Python caller names to the API (``run(out=...)``, ``sim.Results(path,
...)``): the reasons a file could not be read, the run's identity, the runs of a study under
a root. The paths themselves are checked as the command line checks its own
(:mod:`sim.path_args`, whose names this module gives too).
"""

from __future__ import annotations

import ast
import difflib
import errno
import os
import re
import resource
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq

from sim.mc.config import ConfigError
from sim.mc.storage import RECORD, config_hash, read_provenance, read_record, regular_text
from sim.mc.unfinished import unfinished
from sim.path_args import absolute_path, arrow_name, check_path, gone_cwd, too_long
from sim.report.read import memory_failure

__all__ = [
    "another_run",
    "check_path",
    "gone_cwd",
    "absolute_path",
    "arrow_name",
    "check_identity",
    "cell_chunks",
    "cell_mixed",
    "study_runs_in",
    "root_hint",
    "chunks_recorded",
    "too_long",
    "why_not_a_dir",
    "why_unread",
]


def why_unread(e: Exception) -> str:
    """Why a file could not be read, in words: an OSError's reason (its kind when it has
    none, as pyarrow's may not), else the kind of error; memory named as such (a limit just
    above a run's peak: pyarrow could not allocate, or start a thread)."""
    if memory_failure(e):
        cap = resource.getrlimit(resource.RLIMIT_AS)[0]
        limit = f"; ulimit -v is {cap // 1024} kB" if cap != resource.RLIM_INFINITY else ""
        return f"not enough memory: {str(e).splitlines()[0][:160]}{limit}"
    if isinstance(e, OSError) and e.strerror:
        return e.strerror
    return type(e).__name__


def check_identity(v: Any) -> None:
    """``v``, a ``Results``' ``run_sha256``: "" (any run) or the 16 hex digits of
    :func:`run_identity`, which ``run()`` sets. A third argument given by a caller who took
    it for another (``sim.Results(path, "brown_table1", "claims")``) had every read refused
    as "holds another run than the one that returned these Results", of a run never made."""
    if not (v == "" or (isinstance(v, str) and re.fullmatch("[0-9a-f]{16}", v))):
        raise ConfigError(
            "run_sha256",
            f"is the identity of the run that returned these Results, which run() sets (16 "
            f"hex digits): leave it out to read the directory's run (got {v!r})",
        )


def run_identity(out: Path) -> str:
    """The config hash (:func:`sim.mc.storage.config_hash`) of the config and code hash
    ``out/run.json`` records: another run of the study (another seed, another key) has
    another; "" when there is no such record (a damaged one is refused by the reads
    themselves, naming ``run.json``). A record the disk fails to read (EIO, EACCES) is
    refused naming it: the check that the tables are still the run's was skipped, and
    another run's tables read as this one's."""
    rec = read_record(out)
    if rec:
        return config_hash(rec["config"], rec["code_hash"])
    try:
        regular_text(out / RECORD)
    except OSError as e:
        if e.errno is not None and e.errno != errno.ENOENT:  # not "none", not "not a file"
            raise ConfigError("path", f"{out / RECORD} cannot be read ({why_unread(e)})") from None
    except ValueError:  # not UTF-8: damaged, refused by the reads
        pass
    return ""


def why_not_a_dir(path: Path, of_a_run: bool) -> str:
    """Why ``path`` (a ``Results``' directory, not a directory) cannot be read: missing (a run's
    results removed since the run, or a path that never was) or something else."""
    if os.path.lexists(path):
        return "is not a results directory"
    if (run := unfinished(path)) is not None:  # a run killed before it published
        return f"does not exist: {run}"
    return "no longer exists (removed since the run)" if of_a_run else "does not exist"


def chunks_recorded(d: Path) -> bool:
    """Whether the run record of ``d`` maps its chunk files to their sha256, the only chunks
    ``Results.table("chunks")`` reads: a sweep's cell has no record of its own (its sweep's
    records none of its chunks), and ``names()`` listed ``chunks`` and ``trials`` there, each
    of which ``table()`` refused."""
    rec = read_record(d)
    return isinstance(rec, dict) and isinstance(rec.get("chunk_sha256"), dict)


def cell_chunks(d: Path) -> str | None:
    """Why the chunks of ``d``, a cell of a sweep (``<sweep>/cells/<label>/``), are not read,
    or None when ``d`` is no such cell (it was "run.json is missing or not a run record", of
    a directory that never had one)."""
    sweep = d.parent.parent
    if d.parent.name != "cells" or not (sweep / "sweep.parquet").is_file():
        return None
    return (
        f"{d} is a cell of the sweep {sweep}, whose run.json records no sha256 of the cells' "
        "chunk files: they cannot be checked, and are not read (the cell's tables are)"
    )


def cell_mixed(d: Path, names: list[str] | None = None) -> str | None:
    """Why the tables of ``d``, a cell of a sweep (``<sweep>/cells/<label>/``, which has no run
    record of its own), are not that cell's (``names``: only these tables), or None. The
    sweep's ``sweep.parquet`` row of the label gives the cell's seed and swept values and its
    ``run.json`` the code: a cell replaced by another cell's, another sweep's or a single run's
    results (cells renamed, two sweeps merged by hand) was shown as the label's cell."""
    sweep = d.parent.parent
    if d.parent.name != "cells" or (d / RECORD).exists() or not (sweep / "sweep.parquet").is_file():
        return None
    record = read_record(sweep)
    cfg = record.get("config") if isinstance(record, dict) else None
    keys = [k for k in (cfg or {}).get("sweep") or {} if k not in ("replicates", "seed_mode")]
    try:
        rows = pq.read_table(sweep / "sweep.parquet").to_pylist()
    except (OSError, ValueError, pa.ArrowException):
        return None  # not Parquet: its reader names it
    row = next((r for r in rows if isinstance(r, dict) and r.get("label") == d.name), None)
    if not isinstance(cfg, dict) or row is None:
        return None if row else f"{d}: its sweep {sweep} has no cell {d.name} (sweep.parquet)"
    want = {k: row.get(k) for k in ("seed", *keys) if not isinstance(row.get(k), (list, dict))}
    for p in sorted(d / n for n in names) if names else sorted(d.glob("*.parquet")):
        try:
            prov = read_provenance(p)
        except (OSError, ValueError, pa.ArrowException):
            continue  # not Parquet: its reader names it
        mine = prov.get("config") if isinstance(prov, dict) else None
        if not isinstance(mine, dict):
            continue  # no provenance: read as it is (mixed_run's missing_ok)
        diff = [
            f"{k} = {mine.get(k)!r}, the cell's {v!r}"
            for k, v in want.items()
            if not _same_value(mine.get(k), v)
        ]
        if prov.get("code_hash") != record.get("code_hash"):
            diff.append("made by other code than its sweep")
        if diff:
            return (
                f"{p} is not a table of the cell {d.name} of its sweep ({diff[0]}): the cell "
                "holds another cell's or run's results; run the sweep again"
            )
    return None


def study_runs_in(root: Path, study: str, most: int = 500) -> list[Path]:
    """The results directories of ``study`` directly inside ``root`` (a results root: the
    project's ``results/``, a batch's ``--results``), by their run record's study: a network's
    is named by its study file (``results/network_plate``), not ``results/network``, and
    ``Results(root, "network").names()`` of such a root was ``[]``. At most ``most`` entries
    of ``root`` are looked at."""
    return [d for d, s in _runs_in(root, most) if s == study]


def _runs_in(root: Path, most: int = 500) -> list[tuple[Path, str]]:
    """``(directory, its run record's study)`` of the results directories inside ``root``."""
    found = []
    try:
        entries = sorted(os.scandir(root), key=lambda e: e.name)[:most]
    except OSError:
        return []
    for e in entries:
        try:
            if not e.is_dir() or not (Path(e.path) / RECORD).is_file():
                continue
        except OSError:
            continue
        rec = read_record(Path(e.path))
        cfg = rec.get("config") if isinstance(rec, dict) else None
        if isinstance(cfg, dict) and isinstance(cfg.get("study"), str):
            found.append((Path(e.path), cfg["study"]))
    return found


def root_hint(root: Path, study: str) -> str:
    """``; it is a results root: ...`` naming the studies whose results directories ``root``
    holds (none of ``study``, a name mistyped: the one it most likely meant), or "". Of
    ``sim.Results("results", "brown_tabel1")`` it said only "holds tables of 'verify', not of
    'brown_tabel1'" (the root's make verify record), naming none of its twelve studies."""
    studies = sorted({s for _, s in _runs_in(root)})
    if not studies:
        return ""
    near = difflib.get_close_matches(study, studies, n=1, cutoff=0.75)
    meant = f" (did you mean {near[0]!r}?)" if near else ""
    shown = ", ".join(studies[:8]) + (", ..." if len(studies) > 8 else "")
    return (
        f"; it is a results root, whose results directories hold no run of {study!r}{meant}: "
        f"they hold {shown}; give the path of one"
    )


def _same_value(mine: Any, row: Any) -> bool:
    """Whether a cell's config value ``mine`` is the value ``sweep.parquet`` records for it
    (``row``): a list swept (``network.grids``) is recorded as its ``repr`` (the text of the
    study file's order of keys), read back here; one that cannot be read back is not held
    against the cell. Every cell of a sweep over ``network.grids`` was refused as "not a
    table of the cell" (its grids against their own text)."""
    if isinstance(mine, (list, dict)) and isinstance(row, str):
        if len(row) > 100_000:
            return True
        try:
            row = ast.literal_eval(row)
        except (ValueError, TypeError, SyntaxError, MemoryError, RecursionError):
            return True
    return mine == row


def another_run(out: Path, study: str) -> str:
    """Why the Results of a run of ``study`` into ``out`` no longer read it: another run went
    there since. Its advice, ``sim.Results(path, study)``, was given of another study's run
    too, where it is refused in turn ("holds tables of 'brown_dilution'"): that run's study is
    named instead."""
    rec = read_record(out)
    cfg = rec.get("config") if isinstance(rec, dict) else None
    other = cfg.get("study") if isinstance(cfg, dict) else None
    if isinstance(other, str) and other != study:
        return (
            f"{out} holds a run of {other!r} now (run into it since), not the run of "
            f"{study!r} that returned these Results"
        )
    return (
        f"{out} holds another run than the one that returned these Results "
        f"(run again into it since): read it with sim.Results(path, {study!r})"
    )
