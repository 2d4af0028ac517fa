"""The reproducibility record of ``make verify`` (``<results>/reproducibility.parquet``: per
study the comparison and the tables it checked) and the report's *Reproducibility* section."""

from __future__ import annotations

import os
import platform
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

from sim.mc.config import ConfigError
from sim.mc.outputs import results_dirs
from sim.mc.overrides import listed
from sim.mc.storage import PATH_VARIABLES, numerics, read_provenance, versions, write_table
from sim.report.tables import fmt, md_table
from sim.report.verify.rules import DEFAULT_RTOL, Comparison, tables_digest

__all__ = ["write_record", "markdown", "not_a_record"]


def _machine() -> dict:
    """The machine and numerical path of the re-runs, as every run records its own
    (:func:`sim.mc.storage.numerics`, under the same keys: the record named them
    ``openblas_coretype``/``sim_no_jit`` in a copy of its own, and recorded an empty
    ``OPENBLAS_CORETYPE`` that OpenBLAS takes as unset), with the processor, the CPU count
    and the package versions."""
    return {
        **numerics(),
        "processor": platform.processor() or platform.machine(),
        "cpus": os.cpu_count(),
        **versions(),
    }


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
        "tables_sha256": [c.tables or "" for c in comps],  # what was checked: markdown()
        # the overrides of the run each re-run was made with (its run.json's; none: the study
        # file as written): the record said "yes" without saying of which config
        "overrides": pa.array([list(c.overrides) for c in comps], pa.list_(pa.string())),
    }
    return write_table(
        Path(results) / "reproducibility.parquet",
        pa.table(cols),
        {"study": "verify", "machine": _machine()},
    )


def markdown(results: Path) -> str:
    """The report's *Reproducibility* section from ``reproducibility.parquet`` (empty if none)."""
    p = Path(results) / "reproducibility.parquet"
    if not p.is_file():
        return ""
    t, m = _read(p)
    since = _checked_since(Path(results), t)
    older = not any(r.get("tables_sha256") for r in t)
    ver = ", ".join(  # a variable of the numerical path as it is set (OPENBLAS_CORETYPE=...)
        f"{k}={v}" if k.isupper() else f"{k} {v}"
        for k, v in m.items()
        if k not in ("machine", "system", "processor", "cpus")
    )
    made = _committed_on(Path(results))
    rows = [
        [
            r["study"],
            r["files"],
            fmt(r["max_rel_dev"], 2),
            fmt(r["max_dev_over_tol"], 2),
            f"`{r['worst']}`" if r["worst"] else "",
            (since.get(r["study"]) or _verdict(r, older)) + _with(r.get("overrides")),
            r["text_columns_changed"],
        ]
        for r in t
    ]
    made += _not_checked(Path(results), t, since)
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


#: the columns of every record written so far (0a43b332 on; ``tables_sha256`` since 9d90f3a7)
_COLUMNS = ("study", "files", "max_rel_dev", "max_dev_over_tol", "worst", "first_failure")
_COLUMNS += ("text_columns_changed", "ok")


def not_a_record(p: Path) -> str | None:
    """Why the file ``p`` is not a record of make verify (truncated, another table, a file of
    the user's in its place, a pipe or a device), else None. A FIFO there is named unread: make
    verify hung before any re-run, opening it for its first bytes, deaf to Ctrl-C and SIGTERM."""
    if not p.is_file():
        return "it is not a regular file (a pipe, a device or a directory)"
    try:
        t = pq.read_schema(p)
        prov = read_provenance(p)
        m = prov.get("machine", {}) if isinstance(prov, dict) else None
        lacks = [c for c in _COLUMNS if c not in t.names]
        why = f"it has no column {lacks[0]!r}" if lacks else None
        why = why or (None if isinstance(m, dict) else "its provenance names no machine")
        why = why or (None if prov.get("study") == "verify" else "make verify did not write it")
    except (pa.ArrowException, ValueError, AttributeError, OSError) as e:
        why = f"{type(e).__name__}: {str(e).splitlines()[0][:160]}"
    return why


def _read(p: Path) -> tuple[list[dict], dict]:
    """The rows and the machine of the record ``p``; one that is not a record of make verify
    (truncated, or another table in its place) is a :class:`ConfigError` naming it (the
    report blamed the last study table it had read: "wolf_polynomial/claims.parquet ... is
    not as sim wrote it (column 'kind': KeyError: 'study'); run its study again")."""
    why = not_a_record(p)
    if why is not None:
        raise ConfigError(
            "--results",
            f"{p} is not a record of make verify ({why}): move it away (make verify then "
            "writes its record there)",
        )
    try:
        return pq.read_table(p).to_pylist(), read_provenance(p).get("machine", {})
    except (pa.ArrowException, ValueError, OSError) as e:
        why = f"{type(e).__name__}: {str(e).splitlines()[0][:160]}"
        raise ConfigError("--results", f"{p} cannot be read ({why}): move it away") from None


def _verdict(r: dict, older: bool) -> str:
    """A row's *within tolerance* cell: yes or no, of the tables the row names by their hash.
    A row that names none vouches for no tables there now: a record of an older version
    (``older``: before ``tables_sha256``; it read "yes" for results re-run at any commit
    since), or a check that could not read the tables."""
    said = "yes" if r["ok"] else f"no: {r['first_failure']}"
    if r.get("tables_sha256"):
        return said if r["ok"] else f"**{said[:2]}**{said[2:]}"
    who = (
        "checked by an older version, which did not record the tables"
        if older
        else ("the check did not record the tables")
    )
    return f"**not checked now**: {who} (it said {said})"


def _with(overrides) -> str:
    """`` (re-run with the run's overrides: k=v, ...)`` for a row whose results were made with
    overrides (a record of an older version has no such column: "")."""
    if not overrides or not isinstance(overrides, list):
        return ""
    return f" (re-run with the run's overrides: {listed([str(t) for t in overrides])})"


def _checked_since(results: Path, rows: list[dict]) -> dict[str, str]:
    """Per study of the record whose results are no longer the tables it checked (their
    :func:`tables_digest` differs: re-run by make reproduce since, in another terminal while
    verify ran, or copied in or edited by hand; or removed), what the report says instead of
    its verdict. A record that did not say what it checked (an older version's) is taken as
    it is."""
    out = {}
    for r in rows:
        want, name = r.get("tables_sha256"), str(r.get("study"))
        if not want or name in ("", ".", "..") or "/" in name:  # (a record edited by hand)
            continue
        d = results / name
        if not (d / "claims.parquet").is_file():
            out[r["study"]] = "**not checked now**: these results are no longer there"
        elif tables_digest(d) != want:
            out[r["study"]] = "**not checked now**: its tables changed after this check"
    return out


def _not_checked(results: Path, rows: list[dict], since: dict) -> str:
    """The sentences that say which results the record does not vouch for: those changed
    since (:func:`_checked_since`), studies with results but no row, and every study when the
    record does not say which tables it checked."""
    out = ""
    if since:
        out += (
            f" The results of {len(since)} of these studies are not the ones checked (their "
            "tables were re-run, replaced or edited since): run make verify again."
        )
    recorded = {str(r.get("study")) for r in rows}
    new = sorted(
        d.name
        for d in results_dirs(results)
        if (d / "claims.parquet").is_file() and d.name not in recorded
    )
    if new:
        out += f" Not checked: {', '.join(new)} (no row in the record)."
    if rows and not any(r.get("tables_sha256") for r in rows):
        out += (
            " This record does not say which tables it checked (an older version wrote it): "
            "none of these results is shown as checked; run make verify again."
        )
    return out


def _committed_on(results: Path) -> str:
    """Which machine, numerical path and versions produced the committed results (from the
    provenance of the studies' claims tables), as a sentence."""
    seen = set()
    for p in sorted(d / "claims.parquet" for d in results_dirs(results)):
        if not p.is_file():
            continue
        try:
            prov = read_provenance(p)
        except (OSError, pa.ArrowException, ValueError):
            continue
        n, v = prov.get("numerics") or {}, prov.get("versions") or {}
        where = (
            " ".join(str(n[k]) for k in ("system", "machine") if k in n) or "an unrecorded machine"
        )
        path = ", ".join(f"{k}={n[k]}" for k in PATH_VARIABLES if k in n)
        ver = ", ".join(f"{k} {x}" for k, x in sorted(v.items()))
        seen.add(f"{where}{f' ({path})' if path else ''} with {ver}" if ver else where)
    if not seen:
        return ""
    return "The committed results were made on " + "; and on ".join(sorted(seen)) + "."
