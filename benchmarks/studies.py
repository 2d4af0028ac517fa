"""Study rows of the benchmark (``studies.parquet``): what the compiled kernels save of a whole
study.

Issue 22 keeps a compiled path where its engine row shows at least
:data:`benchmarks.engines.KEEP_RATIO` over its NumPy path, *or* where it saves at least
:data:`KEEP_SHARE` of a study's time. The second is measured here: each study of
:data:`STUDIES` is run as ``python -m sim run <file> --out <scratch> --quiet`` in a fresh
process, in two variants, ``compiled`` (1 worker) and ``numpy`` (1 worker, ``SIM_NO_JIT=1``:
every kernel of :mod:`sim.lsq.compile` off): CPU time of the child process (user + system,
steadier than wall time on a shared machine); ``saving`` = 1 - compiled / numpy, the share of
the NumPy run's time the kernels save. (Figures drawn on the pool's workers had two more
variants; they saved under 20 % of every study's wall time, and went.)

The results go to a scratch directory that is removed afterwards. ``--quick`` runs the test
suite's tiny configurations, whose shares say nothing about the full studies.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from sim.mc.children import ended

__all__ = ["STUDIES", "KEEP_SHARE", "VARIANTS", "study_rows"]

#: studies whose time decides a compiled path (the slowest of each family)
STUDIES = ("agnard_block", "brown_design", "wolf_polynomial")
#: issue 22: a compiled path or micro-optimisation stays if it saves this share of a study
KEEP_SHARE = 0.20
#: variant -> (workers, environment, measured clock)
VARIANTS = {
    "compiled": (1, {}, "cpu"),
    "numpy": (1, {"SIM_NO_JIT": "1"}, "cpu"),
}


def _run(cmd: list[str], env: dict, what: str) -> tuple[float, float]:
    """``(cpu_s, wall_s)`` of the child process ``cmd``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    done = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["(no message)"])[-1]
        raise RuntimeError(f"bench: {what} failed (it {ended(done.returncode)}): {last}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, wall


def study_rows(files: list[Path], extra=None) -> dict[str, list]:
    """The columns of ``studies.parquet``: ``study``, ``variant``, ``workers``, ``cpu_s``,
    ``wall_s``, ``seconds`` (the variant's measured clock) and ``clock``. ``extra`` maps a
    study file's name to more arguments of its ``sim run`` (the tiny ``--set``s)."""
    extra = extra or {}
    cols = ("study", "variant", "workers", "cpu_s", "wall_s", "seconds", "clock")
    rows: dict[str, list] = {c: [] for c in cols}
    base = {k: v for k, v in os.environ.items() if k != "SIM_NO_JIT"}
    with tempfile.TemporaryDirectory(prefix="sim-bench-studies-") as tmp:
        for f in files:
            for variant, (workers, env, clock) in VARIANTS.items():
                cmd = [sys.executable, "-m", "sim", "run", str(f), "--out", f"{tmp}/{f.stem}"]
                cmd += ["--overwrite", "--quiet", "--workers", str(workers)]
                cmd += list(extra.get(f.stem, ()))
                cpu, wall = _run(cmd, dict(base, **env), f"{f.stem} ({variant})")
                for c, v in zip(
                    cols,
                    (f.stem, variant, workers, cpu, wall, cpu if clock == "cpu" else wall, clock),
                ):
                    rows[c].append(v)
                print(f"{f.stem:>22} {variant:>16}: cpu {cpu:7.2f} s, wall {wall:7.2f} s")
    return rows
