"""One results directory on its own, read from its Parquet files alone: the verdict counts and
headline rows printed at the end of ``sim run`` and by ``sim show DIR``, and the directory's
``README.md`` (its claims, its study's report section, or its sweep table).

A directory is a study run (``claims.parquet``) or a ``[sweep]`` run (``sweep.parquet``).
"""

from __future__ import annotations

import hashlib
import math
import os
import shlex
from collections import Counter
from pathlib import Path
from typing import Callable

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from sim.claims.rules import NOT_APPLICABLE, PREDICTION_VERDICTS
from sim.escapes import printable
from sim.mc.config import ConfigError
from sim.mc.export_edits import README_KEY
from sim.mc.file_kind import odd_table
from sim.mc.storage import atomic_path, read_provenance, read_record, write_record
from sim.mc.table_shape import kind
from sim.places import held_results, show_target
from sim.report.claimtext import interval_text, sim_text
from sim.report.config_diff import sweep_config_line
from sim.report.labels import column
from sim.report.off_paper import off_note, off_setup, sweep_off_note
from sim.report.papers import paper_name
from sim.report.read import TableError, checked_table, columns, forget, records
from sim.report.sweep import level_texts, sweep_markdown
from sim.report.tables import fmt, md_code, md_text
from sim.report.text_table import cut, text_table

__all__ = [
    "VERDICT_ORDER",
    "verdict_line",
    "off_setup",
    "headline_rows",
    "region_line",
    "terminal_summary",
    "converged_line",
    "terminal_table",
    "run_markdown",
    "write_run_readme",
    "README_MARK",
]

#: verdicts in the order they are counted (others follow in alphabetical order)
VERDICT_ORDER = (
    *PREDICTION_VERDICTS,
    "erratum",
    "paper consistent",
    "not comparable",
    "input",
    "self-check",
    "self-check failed",
    "self-check undecided",
    "self-check not applicable",
    "finding",
)


def _kind_of(out: Path) -> str:
    out = Path(out)
    if (out / "claims.parquet").is_file():
        return "study"
    if (out / "sweep.parquet").is_file():
        return "sweep"
    if (odd := odd_table(out)) is not None:  # a FIFO there: not "there is none"
        raise ConfigError("DIR", odd)
    why = "is not a results directory (no claims.parquet or sweep.parquet)"
    raise ConfigError("DIR", f"{out} {why}{held_results(out)}")


def _counted_as(r: dict) -> str:
    """The heading a claim row is counted under in a verdict line."""
    if r.get("kind") == "paper-check" and r["verdict"] == "holds":
        return "paper consistent"
    if r.get("kind") == "self-check" and r["verdict"] == NOT_APPLICABLE:
        return "self-check not applicable"  # off the paper's setup: its outcome is not this run's
    if r.get("kind") == "self-check" and r.get("outcome") not in (None, "holds"):
        return "self-check failed" if r["outcome"] == "fails" else "self-check undecided"
    return r["verdict"]


def verdict_cell(r: dict) -> str:
    """A claim's verdict as its row shows it: an input's or a self-check's own outcome in
    brackets (``self-check (inconclusive)``), in README.md's table (:mod:`.markdown`) too; the counts
    count it apart (``sim show`` said ``self-check`` of one its counts call undecided)."""
    out = r.get("outcome") if r.get("kind") in ("input", "self-check") else None
    return r["verdict"] + (f" ({out})" if out else "")


def verdict_line(claims: list[dict]) -> str:
    """``"14 claims: 6 holds, 2 fails, ..."`` (every verdict value, in :data:`VERDICT_ORDER`);
    a paper-check that holds (the paper's own arithmetic) counts as ``paper consistent``, as in
    REPORT.md's counts per study, not as a prediction that holds; a self-check that did not
    hold its own rule counts apart (``self-check failed``, ``self-check undecided``: as in
    REPORT.md), not as one that did, and one whose reference is the paper's setup's on a run
    off it apart again (``self-check not applicable``), not as a failed one."""
    c = Counter(_counted_as(r) for r in claims)
    order = [v for v in VERDICT_ORDER if c[v]] + sorted(v for v in c if v not in VERDICT_ORDER)
    return f"{len(claims)} claims: " + ", ".join(f"{c[v]} {v}" for v in order)


def headline_rows(claims: list[dict], n: int | None = None) -> list[dict]:
    """The claims marked ``headline`` (at most ``n``), in the claim book's order."""
    rows = [r for r in claims if r.get("headline")]
    return rows if n is None else rows[:n]


def region_line(out: Path) -> str | None:
    """One line on ``consistent_region.parquet`` if the directory has it: the number of
    accepted input vectors and each input's range over them (input columns are the numeric
    ones, named with their units)."""
    p = Path(out) / "consistent_region.parquet"
    if not p.is_file():
        return None
    t = checked_table(p)
    parts = []
    for name in t.column_names:
        if name == "confirmed" or name.endswith("__value"):
            continue
        vals = [v for v in t.column(name).to_pylist() if isinstance(v, (int, float))]
        vals = [v for v in vals if not isinstance(v, bool) and math.isfinite(v)]
        if vals:
            lo, hi = min(vals), max(vals)
            parts.append(f"{name} {fmt(lo)}" + ("" if lo == hi else f"–{fmt(hi)}"))
    if "part" in t.column_names:  # a region of parts: say how many vectors each part holds,
        # as the verdicts say "holds at all 2261 points" of their part, not of the 2289
        n = Counter(t.column("part").to_pylist())
        parts.insert(0, ", ".join(f"{k} {v}" for k, v in n.items()))
    where = f" ({'; '.join(parts)})" if parts else ""
    return f"consistent region: {t.num_rows} accepted input vectors{where}"


def converged_line(out: Path) -> str | None:
    """One line when some Monte-Carlo trial of the directory (``trials.parquet``'s
    ``<adjustment>.converged`` columns: agnard_block's) has an adjustment that did not
    converge: how many of the trials, and of each adjustment, left as the solver stopped
    (the iteration limit, or flagged singular). Said only in the README's "every adjustment
    converged: no" before (a control weight between the engine's singular limit and about
    1e-5 of the pass weight: some trials stop at the limit); None when every one converged."""
    p = Path(out) / "trials.parquet"
    if not p.is_file():
        p = Path(out) / "summary.parquet"
    try:  # a table that is not Parquet is named as such (it was blamed on claims.parquet's
        # column last read: "claims.parquet ... (column 'verdict': ArrowInvalid: ...)")
        return _trials_converged(p) if p.name == "trials.parquet" else _summary_converged(p)
    except pa.ArrowException as e:
        raise TableError(p, f"cannot be read ({str(e).splitlines()[0][:200]})") from None


def _trials_converged(p: Path) -> str | None:
    """The line of a ``trials.parquet`` with ``<adjustment>.converged`` columns."""
    names = [c for c in pq.read_schema(p).names if c.endswith(".converged")]
    if not names:
        return None
    t = checked_table(p).select(names)
    for c in names:  # as text, "False" read as true (numpy): every trial converged
        if not pa.types.is_boolean(t.column(c).type) or t.column(c).null_count:
            what = f"{kind(t.column(c).type)}" + (", with nulls" if t.column(c).null_count else "")
            raise TableError(p, f"column {c!r} is {what}, not a trial's true or false")
    bad = {c: ~np.asarray(t.column(c).to_numpy(zero_copy_only=False), bool) for c in names}
    some = np.any(list(bad.values()), axis=0)
    if not some.any():
        return None
    each = ", ".join(
        f"{c.removesuffix('.converged')} {int(b.sum())}" for c, b in bad.items() if b.any()
    )
    return (
        f"not converged: {int(some.sum()):,} of {t.num_rows:,} trials in some adjustment "
        f"({each}), their values as the solver left them (at its iteration limit, or singular)"
    )


def _summary_converged(p: Path) -> str | None:
    """The line of a ``summary.parquet`` with ``trials`` and ``converged`` (the network
    kind's): a run of which 31 of 40 trials did not converge said so only in its README's
    summary sentence and its claims' notes (lead32)."""
    if not p.is_file() or not {"trials", "converged"} <= set(pq.read_schema(p).names):
        return None
    t = checked_table(p).select(["trials", "converged"]).to_pylist()
    if len(t) != 1:
        raise TableError(p, f"has {len(t)} rows, not one")
    for c, v in t[0].items():  # (a count as text or null: the line left out without a word)
        if type(v) is not int:
            raise TableError(p, f"column {c!r} holds {v!r:.40}, not a count of trials")
    n, ok = t[0]["trials"], t[0]["converged"]
    if ok >= n:
        return None
    return (
        f"not converged: {n - ok:,} of {n:,} trials (the claims' notes say how each "
        "Monte-Carlo estimate takes them)"
    )


def _value_text(r: dict) -> str:
    return "" if r["verdict"] == "not comparable" else sim_text(r)


def _interval(r: dict) -> str:
    return "" if r["verdict"] == "not comparable" else interval_text(r)


def terminal_summary(out: Path, n: int = 5, shown: str | None = None, get_study=None) -> str:
    """The closing lines of a run: the verdict counts, up to ``n`` headline rows (value,
    95 % interval, verdict), the region line, and the path of the directory's README.md
    (under ``shown``, the directory as the user named it, if given; one of the user's kept
    there is said to be no report of the run); ``get_study`` given, a run
    off the paper's setup says so as its README.md does (:func:`off_note`)."""
    out = Path(out)
    if _kind_of(out) == "sweep":
        t = columns(out / "sweep.parquet")
        ok = sum(bool(f) for f in t.get("feasible", []))
        lines = [f"sweep: {ok} of {len(t.get('feasible', []))} cells ran"]
        lines += [off] if (off := sweep_off_note(out, get_study)) else []
    else:
        claims = records(out / "claims.parquet")
        lines = [verdict_line(claims)]
        if (conv := converged_line(out)) is not None:
            lines.append(conv)
        lines += [off] if (off := off_note(out, get_study)) else []
        for r in headline_rows(claims, n):
            ci = _interval(r)
            lines.append(
                f"  {r['claim']}: {_value_text(r)}"
                + (f" {ci}" if ci else "")
                + f" {verdict_cell(r)}"
            )
        if (reg := region_line(out)) is not None:
            lines.append(reg)
    readme = Path(shown or out) / "README.md"
    if _ours(out / "README.md"):
        lines.append(f"report: {readme}")
    elif os.path.lexists(out / "README.md"):  # a user's, kept: "report:" sent them to it
        lines.append(
            f"report: not written ({readme} is yours, kept; sim show --markdown "
            f"{shown or out} prints the run's)"
        )
    return "\n".join(lines)


def terminal_table(
    out: Path, width: int = 100, design: Callable | None = None, get_study=None
) -> str:
    """Every claim of a results directory as a plain-text table (claim, simulated, 95 %
    interval, verdict), then the counts; a sweep directory as its cells. ``design``: see
    :func:`run_markdown` (what the run changed from its study file, a line at the end);
    ``get_study``: the study's object by its name, to say a run off the paper's setup
    (:func:`off_note`)."""
    out = Path(out)
    study = _kind_of(out) == "study"
    cfg = read_provenance(out / "claims.parquet") if study else _sweep_prov(out)
    changed = sweep_config_line(cfg, out.name, design)  # a study's: config_line
    tail = "" if changed is None else f"\n{changed}"
    if _kind_of(out) == "sweep":  # each cell with its swept values (cell0003_r0 alone named
        t = columns(out / "sweep.parquet")  # no setting), and where its claims are
        keys = [k for k in cfg["sweep_keys"] if k in t]
        texts = {k: column(level_texts(list(t[k])), lambda s: cut(s, 24), 24) for k in keys}
        rows = [
            [
                t["label"][i],
                *[texts[k][i] for k in keys],
                "yes" if t["feasible"][i] else f"no: {t['reason'][i]}",
            ]
            for i in range(len(t["label"]))
        ]
        table = text_table(["cell", *keys, "feasible"], rows, width)
        ok = sum(bool(f) for f in t["feasible"])
        off = sweep_off_note(out, get_study)
        return (
            (  # what was swept first, the command to paste (doors25a) last but a note
                f"{table}\n\n{tail[1:] + chr(10) if tail else ''}sweep: {ok} of {len(rows)} cells "
                f"ran; every claim of every cell: sim show {shlex.quote(str(out))} --markdown"
            )
            + (f"\n{off}" if off else "")
        )
    claims = records(out / "claims.parquet")
    rows = [[r["claim"], _value_text(r), _interval(r), verdict_cell(r)] for r in claims]
    table = text_table(["claim", "simulated", "95% interval", "verdict"], rows, width)
    conv = converged_line(out)
    off = off_note(out, get_study)
    notes = "".join(f"\n{x}" for x in (conv, off) if x)
    return table + "\n\n" + verdict_line(claims) + notes + tail


def _sweep_prov(out: Path) -> dict:
    """The provenance of a sweep's ``sweep.parquet``; a :class:`TableError` naming it when it
    names no study and swept keys (rewritten by a tool that drops schema metadata: its cells
    were listed without their swept values, or "a table ... (KeyError: 'study')")."""
    p = Path(out) / "sweep.parquet"
    prov = read_provenance(p)
    prov = prov if isinstance(prov, dict) else {}
    keys = prov.get("sweep_keys")
    if not isinstance(prov.get("study"), str) or not isinstance(keys, list):
        raise TableError(
            p,
            "its provenance (schema metadata 'sim.provenance') names no study "
            "and swept keys: rewritten by a tool?",
        )
    if not all(isinstance(k, str) for k in keys):
        raise TableError(p, f"its provenance's swept keys are not names ({keys!r:.60})")
    return prov


def run_markdown(
    out: Path,
    get_study: Callable,
    name: str | None = None,
    design: Callable | None = None,
    where: Path | None = None,
) -> str:
    """The README.md of one results directory: what ran (study, paper, config), the verdict
    counts, the region line, then the study's own report section (claims, tables, figures:
    links relative to the directory) or the sweep's table. ``name``: the directory's name in
    its title (a run writes the README in its staging directory, ``.<name>.partial``);
    ``design``: a study file's config by its name (``sim.studies.design_config``), to name
    what the run changed from it (:mod:`sim.report.config_diff`); ``where``: the directory
    the README ends in (``out`` by default), which its ``sim show`` command names
    (:func:`sim.places.show_target`)."""
    out = Path(out)
    name = name or out.name
    forget()
    kind = _kind_of(out)
    src = out / ("claims.parquet" if kind == "study" else "sweep.parquet")
    prov = read_provenance(src) if kind == "study" else _sweep_prov(out)
    study = get_study(prov["study"])
    paper = paper_name(study.seed_file, full=True)
    head = [
        f"# {md_text(name)}: {study.title}",  # a directory name of the user's
        "",
        f"Study `{prov['study']}`"
        + (f", seed paper: {paper}." if paper else " (a declared network, no seed paper).")
        + " Written by `sim run` from this directory's Parquet files "
        f"({md_code(f'sim show {shlex.quote(show_target(where or out))}')} prints it again).",
        "",
    ]
    if (changed := sweep_config_line(prov, name, design)) is not None:  # a study's: config_line
        head += [f"**Configuration.** {changed}", ""]
    if kind == "sweep":
        if off := sweep_off_note(out, get_study):  # said once, at the top
            head += [f"**{off}.**", ""]
        body = sweep_markdown(out, ".")
    else:
        claims = records(src)
        head += [f"**Verdicts:** {verdict_line(claims)}.", ""]
        if off := off_setup(study, prov.get("config") or {}):  # said once, at the top
            head += [f"**{off[0].upper()}{off[1:]}.**", ""]
        body = study.report(out)
        # the region once: a study's own region section gives it (it read twice, as
        # "Consistent region: N accepted input vectors" and "**Consistent region.** ...")
        if (reg := region_line(out)) is not None and "**Consistent region.**" not in body:
            head += [reg[0].upper() + reg[1:] + ".", ""]
    return "\n".join(head) + "\n" + _relink(body, out.name) + "\n"


def _relink(body: str, name: str) -> str:
    """Study report sections link files as ``<dir>/file`` (relative to ``results/``); in the
    directory's own README they are relative to the directory."""
    return body.replace(f"]({name}/", "](")


#: the first line of every README.md the suite writes in a results directory: a README.md
#: without it is the user's, and is never replaced
README_MARK = (
    "<!-- written by sim from this directory's Parquet files; edited, it is yours: kept, "
    "and a run into the directory refused -->"
)
#: the mark of the versions that replaced an edited README.md ("edits are overwritten")
_OLD_MARKS = ("<!-- written by sim from this directory's Parquet files; edits are overwritten -->",)


def _ours(path: Path) -> bool:
    """True for a README.md the suite wrote (its mark on the first line) and has not been
    edited since (its sha256 the one its directory's run record holds, where it holds one:
    :mod:`sim.mc.export_edits`)."""
    if not path.is_file():  # a FIFO put in its place blocked sim report and a re-run: a
        return False  # user's file, never opened (as markdown._ours keeps REPORT.md's)
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            # the mark behind an editor's UTF-8 signature (Notepad's) is the mark: such a
            # README was the user's, never rebuilt and left stale without a word
            if f.readline().removeprefix("\ufeff").rstrip("\n") not in (README_MARK, *_OLD_MARKS):
                return False
        want = (read_record(path.parent) or {}).get(README_KEY)
        if isinstance(want, list):  # one being written (write_run_readme): either is ours
            return hashlib.sha256(path.read_bytes()).hexdigest() in want
        return not isinstance(want, str) or hashlib.sha256(path.read_bytes()).hexdigest() == want
    except (OSError, ValueError):
        return False


def _user_readme(path: Path) -> bool:
    return path.is_symlink() or (path.exists() and not _ours(path))


def write_run_readme(
    out: Path,
    get_study: Callable,
    name: str | None = None,
    final: Path | None = None,
    design: Callable | None = None,
) -> Path | None:
    """Write ``out/README.md`` (see :func:`run_markdown`; ``name``: the directory's name in
    it) atomically and list it among the files the run wrote (``run.json``, so a later run
    into the directory replaces it rather than keeping it as the user's). A README.md the
    suite did not write (no mark) is left as it is: returns None then, else the path.
    ``final``: the results directory that ``out``, a run's staging directory, replaces; a
    README.md of the user's there is kept as well (carried into the new results), and none is
    written."""
    out = Path(out)
    path = out / "README.md"
    if path.is_symlink() or (path.exists() and not _ours(path)):
        return None
    if final is not None and _user_readme(Path(final) / "README.md"):
        if path.exists():  # ours, of an earlier attempt: it would take the user's place
            path.unlink()
            rec = read_record(out)
            if rec is not None and "README.md" in (rec.get("files") or []):
                write_record(out, {**rec, "files": [f for f in rec["files"] if f != "README.md"]})
        return None
    text = README_MARK + "\n" + printable(run_markdown(out, get_study, name, design, final), True)
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()
    rec = read_record(out)  # its sha256: one edited by hand is the user's (kept, named)
    listed = rec is not None and isinstance(rec.get("files"), list)
    if listed and path.is_file():  # the record names both READMEs before the new one is put
        was = hashlib.sha256(path.read_bytes()).hexdigest()  # in place: a process killed
        if was != digest and rec.get(README_KEY) != [was, digest]:  # between the two renames
            write_record(out, {**rec, README_KEY: [was, digest]})  # left the suite's README
    with atomic_path(path) as tmp:  # taken as edited by hand (kept, a re-run refused)
        tmp.write_text(text, encoding="utf-8")
    if listed:
        new = {**rec, "files": sorted({*rec["files"], "README.md"}), README_KEY: digest}
        if new != read_record(out):
            write_record(out, new)
    return path
