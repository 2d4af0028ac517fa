"""Reproducibility verified, not promised: re-run the studies and compare with committed results.

``python -m sim.report.verify`` (``make verify``) re-runs every study of a results directory
(its study file in ``studies/``) into a scratch directory and compares, file by file and column
by column, the Parquet tables there with the committed ones, each column by the rule declared
with it for the kind of number it holds (:mod:`sim.mc.tolerance`; docs/reproducibility.md):

* ``exact`` (labels, counts, flags, and every ``verdict``, ``outcome`` and ``holds`` column,
  in any table): any change fails;
* ``arithmetic``: within the bound from its conditioning, ``cond * eps`` relative plus ``atol``
  (the default for a number that declares nothing: 1e-7 relative plus 1e-9);
* ``mc``: beyond that, a fraction of its Monte-Carlo standard error (from its row's interval);
* ``chain``: within its Monte-Carlo interval;
* ``axial``/``circular``: modulo the period; a null (an undefined value, with its reason)
  matches a null only;
* other text columns: listed when they differ (notes format numbers), never a failure;
* the set of files, their columns and row counts must be the same.

``--trials N`` (with ``--set KEY=VALUE`` for other trial counts) re-runs with fewer trials and
compares at the Monte-Carlo level: ``mc`` and ``chain`` columns within ``MC_K`` combined
standard errors of the two runs, columns declared ``analytic`` by their rule, the rest not at
all, and no verdict (a smaller run may be inconclusive where the full one decides).
``tests/test_verify.py`` runs it under another numerical path (``OPENBLAS_CORETYPE``,
``SIM_NO_JIT=1``, another worker count): the environment passes to the re-runs.

A full comparison of every study is written to ``<results>/reproducibility.parquet`` (one row
per study, with the machine and package versions in the provenance) for the report's
*Reproducibility* section. A bad option, an unknown study or an empty results directory is one
line and exit 2; a failed comparison exit 1. ``--scratch`` replaces only what the suite wrote
there (a directory with its ``run.json``); anything else is refused, never deleted.
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from sim.mc import tolerance as tl
from sim.mc.storage import read_provenance, read_record, read_tolerances, versions, write_table
from sim.report.tables import fmt, md_table

__all__ = [
    "compare_dirs",
    "compare_tables",
    "verify",
    "main",
    "DEFAULT_RTOL",
    "DEFAULT_ATOL",
    "Comparison",
    "VerifyError",
]

DEFAULT_RTOL = tl.DEFAULT_COND * tl.EPS
DEFAULT_ATOL = tl.DEFAULT_ATOL
VERDICT_COLUMNS = ("verdict", "outcome", "holds")
#: files a verify run writes itself, never compared
SKIP = ("reproducibility.parquet",)
MODES = ("full", "mc")


class VerifyError(ValueError):
    """A bad request (unknown study, no results, a scratch directory not ours): one line."""


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
    not_compared: list[str] = field(default_factory=list)  # at the MC level: not comparable

    @property
    def ok(self) -> bool:
        return not self.failures


# --- the rule of a column ---------------------------------------------------------------------


def _legacy(prov: dict, fname: str) -> dict:
    """Tolerances of results written before they were declared with the column: a relative
    tolerance in the provenance (``tolerances`` -> file -> column), read as a chain's."""
    out = {}
    for col, t in ((prov.get("tolerances") or {}).get(fname) or {}).items():
        rtol = t.get("rtol", DEFAULT_RTOL) if isinstance(t, dict) else t
        out[col] = tl.chain(rtol=float(rtol))
    return out


def _specs(a: Path, b: Path) -> tuple[dict, dict]:
    """The committed table's declarations (else the re-run's), and the re-run's own."""
    sa, sb = read_tolerances(a), read_tolerances(b)
    legacy = _legacy(read_provenance(a), a.name)
    return {**sb, **legacy, **sa}, sb


def _spec(specs: dict, name: str, col: str, t: pa.DataType) -> dict | None:
    if col in specs:
        return specs[col]
    if col in VERDICT_COLUMNS:  # a decision, in any table
        return tl.exact()
    return tl.default_for(t)


def _floats(c: pa.ChunkedArray) -> np.ndarray:
    """A numeric column as floats, null as NaN."""
    return np.asarray(c.to_numpy(zero_copy_only=False), dtype=float)


def _se(spec: dict, t: pa.Table) -> np.ndarray:
    """Per row the standard error a spec points to (0 where none)."""
    if "se" in spec:
        se = _floats(t.column(spec["se"]))
    elif "ci" in spec:
        lo, hi = (_floats(t.column(c)) for c in spec["ci"])
        se = (hi - lo) / tl.CI_SPAN_SE
    else:
        return np.zeros(t.num_rows)
    return np.where(np.isfinite(se), np.abs(se), 0.0)


def _bound(spec, x, y, ta, tb, sb, mode):
    """Allowed ``|x - y|`` per row (``x`` committed, ``y`` re-run) for the rows given."""
    kind = spec["kind"]
    if kind == "exact":
        return np.zeros_like(x)
    rtol = spec.get("cond", tl.DEFAULT_COND) * tl.EPS
    atol = spec.get("atol", tl.DEFAULT_ATOL)
    if kind in ("axial", "circular"):
        return np.full_like(x, rtol * spec["period"] + atol)
    scale = np.maximum(np.abs(x), np.abs(y))
    arith = rtol * scale + atol
    if kind == "arithmetic":
        return arith
    se_a = _se(spec, ta)
    if kind == "mc":
        if mode == "full":
            return arith + spec.get("fraction", 0.1) * se_a
        return arith + tl.MC_K * np.hypot(se_a, _se(sb or spec, tb))
    # a chain: within its Monte-Carlo interval (at the MC level, both runs' own, combined)
    ka = spec.get("rtol", 0.0) * np.abs(x) + spec.get("k", tl.MC_K) * se_a
    if mode == "full":
        return arith + np.maximum(ka, spec.get("rtol", 0.0) * scale)
    sb = sb or spec
    kb = sb.get("rtol", 0.0) * np.abs(y) + sb.get("k", tl.MC_K) * _se(sb, tb)
    return arith + np.hypot(ka, kb)


def _deviation(spec: dict, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    d = np.abs(x - y)
    if spec["kind"] in ("axial", "circular"):
        d = np.mod(d, spec["period"])
        d = np.minimum(d, spec["period"] - d)
    return d


# --- comparing tables -------------------------------------------------------------------------


def _compare_numbers(name, col, spec, ta, tb, sb, mode, cmp) -> None:
    x, y = _floats(ta.column(col)), _floats(tb.column(col))
    nan_x, nan_y = np.isnan(x), np.isnan(y)
    if np.any(nan_x != nan_y):
        i = int(np.flatnonzero(nan_x != nan_y)[0])
        why = ""
        if "null_reason" in spec:
            t = ta if nan_x[i] else tb
            why = f" ({t.column(spec['null_reason'])[i].as_py()})"
        cmp.failures.append(
            f"{name}:{col}: row {i} is {x[i]:.12g} committed, {y[i]:.12g} re-run{why}"
        )
        return
    inf = np.isinf(x) | np.isinf(y)
    if np.any(x[inf] != y[inf]):
        cmp.failures.append(f"{name}:{col}: infinite values differ")
    m = ~nan_x & ~inf
    if not m.any():
        return
    rows = np.flatnonzero(m)
    dev = _deviation(spec, x[m], y[m])
    bound = _bound(spec, x[m], y[m], ta.take(rows), tb.take(rows), sb, mode)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(dev > 0, dev / bound, 0.0)
        scale = np.maximum(np.abs(x[m]), np.abs(y[m]))
        rel = np.where(scale > 0, dev / scale, 0.0)
    k = int(np.argmax(ratio))
    cmp.max_rel = max(cmp.max_rel, float(np.max(rel)))
    if ratio[k] > cmp.max_ratio:
        cmp.max_ratio, cmp.worst = float(ratio[k]), f"{name}:{col}"
    if ratio[k] > 1:
        cmp.failures.append(
            f"{name}:{col}: row {int(rows[k])}: {x[m][k]:.12g} committed, {y[m][k]:.12g} re-run "
            f"({spec['kind']}: allowed {bound[k]:.3g})"
        )


def _compare_labels(name, col, spec, ta, tb, cmp) -> None:
    la, lb = ta.column(col).to_pylist(), tb.column(col).to_pylist()
    if la == lb:
        return
    if spec is None or spec["kind"] != "exact":
        cmp.text_changes.append(f"{name}:{col}")
        return
    for i, (x, y) in enumerate(zip(la, lb)):
        if x != y:
            row = ta.column("claim")[i].as_py() if "claim" in ta.column_names else f"row {i}"
            cmp.failures.append(f"{name}: {col} of {row} changed: {x} -> {y}")


def _read(p: Path, cmp: Comparison, side: str) -> pa.Table | None:
    try:
        return pq.read_table(p)
    except (OSError, pa.ArrowException, ValueError) as e:
        first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
        cmp.failures.append(f"{p.name}: the {side} file cannot be read ({first})")
        return None


def compare_tables(a: Path, b: Path, cmp: Comparison, mode: str = "full") -> None:
    """Compare committed table ``a`` with re-run table ``b`` into ``cmp`` (``mode``: ``full``,
    or ``mc`` for a re-run with fewer trials)."""
    name = a.name
    ta, tb = _read(a, cmp, "committed"), _read(b, cmp, "re-run")
    if ta is None or tb is None:
        return
    if ta.column_names != tb.column_names:
        diff = sorted(set(ta.column_names) ^ set(tb.column_names)) or "their order"
        cmp.failures.append(f"{name}: columns differ ({diff})")
        return
    specs, sb = _specs(a, b)
    if ta.num_rows != tb.num_rows:
        if mode == "full":
            cmp.failures.append(f"{name}: {ta.num_rows} rows committed, {tb.num_rows} re-run")
        else:
            cmp.not_compared.append(f"{name} ({ta.num_rows} rows committed, {tb.num_rows})")
        return
    for c in ta.column_names:
        ca, cb = ta.column(c), tb.column(c)
        spec = _spec(specs, name, c, ca.type)
        if mode == "mc" and spec is not None and not _at_mc_level(spec):
            continue
        numeric = all(pa.types.is_floating(t) or pa.types.is_integer(t) for t in (ca.type, cb.type))
        if numeric and spec is not None:
            _compare_numbers(name, c, spec, ta, tb, sb.get(c), mode, cmp)
        elif mode == "full" or spec is not None:
            _compare_labels(name, c, spec, ta, tb, cmp)


def _at_mc_level(spec: dict) -> bool:
    """Compared against a run with fewer trials: analytic columns, MC statistics, chains."""
    return bool(spec.get("analytic")) or spec["kind"] in ("mc", "chain")


def compare_dirs(
    committed: Path, rerun: Path, study: str | None = None, mode: str = "full"
) -> Comparison:
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
        compare_tables(committed / f, rerun / f, cmp, mode)
    return cmp


# --- re-running -------------------------------------------------------------------------------


def _machine() -> dict:
    return {
        "machine": platform.machine(),
        "system": platform.system(),
        "processor": platform.processor() or platform.machine(),
        "cpus": os.cpu_count(),
        **(
            {"openblas_coretype": os.environ["OPENBLAS_CORETYPE"]}
            if "OPENBLAS_CORETYPE" in os.environ
            else {}
        ),
        **({"sim_no_jit": os.environ["SIM_NO_JIT"]} if os.environ.get("SIM_NO_JIT") else {}),
        **versions(),
    }


def study_dirs(results: Path, only: list[str] | None = None) -> list[tuple[Path, str]]:
    """(directory, study) of every study with committed results, or of those named in
    ``only`` (a study or its directory name); VerifyError for none or an unknown name."""
    results = Path(results)
    if not results.is_dir():
        raise VerifyError(f"--results: {results} is not a directory")
    found = []
    for d in sorted(p for p in results.iterdir() if (p / "claims.parquet").is_file()):
        try:
            study = read_provenance(d / "claims.parquet").get("study") or d.name
        except (OSError, pa.ArrowException, ValueError):
            study = d.name  # a damaged file: the comparison names it
        found.append((d, str(study)))
    if not found:
        raise VerifyError(f"--results: no study results in {results} (no */claims.parquet)")
    if only:
        names = {n for d, s in found for n in (s, d.name)}
        unknown = [s for s in only if s not in names]
        if unknown:
            raise VerifyError(
                f"--study: no results of {', '.join(map(repr, unknown))} in {results} "
                f"(there are: {', '.join(sorted(d.name for d, _ in found))})"
            )
        found = [(d, s) for d, s in found if s in only or d.name in only]
    return found


def _target(scratch: Path, name: str) -> tuple[Path, bool]:
    """Where to re-run, and whether it holds an earlier re-run to replace (``--overwrite``).
    Anything else already there is refused: verify deletes nothing it did not write."""
    target = scratch / name
    if not target.exists() and not target.is_symlink():
        return target, False
    record = read_record(target) if target.is_dir() and not target.is_symlink() else None
    if record is not None:
        listed = {f.split("/")[0] for f in record.get("files", [])}  # what its run wrote
        foreign = [p.name for p in target.iterdir() if not _ours(p) and p.name not in listed]
        if foreign:
            raise VerifyError(
                f"--scratch: {target} holds {foreign[0]!r}, which the suite did not write: "
                "refusing to replace it"
            )
        return target, True
    raise VerifyError(
        f"--scratch: {target} exists and is not a results directory of the suite "
        "(no run.json): refusing to replace it"
    )


def _ours(p: Path) -> bool:
    """A file or directory a study run writes into its results directory."""
    if p.is_symlink():
        return False
    if p.is_dir():
        return p.name in ("trials", "cells")
    return p.name == "run.json" or p.suffix in (".parquet", ".png", ".xml")


def rerun_study(
    d: Path, study: str, target: Path, overwrite: bool, workers: int, extra: list[str]
) -> str | None:
    """Run the study of committed results ``d`` into ``target``; the failure, or None."""
    studies_dir = Path("studies")
    # a study kind with several example files (network_*) is named by its directory
    sf = studies_dir / f"{d.name}.toml"
    sf = sf if sf.is_file() else studies_dir / f"{study}.toml"
    if not sf.is_file():
        return f"no study file {studies_dir / (d.name + '.toml')} to re-run"
    cmd = [sys.executable, "-m", "sim", "run", str(sf), "--out", str(target), "--quiet"]
    cmd += ["--workers", str(workers), *(["--overwrite"] if overwrite else []), *extra]
    print(f"sim verify: re-running {d.name}", file=sys.stderr, flush=True)
    r = subprocess.run(cmd)
    return None if r.returncode == 0 else f"the re-run exited with {r.returncode}"


def verify(
    results: Path,
    scratch: Path,
    workers: int = 1,
    only: list[str] | None = None,
    rerun: bool = True,
    extra: list[str] | None = None,
    mode: str = "full",
) -> list[Comparison]:
    """Re-run each study with committed results into ``scratch`` and compare (``rerun=False``:
    compare with what ``scratch`` holds). ``extra``: further ``sim run`` arguments (``--trials
    N``, ``--set K=V``); ``mode``: ``full``, or ``mc`` for a re-run with fewer trials."""
    scratch = Path(scratch)
    if scratch.exists() and not scratch.is_dir():
        raise VerifyError(f"--scratch: {scratch} is not a directory")
    todo = study_dirs(results, only)
    if scratch.resolve() == Path(results).resolve() or Path(results).resolve() in (
        scratch.resolve().parents
    ):
        raise VerifyError(f"--scratch: {scratch} is (inside) the committed results {results}")
    # every target checked before anything runs: a foreign directory stops it at once
    replace = {d: _target(scratch, d.name)[1] for d, _ in todo} if rerun else {}
    out = []
    for d, study in todo:
        target = scratch / d.name
        if rerun:
            overwrite = replace[d]
            why = rerun_study(d, study, target, overwrite, workers, extra or [])
            if why:
                c = Comparison(d.name)
                c.failures.append(why)
                out.append(c)
                continue
        elif not target.is_dir():
            c = Comparison(d.name)
            c.failures.append(f"no re-run in {target}")
            out.append(c)
            continue
        out.append(compare_dirs(d, target, d.name, mode))
    return out


# --- the record and the report ----------------------------------------------------------------


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
    made = _committed_on(Path(results))
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
        "Parquet column with the committed one by the rule declared for the kind of number it "
        "holds (docs/reproducibility.md): exact for labels, counts and decisions; within the "
        f"bound of its conditioning for arithmetic (by default {DEFAULT_RTOL:g} relative); "
        "within a fraction of its Monte-Carlo standard error for a Monte-Carlo statistic and "
        "its Monte-Carlo interval for a chain's output; modulo the period for an angle. A "
        f"changed verdict fails. {made}\n\n"
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


def _committed_on(results: Path) -> str:
    """Which machine, numerical path and versions produced the committed results (from the
    provenance of the studies' claims tables), as a sentence."""
    seen = set()
    for p in sorted(results.glob("*/claims.parquet")):
        try:
            prov = read_provenance(p)
        except (OSError, pa.ArrowException, ValueError):
            continue
        n, v = prov.get("numerics") or {}, prov.get("versions") or {}
        where = (
            " ".join(str(n[k]) for k in ("system", "machine") if k in n) or "an unrecorded machine"
        )
        path = ", ".join(f"{k}={n[k]}" for k in ("OPENBLAS_CORETYPE", "SIM_NO_JIT") if k in n)
        ver = ", ".join(f"{k} {x}" for k, x in sorted(v.items()))
        seen.add(f"{where}{f' ({path})' if path else ''} with {ver}" if ver else where)
    if not seen:
        return ""
    return "The committed results were made on " + "; and on ".join(sorted(seen)) + "."


# --- command line -----------------------------------------------------------------------------


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one line, exit 2 (main prints it)
        raise VerifyError(message)


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="python -m sim.report.verify", description=__doc__.splitlines()[0])
    p.add_argument("--results", default="results", help="the committed results (default: results)")
    p.add_argument(
        "--scratch", help="where to re-run (default: a temporary directory, removed after)"
    )
    p.add_argument("--workers", type=int, default=1, help="workers of each re-run")
    p.add_argument("--study", action="append", help="only this study (repeatable)")
    p.add_argument(
        "--no-rerun",
        action="store_true",
        help="compare with the re-runs already in --scratch (e.g. made on another machine)",
    )
    p.add_argument(
        "--trials",
        type=int,
        help="re-run with this many trials and compare at the Monte-Carlo level",
    )
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="a config override of the re-runs (repeatable; with --trials)",
    )
    p.add_argument(
        "--no-record", action="store_true", help="do not write <results>/reproducibility.parquet"
    )
    return p


def _check_args(a) -> None:
    if a.workers < 1:
        raise VerifyError(f"--workers: must be at least 1, not {a.workers}")
    if a.trials is not None and a.trials < 2:
        raise VerifyError(f"--trials: must be at least 2, not {a.trials}")
    if a.set and a.trials is None:
        raise VerifyError("--set: only with --trials (a re-run with other inputs is not a check)")
    if a.no_rerun and not a.scratch:
        raise VerifyError("--no-rerun: needs --scratch (the directory of the re-runs)")
    for s in a.set:
        if "=" not in s:
            raise VerifyError(f"--set: {s!r} is not KEY=VALUE")


def _print(comps: list[Comparison]) -> None:
    for c in comps:
        status = "ok" if c.ok else "FAILED"
        print(
            f"{c.study}: {status}; {c.files} files; largest relative deviation "
            f"{c.max_rel:.2g}; largest deviation/tolerance {c.max_ratio:.2g} ({c.worst})"
        )
        for f in c.failures[:20]:
            print(f"  {f}")
        if c.not_compared:
            print(f"  not compared (rows depend on the trials): {', '.join(c.not_compared)}")


def main(argv: list[str] | None = None) -> int:
    try:
        a = _parser().parse_args(argv)
        _check_args(a)
        extra = [] if a.trials is None else ["--trials", str(a.trials)]
        extra += [x for s in a.set for x in ("--set", s)]
        mode = "full" if a.trials is None else "mc"
        with tempfile.TemporaryDirectory(prefix="sim-verify-") as tmp:
            comps = verify(
                Path(a.results),
                Path(a.scratch or tmp),
                workers=a.workers,
                only=a.study,
                rerun=not a.no_rerun,
                extra=extra,
                mode=mode,
            )
    except VerifyError as e:
        print(f"sim verify: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("sim verify: interrupted", file=sys.stderr)
        return 130
    _print(comps)
    if not a.no_record and mode == "full" and not a.study:
        write_record(Path(a.results), comps)
    return 0 if all(c.ok for c in comps) else 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
