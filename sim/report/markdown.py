"""``results/REPORT.md`` built from the Parquet files alone.

The report is a pure function of the result directories: it reads each study's
``claims.parquet`` (and whatever else the study's own ``report`` hook reads) and returns
Markdown. Nothing here runs a simulation.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import pyarrow as pa

from sim.claims.region import REGION_LEVEL, REGION_MIN_POINTS, REGION_SHARE
from sim.claims.rules import NOT_APPLICABLE, P_FAIL, PREDICTION_VERDICTS
from sim.escapes import printable
from sim.mc.config import ConfigError
from sim.mc.export_edits import changed_exports
from sim.mc.outputs import results_dirs
from sim.mc.paths import link_problem
from sim.mc.settle import reread
from sim.mc.storage import atomic_path, read_provenance
from sim.mc.table_edits import missing_cell
from sim.report.claimtext import interval_text, ref_text, sim_text
from sim.report.glance import VERDICT_TEXT as _VERDICT_TEXT
from sim.report.glance import by_paper, design_notes, main_and_variants, number, opening
from sim.report.papers import paper_name
from sim.report.read import (
    cannot_read,
    check_claims_table,
    check_sweep_record,
    checked_table,
    forget,
    records,
)
from sim.report.run_summary import converged_line, headline_rows, verdict_cell, write_run_readme
from sim.report.tables import Md, fmt, md_href, md_link, md_table
from sim.report.verify import markdown as reproducibility_markdown
from sim.standard_error import say

__all__ = [
    "build_report",
    "claims_markdown",
    "fmt",
    "md_table",
    "number",
    "verdict_counts",
    "referee_summary",
]


def claims_markdown(path: Path) -> str:
    """The claims table of one study as Markdown, and its *not reproduced* list if any.

    Columns: the paper's words, the claim's form, the decision zone its printed number stands
    for (rounding widened by the claim's tolerance), the simulated value, its 95 % interval
    (``plates``: the spread of a one-plate statistic, with ``p`` the probability of a plate at
    least as extreme as the paper's), the verdict and its kind."""
    t = records(path)
    rows = []
    for r in t:
        if r["verdict"] == "not comparable":
            sim, ci = "", ""
        else:
            sim, ci = sim_text(r), interval_text(r)
        # the verdict in the words of sim show's table (an input's, a self-check's outcome)
        verdict = verdict_cell({**r, "verdict": _VERDICT_TEXT.get(r["verdict"], r["verdict"])})
        rows.append(
            [
                f"`{r['claim']}`",
                r["paper"],
                r.get("form") or "",
                ref_text(r),
                sim,
                ci,
                verdict,
                r["note"],
            ]
        )
    out = md_table(
        [
            "claim",
            "paper says",
            "form",
            "decision zone",
            "simulated",
            "95% interval",
            "verdict",
            "note",
        ],
        rows,
    )
    nr = Path(path).with_name("not_reproduced.parquet")
    if nr.is_file():
        n = records(nr)
        if n:
            out += "\n\nPrinted numbers not reproduced:\n\n" + md_table(
                ["source", "printed", "why not"], [[x["source"], x["printed"], x["why"]] for x in n]
            )
    return out


def verdict_counts(claims: list[dict]) -> dict[str, int]:
    """Counts per class: predictions by verdict, errata, inputs, self-checks (and how many of
    them failed their own rule, or could not decide it, or were not applicable: a reference of
    the paper's setup on a run off it), findings, not comparable."""
    c = {
        k: 0
        for k in (
            *PREDICTION_VERDICTS,
            "erratum",
            "paper ok",
            "input",
            "self-check",
            "self-check failed",
            "self-check undecided",
            "self-check not applicable",
            "finding",
            "not comparable",
        )
    }
    for r in claims:
        v, k = r["verdict"], r["kind"]
        if k == "prediction":
            c[v if v in PREDICTION_VERDICTS else "finding"] += 1
        elif k == "paper-check":  # a check the simulation cannot settle is not "consistent"
            c["erratum" if v == "erratum" else "paper ok" if v == "holds" else v] += 1
        elif k == "self-check":
            c["self-check"] += 1
            if v == NOT_APPLICABLE:  # its outcome is against the paper's setup, not this run's
                c["self-check not applicable"] += 1
                continue
            c["self-check failed"] += r.get("outcome") == "fails"
            c["self-check undecided"] += r.get("outcome") not in (None, "holds", "fails")
        else:
            c[k] += 1
    return c


_COUNT_COLS = [
    ("holds", "holds"),
    ("fails", "fails"),
    ("inconclusive", "inconclusive"),
    ("depends", "depends"),
    ("holds or undecided", "holds or undecided"),
    ("fails or undecided", "fails or undecided"),
    ("undecidable", "undecidable"),
    ("not comparable", "not comparable"),
    ("erratum", "errata"),
    ("paper ok", "paper consistent"),
    ("input", "inputs"),
    ("self-check", "self-checks"),
    ("finding", "findings"),
]


def referee_summary(entries: list[tuple]) -> str:
    """Per paper: every headline claim with the paper's words, the decision zone, the
    simulated value (at the precision its interval supports), the interval and the verdict."""
    by_seed = by_paper(entries)
    parts = [
        "## Every headline claim\n",
        "Each claim is decided by its stated rule (see *How verdicts are decided* below); "
        "the detail of each study is in its directory's README.md.\n",
    ]
    for seed in sorted(s for s in by_seed if s):
        rows = []
        main, variants = main_and_variants(by_seed[seed])
        for name, study, claims in main + variants:
            # a variant run's rows carry the claims' names of the main run: say whose they are
            also = "" if not any(name == v[0] for v in variants) else f" (`{name}`, not counted)"
            for r in headline_rows(claims):
                nc = r["verdict"] == "not comparable"
                rows.append(
                    [
                        f"[`{r['claim']}`]({md_href(name)}){also}",
                        r["paper"],
                        ref_text(r),
                        "" if nc else sim_text(r),
                        "" if nc else interval_text(r),
                        _VERDICT_TEXT.get(r["verdict"], r["verdict"]),
                    ]
                )
        titles = "; ".join(dict.fromkeys(study.title for _, study, _ in main))
        parts.append(f"**{paper_name(seed, full=True)}** ({titles})\n")
        parts.append(
            md_table(
                [
                    "headline claim",
                    "paper says",
                    "decision zone",
                    "simulated",
                    "95% interval",
                    "verdict",
                ],
                rows,
            )
            if rows
            else "_no headline claim declared_"
        )
        parts.append("")
    return "\n".join(parts)


def _claims_of(d: Path, get_study: Callable):
    """``(study, provenance, claim rows)`` of a results directory, or one line naming the file
    when its ``claims.parquet`` is not a claims table its run wrote (as ``sim show`` checks it,
    :func:`~sim.report.read.check_claims_table`: reading its two columns first, a table of a
    million rows is named at once, and one of another study than its run.json's is named as
    such, not read as that study's results)."""
    f = d / "claims.parquet"
    check_claims_table(f, "--results")
    try:
        return get_study(read_provenance(f)["study"]), read_provenance(f), records(f)
    except ConfigError:  # a study this version lacks (sim.cli_read): said as such
        raise
    except (OSError, ValueError, pa.ArrowException) as e:
        raise cannot_read("--results", f, e) from None


_RULES = (
    "### How verdicts are decided\n\n"
    "Each claim declares its *form* and the half-width that decides (`tol`); the *decision "
    "zone* is the interval the paper's printed number stands for (its rounding) widened by "
    "that tolerance. For a value, share, count or bound the claim **holds** when the 95 % "
    "interval of the simulated value lies inside the zone, **fails** when the two do not "
    "meet, and is **inconclusive** otherwise (the interval covers both agreeing and "
    'contradicting values). A *range* ("from 5 to 15 %") holds when every element\'s '
    "interval lies inside it and fails when some element's interval lies wholly outside. "
    "A *one-plate* statistic (the paper's one plate) fails when its two-sided `p` is below "
    f"{P_FAIL:g}: fewer than {100 * P_FAIL / 2:g} % of simulated plates are as extreme as the "
    "paper's on its side (every value that prints as the paper's number counted), and holds "
    "when, besides, the central 95 % of simulated plates lies inside the zone. A prediction "
    "decided over a "
    "study's consistent region (the unprinted inputs the paper's statements leave) "
    "**holds** or **fails** when it does so everywhere in the region, **depends** when it "
    "holds in one part and fails in another, **holds or undecided** (**fails or undecided**) "
    "when it holds (fails) in one part, the opposite nowhere and is undecided at the rest, "
    "and is **undecidable** when no input of the region decides it; a region sampled at "
    f"fewer than {REGION_MIN_POINTS} accepted points leaves an everywhere-holding (-failing) "
    f"prediction **inconclusive** ({REGION_MIN_POINTS} points bound the share of the region "
    f"where it is wrong under {100 * REGION_SHARE:g} %, {100 * REGION_LEVEL:g} %). A paper check whose recomputation from the paper's own printed data "
    "fails is an **erratum**. Numbers are printed at the precision their interval supports "
    "(two significant digits of its half-width).\n\n"
)


def _entry(d: Path, get_study: Callable) -> tuple:
    forget()
    study, prov, claims = _claims_of(d, get_study)
    c = verdict_counts(claims)
    nr = d / "not_reproduced.parquet"
    n_nr = checked_table(nr).num_rows if nr.is_file() else 0
    row = [Md(f"{md_link(d.name)}: {study.title}"), paper_name(study.seed_file) or "—"]
    row += [c[k] for k, _ in _COUNT_COLS]
    apart = [
        f"{c[f'self-check {w}']} {w}"
        for w in ("failed", "undecided", "not applicable")
        if c[f"self-check {w}"]
    ]
    if apart:  # counted as self-checks, but not ones that held their own rule
        row[2 + [k for k, _ in _COUNT_COLS].index("self-check")] = (
            f"{c['self-check']} ({', '.join(apart)})"
        )
    row += [n_nr, prov.get("git_commit", "")[:12]]
    return (study.order, d.name, study, claims, row)


def build_report(
    results: Path, get_study: Callable, design: Callable | None = None, studies=()
) -> str:
    """The suite's report over every results directory under ``results``: one screen of
    verdicts per paper, every headline claim, the counts per study, the rules, the
    reproducibility check, and links to each directory's README.md (the detail).
    ``get_study(name)`` gives the registered study (title, seed file, order); ``design(name)``
    the config of the study file a directory is named after (a run that changed it is said);
    ``studies``: the study files ``results`` should hold (the project's ``studies/*.toml``
    for the project's own ``results/``), those without results named below the opening
    screen (a paper's study left out read as the whole of it)."""
    results = Path(results)
    if not results.is_dir():
        why = link_problem(results) or "is not a results directory"
        raise ConfigError("--results", f"{results} {why}")
    entries = [
        _entry(d, get_study)
        for d in sorted(p for p in results_dirs(results) if (p / "claims.parquet").is_file())
    ]
    entries.sort(key=lambda e: (e[0], e[1]))
    sweeps = sorted(
        p.name
        for p in results_dirs(results)
        if (p / "sweep.parquet").is_file() and not (p / "claims.parquet").is_file()
    )
    head = (  # a directory of the user's was made by `sim run`, not `make reproduce`
        "# Reproducibility report\n\n"
        f"Every number below was produced by a run of the code "
        f"(`{'make reproduce' if studies else 'sim run'}`); paper values "
        "appear only as the reference of a claim. Rebuilt from the Parquet files alone by "
        "`sim report`; each study's detail is its directory's README.md.\n\n"
    )
    if not entries:  # sweeps only: no claim to count (its tables were printed empty)
        return (
            head
            + "No study results here, only sweeps: each sweep's README.md has its cells.\n\n"
            + "".join(f"- {md_link(s)}: a sweep\n" for s in sweeps)
        )
    table = md_table(
        ["study", "paper"] + [t for _, t in _COUNT_COLS] + ["not reproduced", "code commit"],
        [e[4] for e in entries],
    )
    repro = reproducibility_markdown(results)
    lost = _no_file({e[1] for e in entries} | set(sweeps), studies)
    details = [  # the trials that did not converge: said by sim show, not here (lead33)
        f"- {md_link(e[1])}: {e[2].title}{lost.get(e[1], '')}"
        + (f". N{line[1:]}" if (line := converged_line(results / e[1])) else "")
        for e in entries
    ]
    details += [f"- {md_link(s)}: a sweep{lost.get(s, '')}" for s in sweeps]
    return (
        head
        + opening(entries, results)
        + "".join(line + "\n" for line in design_notes(entries, results, design))
        + _absent({e[1] for e in entries} | set(sweeps), studies)
        + "".join(f"- `{d}`{why}\n" for d, why in lost.items())
        + "\n"
        + referee_summary(entries)
        + "\n### Counts per study\n\n"
        + table
        + "\n\n"
        + _RULES
        + ("\n" + repro if repro else "")
        + "\n## The studies in detail\n\n"
        + "\n".join(details)
        + "\n"
    )


def _no_file(have: set[str], studies) -> dict[str, str]:
    """For each results directory among ``have`` without its study file among ``studies``
    (the project's ``studies/*.toml``; none for a results directory of the user's, whose
    files may be anywhere), the words that mark it: it was shown like any other."""
    names = {Path(f).stem for f in studies}
    return {
        d: f" (no study file `studies/{d}.toml`: these results cannot be re-run)"
        for d in sorted(have)
        if studies and d not in names
    }


def _absent(have: set[str], studies) -> str:
    """The line naming the study files of ``studies`` that have no results directory among
    ``have`` ("" when every one has): the report leaves them out."""
    absent = [f"`studies/{Path(f).name}`" for f in studies if Path(f).stem not in have]
    if not absent:
        return ""
    return (
        f"- No results here for {', '.join(absent)}: this report leaves "
        f"{'them' if len(absent) > 1 else 'it'} out (`make reproduce` runs what is missing).\n"
    )


#: the first line of every REPORT.md the suite writes: a file without it is the user's
MARK = "<!-- written by `sim report` from the Parquet files alone; edits are overwritten -->"


def _ours(path: Path) -> bool:
    """True for a REPORT.md the suite wrote (its mark, or the heading the reports had before)."""
    if not path.is_file():  # a FIFO or a device is not ours, and is never opened (it blocks)
        return False
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            first = f.readline().removeprefix("\ufeff").rstrip("\n")  # an editor's signature
    except OSError:  # (Notepad's) before the mark: it was "not written by sim report"
        return False
    return first in (MARK, "# Reproducibility report")


def _dirs(results: Path) -> dict[str, int]:
    """Each results directory's inode: a run that published one meanwhile gave it a new one."""
    out = {}
    try:
        dirs = results_dirs(results)
    except OSError:
        return out
    for d in dirs:
        try:
            out[d.name] = d.stat().st_ino
        except OSError:
            out[d.name] = -1
    return out


def _settled(results: Path, build: Callable):
    """``build()``, done again when a run published a study while it read the directories
    (``make reproduce`` in another terminal): the report took the tables of two runs as one
    (or named one of them as another run's table beside a run.json). A failure while the
    directories moved is read again too; after :data:`sim.mc.settle.READS` reads, the last
    outcome stands (:func:`sim.mc.settle.reread`)."""
    return reread(build, lambda: _dirs(results), last_stands=True)


def _kept(what: str) -> str:
    """The words of a results directory's README.md kept by ``sim report`` as the user's."""
    kind = f"was {what}" if what.startswith("changed") else f"is {what}"
    return f"{kind}: kept as yours, not rebuilt (move it away for the run's)"


def write_report(
    results: Path, get_study: Callable, design: Callable | None = None, studies=()
) -> Path:
    """Write each results directory's README.md (see
    :func:`sim.report.run_summary.write_run_readme`) and ``results/REPORT.md``
    (:func:`build_report`, built again when a run published a study while the READMEs were
    written); a REPORT.md there that the suite did not write is refused (one line naming it),
    never replaced."""
    results = Path(results)
    out = results / "REPORT.md"
    if out.is_symlink() or (out.exists() and not _ours(out)):
        raise ConfigError(
            "--results", f"{out} was not written by sim report; sim never replaces it"
        )

    def build() -> str:
        return MARK + "\n" + printable(build_report(results, get_study, design, studies), True)

    text, read = _settled(results, build), _dirs(results)
    for d in sorted(results_dirs(results)):
        if (why := missing_cell(d)) is not None:  # its README.md would link a cell that is gone
            raise ConfigError("--results", why)
        check_sweep_record(d, "--results")  # its README.md from a table it cannot check
        if (d / "claims.parquet").is_file() or (d / "sweep.parquet").is_file():
            _settled(results, lambda d=d: write_run_readme(d, get_study, design=design))
            if (what := changed_exports(d).get("README.md")) is not None:  # kept: said
                say(f"sim: note: {d / 'README.md'} {_kept(what)}")
    if _dirs(results) != read:  # a run published while the READMEs were written: REPORT.md
        text = _settled(results, build)  # held the replaced run's claims beside the new run
    with atomic_path(out) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return out
