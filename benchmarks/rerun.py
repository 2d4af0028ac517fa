"""Rerun rows of the benchmark (``rerun.parquet``): the wall time of ``make rerun``.

Every study file is run the way ``make rerun`` runs it: ``python -m sim.batch`` in a fresh
process (its ``--timings``), each study in a process of its own, ``python -m sim run <file> --out <dir>/<name> --overwrite --workers N --quiet``,
:data:`JOBS` studies side by side, the slowest first; then ``python -m sim report`` over the
results (``make rerun``'s last step), for ``N`` = 1 and 2 workers. The results go to a
scratch directory (``results/`` is never touched) that is removed afterwards. One row per
study and worker count (``study`` = the file's name, or ``report``; its ``wall_s`` is that
run's own wall time, which overlaps its neighbour's; ``start_s`` when it started, after the
first start), and a ``total`` row per worker count:
the wall time from the first start to the report's end, against the 90 s target of issue 12
(``target_s``; NaN on the other rows). ``jobs``: the studies run at a time. Wall clock, so
the machine must be quiet.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from sim.mc.children import ended

__all__ = ["JOBS", "TARGET_S", "rerun_rows", "study_files"]

#: issue 12: ``make rerun`` under 90 s on a 2-core machine (its ``RUN_FLAGS``: ``--workers 1``)
TARGET_S = 90.0
#: studies run side by side by ``make rerun`` (the Makefile's ``RUN_JOBS``)
JOBS = 2


def study_files(pattern: str = "studies/*.toml") -> list[Path]:
    """The study files ``make rerun`` runs (its ``$(wildcard studies/*.toml)``), sorted."""
    p = Path(pattern)
    files = sorted(Path(p.parent).glob(p.name)) if p.parent.is_dir() else []
    if not files:
        raise FileNotFoundError(f"bench --rerun-files: no study file matches {pattern}")
    return files


def _wall(cmd: list[str], what: str) -> float:
    t = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
        raise RuntimeError(f"bench: {what} failed (it {ended(done.returncode)}): {last}")
    return wall


def rerun_rows(
    files: list[Path], workers=(1, 2), extra=None, jobs: int | None = None
) -> dict[str, list]:
    """The columns of ``rerun.parquet``: ``study``, ``workers``, ``jobs``, ``start_s``,
    ``wall_s``, ``target_s``, ``within_target`` (true/false on the total rows, false elsewhere).
    ``extra`` maps a study file's name (stem) to more arguments of its ``sim run`` (e.g.
    ``--set trials=...`` for a smoke run); ``jobs`` defaults to ``make rerun``'s."""
    jobs = JOBS if jobs is None else jobs
    extra = extra or {}
    rows: dict[str, list] = {
        c: []
        for c in ("study", "workers", "jobs", "start_s", "wall_s", "target_s", "within_target")
    }

    def add(study, n, wall, target=np.nan, start=0.0):
        rows["study"].append(study)
        rows["workers"].append(n)
        rows["jobs"].append(jobs)
        rows["start_s"].append(start)
        rows["wall_s"].append(wall)
        rows["target_s"].append(target)
        rows["within_target"].append(bool(wall < target))

    py = [sys.executable, "-m", "sim"]
    with tempfile.TemporaryDirectory(prefix="sim-bench-rerun-") as tmp:
        for n in workers:
            res = Path(tmp) / f"workers{n}"
            t0 = time.perf_counter()
            done = {}
            # make rerun's command; a smoke run's per-study sets: one batch per file
            for group in [[f] for f in files] if extra else [files]:
                done.update(
                    _batch(
                        group,
                        res,
                        jobs,
                        n,
                        extra.get(group[0].stem, ()) if extra else (),
                        Path(tmp) / "timings.json",
                        time.perf_counter() - t0,
                    )
                )
            for f in files:
                _, wall, start = done[f.stem]
                add(f.stem, n, wall, start=start)
                print(f"{f.stem:>22} workers={n} {wall:7.1f} s")
            t1 = time.perf_counter() - t0
            add("report", n, _wall([*py, "report", "--results", str(res)], "sim report"), start=t1)
            total = time.perf_counter() - t0
            add("total", n, total, TARGET_S)
            print(
                f"{'make rerun':>22} workers={n} jobs={jobs} {total:7.1f} s "
                f"(target {TARGET_S:.0f} s)"
            )
    return rows


def _batch(files, res, jobs, n, sets, timings: Path, offset: float) -> dict:
    """``python -m sim.batch`` over ``files`` (what ``make rerun`` runs): ``{stem: (exit
    code, wall s, start s)}``, the starts shifted by ``offset``."""
    cmd = [
        sys.executable,
        "-m",
        "sim.batch",
        "--jobs",
        str(jobs),
        "--results",
        str(res),
        "--timings",
        str(timings),
        *map(str, files),
        "--",
        "--workers",
        str(n),
        "--quiet",
        *sets,
    ]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if not timings.is_file():
        last = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
        raise RuntimeError(f"bench: sim.batch failed (it {ended(done.returncode)}): {last}")
    out = json.loads(timings.read_text())
    timings.unlink()
    for k, (c, _, _) in out.items():
        if c != 0:
            last = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
            raise RuntimeError(f"bench: sim run of {k} failed (it {ended(c)}): {last}")
    return {k: (c, w, s + offset) for k, (c, w, s) in out.items()}
