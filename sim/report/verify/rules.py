"""The comparison rules of ``make verify``: a committed table against a re-run's, column by
column, each by the rule declared with it for the kind of number it holds
(:mod:`sim.mc.tolerance`; the list of rules: :mod:`sim.report.verify`)."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from sim.mc import tolerance as tl
from sim.mc.storage import read_provenance, read_record, read_tolerances
from sim.mc.table_shape import NUMBERS, kind

__all__ = [
    "compare_dirs",
    "compare_tables",
    "tables_digest",
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
    tables: str | None = None  # the committed tables compared (:func:`tables_digest`)
    overrides: list[str] = field(default_factory=list)  # the run's, re-run with (run.json)

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


def _specs(a: Path, b: Path, ta: pa.Table, tb: pa.Table) -> tuple[dict, dict]:
    """The committed table's declarations (else the re-run's), and the re-run's own; a
    ValueError naming the table whose declarations are not as sim writes them (its schema
    metadata edited: not JSON, not an object of columns, a rule of no kind), which the
    comparison read as they stood (a JSONDecodeError or TypeError traceback)."""
    sa, sb = _declared(a, ta, "committed"), _declared(b, tb, "re-run")
    legacy = _legacy(read_provenance(a), a.name)
    return {**sb, **legacy, **sa}, sb


def _declared(p: Path, t: pa.Table, side: str) -> dict:
    try:
        specs = read_tolerances(p)
        if not isinstance(specs, dict) or not all(isinstance(v, dict) for v in specs.values()):
            raise ValueError("not an object of column rules")
        return tl.validate(specs, t)
    except (ValueError, TypeError, RecursionError) as e:
        raise ValueError(
            f"{p.name}: the {side} table's tolerance declarations (schema metadata "
            f"'sim.tolerances') are not as sim writes them ({str(e)[:120]})"
        ) from None


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
    if p.exists() and not p.is_file():  # a pipe named *.parquet: its read waited for ever
        cmp.failures.append(f"{p.name}: the {side} file is not a regular file")
        return None
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
    try:
        specs, sb = _specs(a, b, ta, tb)
    except ValueError as e:
        cmp.failures.append(str(e))
        return
    if ta.num_rows != tb.num_rows:
        if mode == "full":
            cmp.failures.append(f"{name}: {ta.num_rows} rows committed, {tb.num_rows} re-run")
        else:
            cmp.not_compared.append(f"{name} ({ta.num_rows} rows committed, {tb.num_rows})")
        return
    for c in ta.column_names:
        ca, cb = ta.column(c), tb.column(c)
        ka, kb = kind(ca.type), kind(cb.type)
        if ka != kb and not {ka, kb} <= NUMBERS:  # numbers as text, true/false: not compared
            cmp.failures.append(f"{name}:{c}: {ka} committed, {kb} re-run")
            continue
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


def tables_digest(d: Path) -> str | None:
    """The sha256 of the tables a comparison reads in the results ``d`` (every ``*.parquet``
    but :data:`SKIP`, by name and content), or None when ``d`` or a table cannot be read: what
    the reproducibility record says it checked, so that results re-run, copied in or edited
    since are not shown as verified. Content only: a copy (``cp``, ``tar``, a clone) keeps it."""
    h = hashlib.sha256()
    try:
        for p in sorted(q for q in Path(d).glob("*.parquet") if q.name not in SKIP):
            if not p.is_file():  # a pipe's read waited for a writer: verify hung
                return None
            h.update(p.name.encode("utf-8", "surrogateescape") + b"\0")
            h.update(hashlib.sha256(p.read_bytes()).digest())
    except OSError:
        return None
    return h.hexdigest()


def compare_dirs(
    committed: Path, rerun: Path, study: str | None = None, mode: str = "full"
) -> Comparison:
    """Compare every Parquet table of ``committed`` (a study's results) with ``rerun``."""
    committed, rerun = Path(committed), Path(rerun)
    cmp = Comparison(study or committed.name)
    fa, fb = _tables(committed), _tables(rerun)
    for missing in sorted(fa ^ fb):
        cmp.failures.append(
            f"{missing}: only in the {'committed' if missing in fa else 're-run'} results"
        )
    for f in sorted(fa & fb):
        cmp.files += 1
        compare_tables(committed / f, rerun / f, cmp, mode)
    return cmp


def _tables(d: Path) -> set[str]:
    """The tables of the results ``d`` that verify compares: those its run record lists
    (``table_sha256``), else (an older version's record) every ``*.parquet``. A copy the user
    kept beside them (``claims_old.parquet``) failed the study as "only in the committed
    results"; it is not the run's, and is left out."""
    found = {p.name for p in d.glob("*.parquet") if p.name not in SKIP}
    sums = (read_record(d) or {}).get("table_sha256")
    listed = {k for k in sums if "/" not in k} if isinstance(sums, dict) else set()
    return found & listed if listed else found
