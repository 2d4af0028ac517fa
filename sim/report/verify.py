"""Reproducibility verified, not promised: re-run the studies and compare with committed results.

``sim verify`` re-runs every study of a results directory (its study file in ``studies/``)
into a scratch directory and compares, file by file and column by column, the Parquet tables
there with the committed ones:

* numeric columns: the largest deviation ``|a - b|`` against the column's tolerance
  ``rtol * max(|a|, |b|) + atol``. Deterministic numbers use ``DEFAULT_RTOL`` (the rounding
  left by a different BLAS or CPU) and ``DEFAULT_ATOL``; a table may declare larger ones for
  columns that carry Monte-Carlo error of a chain or sample, in its provenance:
  ``prov["tolerances"] = {"<file>.parquet": {"<column>": rtol or {"rtol": .., "atol": ..}}}``;
* the ``verdict``, ``outcome`` and ``holds`` columns of ``claims.parquet``: any change fails;
* other text columns: reported when they differ (notes format numbers), never a failure;
* the set of files, their columns and row counts must be the same.

The outcome is written to ``<results>/reproducibility.parquet`` (one row per study, with the
machine and package versions in the provenance) for the report's *Reproducibility* section.
"""

from __future__ import annotations

import os
import platform
import shutil
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from sim.mc.storage import read_provenance, versions, write_table
from sim.report.tables import fmt, md_table

__all__ = ["compare_dirs", "verify", "DEFAULT_RTOL", "DEFAULT_ATOL", "Comparison"]

DEFAULT_RTOL = 1e-7
DEFAULT_ATOL = 1e-9
VERDICT_COLUMNS = ("verdict", "outcome", "holds")
#: files a verify run writes itself, never compared
SKIP = ("reproducibility.parquet",)


@dataclass
class Comparison:
    """The comparison of one study's committed results with a re-run."""

    study: str
    files: int = 0
    max_ratio: float = 0.0  # largest deviation / tolerance over all numeric cells
    max_rel: float = 0.0  # largest relative deviation
    worst: str = ""  # file:column of max_ratio
    failures: list[str] = field(default_factory=list)
    text_changes: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return not self.failures


def _tol(prov: dict, fname: str, col: str) -> tuple[float, float]:
    t = (prov.get("tolerances") or {}).get(fname, {}).get(col)
    if t is None:
        return DEFAULT_RTOL, DEFAULT_ATOL
    if isinstance(t, dict):
        return float(t.get("rtol", DEFAULT_RTOL)), float(t.get("atol", DEFAULT_ATOL))
    return float(t), DEFAULT_ATOL


def _numeric(col: pa.ChunkedArray) -> bool:
    t = col.type
    return pa.types.is_floating(t) or pa.types.is_integer(t)


def compare_tables(a: Path, b: Path, cmp: Comparison) -> None:
    """Compare committed table ``a`` with re-run table ``b`` into ``cmp``."""
    name = a.name
    ta, tb = pq.read_table(a), pq.read_table(b)
    prov = read_provenance(a)
    if ta.column_names != tb.column_names:
        cmp.failures.append(
            f"{name}: columns differ ({sorted(set(ta.column_names) ^ set(tb.column_names))})"
        )
        return
    if ta.num_rows != tb.num_rows:
        cmp.failures.append(f"{name}: {ta.num_rows} rows committed, {tb.num_rows} re-run")
        return
    for c in ta.column_names:
        ca, cb = ta.column(c), tb.column(c)
        if name == "claims.parquet" and c in VERDICT_COLUMNS:
            la, lb = ca.to_pylist(), cb.to_pylist()
            for i, (x, y) in enumerate(zip(la, lb)):
                if x != y:
                    claim = ta.column("claim")[i].as_py() if "claim" in ta.column_names else i
                    cmp.failures.append(f"{name}: {c} of {claim} changed: {x} -> {y}")
            continue
        if _numeric(ca) and _numeric(cb):
            x = ca.to_numpy(zero_copy_only=False).astype(float)
            y = cb.to_numpy(zero_copy_only=False).astype(float)
            nan_x, nan_y = np.isnan(x), np.isnan(y)
            if np.any(nan_x != nan_y):
                cmp.failures.append(f"{name}:{c}: missing values differ")
                continue
            m = ~nan_x
            if not m.any():
                continue
            x, y = x[m], y[m]
            inf = np.isinf(x) | np.isinf(y)
            if np.any(x[inf] != y[inf]):
                cmp.failures.append(f"{name}:{c}: infinite values differ")
            x, y = x[~inf], y[~inf]
            if x.size == 0:
                continue
            rtol, atol = _tol(prov, name, c)
            dev = np.abs(x - y)
            scale = np.maximum(np.abs(x), np.abs(y))
            ratio = dev / (rtol * scale + atol)
            k = int(np.argmax(ratio))
            rel = float(np.max(np.where(scale > 0, dev / np.where(scale > 0, scale, 1), 0)))
            cmp.max_rel = max(cmp.max_rel, rel)
            if ratio[k] > cmp.max_ratio:
                cmp.max_ratio, cmp.worst = float(ratio[k]), f"{name}:{c}"
            if ratio[k] > 1:
                cmp.failures.append(
                    f"{name}:{c}: {x[k]:.12g} committed, {y[k]:.12g} re-run "
                    f"(tolerance rtol {rtol:g}, atol {atol:g})"
                )
        elif ca.to_pylist() != cb.to_pylist():
            cmp.text_changes.append(f"{name}:{c}")


def compare_dirs(committed: Path, rerun: Path, study: str | None = None) -> Comparison:
    """Compare every Parquet table of ``committed`` (a study's results) with ``rerun``."""
    committed, rerun = Path(committed), Path(rerun)
    cmp = Comparison(study or committed.name)
    fa = {p.name for p in committed.glob("*.parquet") if p.name not in SKIP}
    fb = {p.name for p in rerun.glob("*.parquet") if p.name not in SKIP}
    for missing in sorted(fa ^ fb):
        cmp.failures.append(
            f"{missing}: only in the {'committed' if missing in fa else 're-run'} results"
        )
    for f in sorted(fa & fb):
        cmp.files += 1
        compare_tables(committed / f, rerun / f, cmp)
    return cmp


def _machine() -> dict:
    return {
        "machine": platform.machine(),
        "system": platform.system(),
        "processor": platform.processor() or platform.machine(),
        "cpus": os.cpu_count(),
        **versions(),
    }


def verify(
    results: Path,
    scratch: Path,
    studies_dir: Path = Path("studies"),
    workers: int = 1,
    only: list[str] | None = None,
    rerun: bool = True,
) -> list[Comparison]:
    """Re-run each study with committed results into ``scratch`` and compare."""
    results, scratch = Path(results), Path(scratch)
    out = []
    dirs = sorted(p for p in results.iterdir() if (p / "claims.parquet").is_file())
    for d in dirs:
        study = read_provenance(d / "claims.parquet").get("study", d.name)
        if only and study not in only:
            continue
        target = scratch / d.name
        if rerun:
            # a study kind with several example files (network_*) is named by its directory
            sf = studies_dir / f"{d.name}.toml"
            sf = sf if sf.is_file() else studies_dir / f"{study}.toml"
            cmd = [
                sys.executable,
                "-m",
                "sim",
                "run",
                str(sf),
                "--out",
                str(target),
                "--quiet",
                "--workers",
                str(workers),
            ]
            if target.exists():
                shutil.rmtree(target)
            print(f"sim verify: re-running {study}", file=sys.stderr, flush=True)
            r = subprocess.run(cmd)
            if r.returncode != 0:
                c = Comparison(d.name)
                c.failures.append(f"the re-run exited with {r.returncode}")
                out.append(c)
                continue
        out.append(compare_dirs(d, target, d.name))
    return out


def write_record(results: Path, comps: list[Comparison]) -> Path:
    cols = {
        "study": [c.study for c in comps],
        "files": [c.files for c in comps],
        "max_rel_dev": [c.max_rel for c in comps],
        "max_dev_over_tol": [c.max_ratio for c in comps],
        "worst": [c.worst for c in comps],
        "failures": [len(c.failures) for c in comps],
        "first_failure": [c.failures[0] if c.failures else "" for c in comps],
        "text_columns_changed": [", ".join(c.text_changes) for c in comps],
        "ok": [c.ok for c in comps],
    }
    return write_table(
        Path(results) / "reproducibility.parquet", cols, {"study": "verify", "machine": _machine()}
    )


def markdown(results: Path) -> str:
    """The report's *Reproducibility* section from ``reproducibility.parquet`` (empty if none)."""
    p = Path(results) / "reproducibility.parquet"
    if not p.is_file():
        return ""
    t = pq.read_table(p).to_pylist()
    m = read_provenance(p).get("machine", {})
    ver = ", ".join(
        f"{k} {v}" for k, v in m.items() if k not in ("machine", "system", "processor", "cpus")
    )
    rows = [
        [
            r["study"],
            r["files"],
            fmt(r["max_rel_dev"], 2),
            fmt(r["max_dev_over_tol"], 2),
            f"`{r['worst']}`" if r["worst"] else "",
            "yes" if r["ok"] else f"**no**: {r['first_failure']}",
            r["text_columns_changed"],
        ]
        for r in t
    ]
    return (
        "## Reproducibility\n\n"
        f"`make verify` re-ran every study into a scratch directory on {m.get('system', '?')} "
        f"{m.get('machine', '?')} ({m.get('cpus', '?')} CPUs; {ver}) and compared each "
        "Parquet column with the committed one against the column's tolerance (rounding level "
        f"{DEFAULT_RTOL:g} relative for deterministic numbers; Monte-Carlo-sized where a "
        "table declares it); a changed verdict fails.\n\n"
        + md_table(
            [
                "study",
                "files",
                "largest relative deviation",
                "largest deviation / tolerance",
                "where",
                "within tolerance",
                "text columns that differ",
            ],
            rows,
        )
        + "\n"
    )


def main(argv: list[str] | None = None) -> int:
    import argparse
    import tempfile

    p = argparse.ArgumentParser(prog="sim verify", description=__doc__.splitlines()[0])
    p.add_argument("--results", default="results")
    p.add_argument("--scratch", help="where to re-run (default: a temporary directory)")
    p.add_argument("--workers", type=int, default=1)
    p.add_argument("--study", action="append", help="only this study (repeatable)")
    p.add_argument(
        "--no-record", action="store_true", help="do not write <results>/reproducibility.parquet"
    )
    a = p.parse_args(argv)
    results = Path(a.results)
    if not results.is_dir():
        print(f"sim: error: --results: {results} is not a directory", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory(prefix="sim-verify-") as tmp:
        comps = verify(results, Path(a.scratch or tmp), workers=a.workers, only=a.study)
    for c in comps:
        status = "ok" if c.ok else "FAILED"
        print(
            f"{c.study}: {status}; {c.files} files; largest relative deviation "
            f"{c.max_rel:.2g}; largest deviation/tolerance {c.max_ratio:.2g} ({c.worst})"
        )
        for f in c.failures[:20]:
            print(f"  {f}")
    if not a.no_record and comps:
        write_record(results, comps)
    return 0 if comps and all(c.ok for c in comps) else 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
