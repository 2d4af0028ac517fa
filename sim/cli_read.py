"""The commands of ``sim`` that read finished results: ``sim show DIR`` (one results
directory as a table, or its README.md) and ``sim report`` (REPORT.md and every study's
README.md). They read the Parquet tables only; a table that does not read as its study wrote
it is one line naming it (:func:`sim.cli_tables.not_as_written`)."""

from __future__ import annotations

import difflib
import itertools
import os
import shlex
import sys
from pathlib import Path

import pyarrow as pa

from sim.api_paths import arrow_name, cell_mixed, too_long
from sim.cli_tables import lost_table, not_as_written, older_lacks
from sim.ends import unshown
from sim.mc.config import ConfigError
from sim.mc.file_kind import odd_table
from sim.mc.message_text import printable
from sim.mc.outputs import name_problem, results_dirs
from sim.mc.paths import link_problem
from sim.mc.settle import settled
from sim.mc.storage import umask_problem
from sim.mc.unfinished import unfinished, unfinished_in
from sim.places import base, shown_path
from sim.report.markdown import write_report
from sim.report.read import check_claims_table, check_sweep_record, mixed_run
from sim.report.run_summary import run_markdown, terminal_table
from sim.report_due import clear_due
from sim.stale import other_code, other_dirs, remade, stale_dirs
from sim.studies import MODULES, STUDY_FILES, design_config, get_study

__all__ = ["show", "report", "report_command"]

#: where ``sim show NAME`` looks for NAME when it is no directory here: the project's results
#: and the scratch directories of its runs without ``--out``
WHERE = (Path("results"), Path("scratch"))


def show(args) -> int:
    """``sim show DIR``: the results directory's claims (``--markdown``: its README.md)."""
    if name_problem(args.dir):
        raise ConfigError(
            "DIR", f"not a directory name: {name_problem(args.dir)} (got {args.dir!r})"
        )
    if (why := too_long(args.dir)) is not None:  # it was the system's words and the whole path
        raise ConfigError("DIR", why)
    d = Path(args.dir)
    # the name a README.md gives (`sim show NAME` prints it again) is read under the project's
    # results/ and scratch/ too (from docs/ as from the root), where sim run writes without
    # --out (a scratch run's README named a command that said "does not exist" from the root)
    # a name only (`sim show results/x` was told of results/results/x too); the path a run
    # printed (`results in scratch/x/`), typed from docs/, is read under the project's root
    where = [Path(shown_path(base() / b)) for b in WHERE] if len(d.parts) == 1 else []
    if len(d.parts) > 1 and Path(d.parts[0]) in WHERE and base() != Path("."):
        where = [Path(shown_path(base()))]
    d = next((b / d for b in where if not d.exists() and (b / d).is_dir()), d)
    if not d.is_dir():
        what = "is not a directory" if os.path.lexists(d) else "does not exist"
        also = (
            ""
            if d.is_absolute() or d.exists() or not where
            else f" (nor is there a directory {' or '.join(str(b / args.dir) for b in where)})"
        )
        if guess := _show_guess(args.dir, d):  # one bracket: "(nor is ...: did you mean ...?)"
            also = f"{also[:-1]}: {guess})" if also else f" ({guess})"
        why = link_problem(d) or f"{what}{also}"
        if (run := unfinished(d)) is not None:  # a run killed before it published
            why = f"{what}: {run}"
        raise ConfigError("DIR", f"{args.dir} {why}")
    # read again when a run publishes d meanwhile: one run's claims were printed under the
    # other's configuration note (sim.mc.settle)
    text = settled(d, lambda: _shown_text(d, args.markdown), "DIR")
    print(printable(text, lines=True), end="")  # a forged note's escape sequences: shown
    print("" if args.markdown else "\n", end="")
    if older := other_code(d):  # verdicts of code since changed: read as current otherwise
        print(
            f"sim: note: {older} was made by another version of the suite's code (its study's "
            f"code changed since): {remade(d)}",
            file=sys.stderr,
        )
    for why in other_dirs(d)[:1]:  # another study's results under this name (copied)
        print(f"sim: note: {why}", file=sys.stderr)
    return 0


def _show_guess(typed: str, d: Path) -> str:
    """``did you mean sim show results/brown_table1?`` for a results directory named the
    way a new user names it: as its study file (``brown_table1.toml``,
    ``studies/brown_table1.toml``: "is not a directory"), mistyped (``brown_tabel1``), or
    without the config hash of the scratch directory its run went to (``scratch/brown_table1``
    for ``scratch/brown_table1-353c12b0``), or as a file in it (``results/brown_table1/README.md``:
    ``sim show results/brown_table1 --markdown``). Each was "does not exist" with no guess, where
    ``sim run`` and ``sim check`` guess a study file's name (D45). Looked for in the project's
    ``results/`` and ``scratch/`` (:data:`WHERE`; only the one typed, if any): the name
    itself, then a scratch run of it (the newest), then the closest spelling."""
    up = Path(os.path.dirname(d))  # a file of a results directory: its README.md, a table
    if os.path.isfile(d) and ((up / "run.json").is_file() or (up / "claims.parquet").is_file()):
        markdown = " --markdown" if d.name == "README.md" else ""
        return f"did you mean sim show {up}{markdown}?"
    stem = Path(typed).name.removesuffix(".toml")
    seen: list[Path] = []
    # a path typed under results/ or scratch/ is guessed there only (a scratch run's typo
    # is not the committed results)
    for b in [b for b in WHERE if b.name == Path(typed).parent.name] or WHERE:
        try:
            with os.scandir(base() / b) as it:  # a few hundred runs at most
                seen += [Path(e.path) for e in itertools.islice(it, 2000) if e.is_dir()]
        except OSError:
            continue
    seen = [e for e in seen if (e / "run.json").is_file() or (e / "claims.parquet").is_file()]
    close = difflib.get_close_matches(stem, [e.name for e in seen], n=3, cutoff=0.75)

    def rank(e: Path) -> tuple:
        kind = 0 if e.name == stem else 1 if e.name.startswith(f"{stem}-") else 2
        try:
            return (kind, -e.stat().st_mtime)
        except OSError:  # removed meanwhile
            return (kind, 0.0)

    hits = [e for e in seen if e.name == stem or e.name.startswith(f"{stem}-") or e.name in close]
    hits = [e for e in sorted(hits, key=rank) if os.path.abspath(e) != os.path.abspath(d)]
    return f"did you mean sim show {shown_path(hits[0])}?" if hits else ""


def _shown_text(d: Path, markdown: bool) -> str:
    """What ``sim show`` prints of the results directory ``d``: its claims as a table, or
    (``markdown``) its README.md as written from its tables."""
    check_claims_table(d / "claims.parquet", "DIR")
    check_sweep_record(d, "DIR")
    if (sweep := _sweep_of(d)) is not None and (mixed := mixed_run(sweep)) is not None:
        raise ConfigError("DIR", mixed)  # a cell's figure replaced by hand: its sweep's record
    if (cell := cell_mixed(d)) is not None:  # a cell's tables of another cell or run
        raise ConfigError("DIR", cell)
    try:
        if markdown:
            return run_markdown(d, _study_of("DIR", d), design=design_config)
        return terminal_table(d, design=design_config, get_study=_study_of("DIR", d))
    except ConfigError:
        raise
    except (KeyError, IndexError, TypeError, ValueError, pa.ArrowException) as e:
        raise ConfigError("DIR", not_as_written(d, e)) from None
    except FileNotFoundError as e:
        if (why := older_lacks(d, e) or lost_table(e)) is None:
            raise
        raise ConfigError("DIR", why) from None


def _sweep_of(d: Path) -> Path | None:
    """The sweep directory whose run record covers ``d`` (a sweep's own directory, which has
    no claims table of its own, or one of its ``cells/<label>/``, which has no run record), or
    None: a sweep records the sha256 of every cell's figures in its one ``run.json``."""
    if (d / "sweep.parquet").is_file() and not (d / "claims.parquet").is_file():
        return d
    up = d.resolve().parent
    if up.name == "cells" and (up.parent / "sweep.parquet").is_file():
        if not (d / "run.json").exists():
            return up.parent
    return None


def report_command(args) -> int:
    """``sim report [--results DIR]``: the project's results when none is given (from a
    directory inside the project, docs/, too)."""
    if args.results is None:
        args.results = shown_path(base() / "results")
    if name_problem(args.results):
        why = name_problem(args.results)
        raise ConfigError("--results", f"not a directory name: {why} (got {args.results!r})")
    if why := too_long(args.results):  # was "does not exist"
        raise ConfigError("--results", why)
    return report(Path(args.results))


def report(results: Path) -> int:
    """``sim report``: only over a directory that holds study results (a directory of the
    user's with none gets no REPORT.md written into it)."""
    # from / or $HOME: not "is not a results directory" (a link loop on the way: its words)
    if not os.path.lexists(results) and not link_problem(results):
        raise ConfigError("--results", f"{results} does not exist (in {os.getcwd()})")
    for d in sorted(results_dirs(results)) if results.is_dir() else ():
        if (odd := odd_table(d)) is not None:  # a FIFO as claims.parquet: the study was
            raise ConfigError("--results", odd)  # left out of REPORT.md without a word
    if results.is_dir() and not any(
        (d / "claims.parquet").is_file() or (d / "sweep.parquet").is_file()
        for d in results_dirs(results)
    ):
        if any((results / f).is_file() for f in ("claims.parquet", "sweep.parquet")):
            raise ConfigError(  # "no */claims.parquet" of a directory that holds one
                "--results",
                f"{results} is one results directory, not a directory of them: give the "
                f"directory that holds it (sim show {shlex.quote(str(results))} prints this one)",
            )
        run = unfinished_in(results)
        raise ConfigError(
            "--results",
            f"no study results in {results} (no */claims.parquet): nothing to report"
            + (f"; {run}" if run else ""),
        )
    if (why := umask_problem()) is not None:
        raise ConfigError(None, why)
    if (why := unshown(str(results / "REPORT.md"))) is not None:  # printed once it is written
        raise ConfigError("--results", why)
    arrow_name("--results", results)
    try:
        text = write_report(
            results, _study_of("--results", results), design_config, project_studies(results)
        )
    except ConfigError:
        raise
    except (KeyError, IndexError, TypeError, ValueError, pa.ArrowException) as e:
        # report reads the Parquet tables only: one that fails here was not written as it is
        # by sim (a table replaced or edited by hand)
        raise ConfigError("--results", not_as_written(results, e)) from None
    except FileNotFoundError as e:
        if (why := older_lacks(results, e) or lost_table(e)) is None:
            raise
        raise ConfigError("--results", why) from None
    clear_due(results)  # a batch's report killed before it ended is rebuilt now
    print(text)
    if stale := stale_dirs(results):  # a report of verdicts since changed: read as current
        names = ", ".join(sorted(Path(s).name for s in stale)[:4]) + (
            ", ..." if len(stale) > 4 else ""
        )
        print(
            f"sim: note: {len(stale)} of the reported results directories ({names}) "
            f"{'was' if len(stale) == 1 else 'were'} made by another version of the suite's code "
            "(changed since the run): the report "
            f"gives the verdicts as they were; {remade(results)}",
            file=sys.stderr,
        )
    for why in other_dirs(results):  # another study's numbers under a study's name
        print(f"sim: note: {why}", file=sys.stderr)
    return 0


def project_studies(results: Path) -> list[Path]:
    """The project's study files (``studies/*.toml`` of the suite's own checkout) when
    ``results`` is the project's own ``results/`` (what ``make reproduce`` writes), else none:
    a results directory of the user's holds the studies they chose to run (``--studies``),
    and the report names no study file it lacks."""
    try:
        if Path(results).resolve() != (STUDY_FILES.parent / "results").resolve():
            return []
        return sorted(STUDY_FILES.glob("*.toml"))
    except (OSError, RuntimeError):  # a loop: the report names it
        return []


def _study_of(key: str, d: Path):
    """``get_study`` for the tables under ``d``: a study this version of the suite lacks
    (results of a newer version, or of a study since removed) is named as such, not "study:
    unknown study" (``sim report``: "claims.parquet cannot be read")."""

    def get(name):
        if isinstance(name, str) and name not in MODULES:
            raise ConfigError(
                key,
                f"{d} holds results of the study {name!r}, which this version of the suite "
                f"does not have (results of another version?; it has {', '.join(sorted(MODULES))})",
            )
        return get_study(name)

    return get
