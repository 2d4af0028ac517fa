"""The command line of ``make verify``: ``python -m sim.report.verify``."""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
from pathlib import Path

from sim.api_paths import arrow_name, too_long
from sim.ends import stdout_failed
from sim.env_vars import environment_problem
from sim.held_stops import held_stops
from sim.mc.argv import OnceParser, integer, most_workers
from sim.mc.config import ConfigError, parse_override
from sim.mc.outputs import name_problem
from sim.mc.overrides import listed
from sim.option_words import Meant
from sim.places import base, shown_path
from sim.report.verify.record import not_a_record, write_record
from sim.report.verify.rerun import verify
from sim.report.verify.rules import Comparison, VerifyError
from sim.report.verify.scratch import scratch_dir
from sim.stops import check_interrupt, ended_as_ctrl_c, exit_status, keep_lost_interrupts

__all__ = ["main"]

DESCRIPTION = (
    "Reproducibility verified, not promised: re-run the studies and compare with committed results."
)


# --- command line -----------------------------------------------------------------------------


class _Parser(Meant, OnceParser):  # -j: --workers (sim.option_words)
    words = "verify"

    def refuse(self, message: str):  # one line, exit 2 (main prints it)
        raise VerifyError(message)


#: the fewest trials of a re-run compared at the Monte-Carlo level (``--trials``): the rule's
#: standard errors come from each run's 95 % interval (a normal approximation). The tests check
#: it at 400 trials; at 100 a network's sigma bounds failed it by chance, at 200 they reached
#: 0.85 of their tolerance
MIN_TRIALS = 400


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="python -m sim.report.verify", description=DESCRIPTION)
    # --results, unlike the other paths, may be given again: make verify passes --results
    # results before VERIFY_FLAGS (the last wins, as before)
    p.add_argument(
        "--results",
        action="store",
        help="the committed results (default: results, the project's from inside it)",
    )
    p.add_argument(
        "--scratch", help="where to re-run (default: a temporary directory, removed after)"
    )
    p.add_argument(
        "--studies",
        help="the study files of the results, DIR/<results directory>.toml (default: studies, "
        "the project's from inside it)",
    )
    p.add_argument(
        "--workers",
        type=integer("workers", 1, most_workers()),
        default=1,
        help="workers of each re-run (default 1; make verify passes 2)",
    )
    p.add_argument("--study", action="append", help="only this study (repeatable)")
    p.add_argument(
        "--no-rerun",
        action="store_true",
        help="compare with the re-runs already in --scratch (e.g. made on another machine)",
    )
    p.add_argument(
        "--trials",
        type=integer("trials"),
        help=f"re-run with this many trials (at least {MIN_TRIALS}) and compare at the "
        "Monte-Carlo level",
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


def _defaults(a) -> None:
    """``--results`` and ``--studies`` not given: the project's ``results/`` and ``studies/``
    from a directory inside it (:func:`sim.places.base`, as ``sim run``, ``sim report`` and
    ``python -m sim.batch`` take theirs): from ``docs/`` it refused, "no studies/ directory"."""
    a.studies_given = a.studies is not None
    a.results = shown_path(base() / "results") if a.results is None else a.results
    a.studies = shown_path(base() / "studies") if a.studies is None else a.studies


def _cwd_exists() -> bool:
    try:
        os.getcwd()
    except OSError:
        return False
    return True


def _check_args(a) -> None:
    for name, v in (("--results", a.results), ("--scratch", a.scratch), ("--studies", a.studies)):
        why = None if v is None else name_problem(v)
        if why:
            raise VerifyError(f"{name}: {why} (got {v!r})")
        if v is not None and (why := too_long(v)):  # it was the system's words and the whole
            raise VerifyError(f"{name}: {why}")  # path (6 kB), no option named
        if v is not None and not os.path.isabs(v) and not _cwd_exists():  # (R44) it was
            raise VerifyError(  # "No such file or directory", from the refusal's Path.cwd()
                f"{name}: {v} is relative, but the working directory is gone (it was deleted)"
            )
    for v in a.study or ():  # a name of 300 bytes: "File name too long: results/ccc..."
        if why := too_long(v):
            raise VerifyError(f"--study: {why}")
    if a.trials is not None and a.trials < MIN_TRIALS:
        raise VerifyError(
            f"--trials: must be at least {MIN_TRIALS}, not {a.trials} (the Monte-Carlo rule takes "
            "each run's standard error from its interval, which needs that many trials: at 100 a "
            "network's interval bounds fail it by chance)"
        )
    if a.set and a.trials is None:
        raise VerifyError("--set: only with --trials (a re-run with other inputs is not a check)")
    if a.no_rerun and not a.scratch:
        raise VerifyError("--no-rerun: needs --scratch (the directory of the re-runs)")
    if not a.no_rerun and a.studies_given and not Path(a.studies).is_dir():
        raise VerifyError(f"--studies: {a.studies} is not a directory")
    if not a.no_rerun and not Path(a.studies).is_dir():  # run elsewhere, every study "FAILED"
        raise VerifyError(
            f"no studies/ directory in {Path.cwd()}: the re-runs read their study files from "
            "studies/; run from the project's root (or name their directory with --studies)"
        )
    keys = set()
    for s in a.set:
        if "=" not in s:
            raise VerifyError(f"--set: {s!r} is not KEY=VALUE")
        try:
            key = parse_override(s)[0]
        except ConfigError as e:
            raise VerifyError(f"--set: {e}" if e.key else str(e)) from None
        if key in keys:  # each re-run refused it, one by one after the runs before it
            raise VerifyError(f"--set: {key}: given twice by --set: give one value")
        keys.add(key)


def _print(comps: list[Comparison]) -> None:
    for c in comps:
        status = "ok" if c.ok else "FAILED"
        given = listed(c.overrides)
        if not c.files and c.failures:  # nothing compared: no deviation to state
            print(f"{c.study}: FAILED; nothing compared")
            for f in c.failures[:20]:
                print(f"  {f}")
            if c.overrides and given not in c.failures[0]:
                print(f"  re-run with the run's overrides: {given}")
            continue
        print(
            f"{c.study}: {status}; {c.files} files; largest relative deviation "
            f"{c.max_rel:.2g}; largest deviation/tolerance {c.max_ratio:.2g}"
            + (f" ({c.worst})" if c.worst else "")  # "0 ()" named no column: every one equal
        )
        for f in c.failures[:20]:
            print(f"  {f}")
        if c.overrides:  # results of a run off its study file's values, re-run with them
            print(f"  {'reproduced' if c.ok else 're-run'} with the run's overrides: {given}")
        if c.not_compared:
            print(f"  not compared (rows depend on the trials): {', '.join(c.not_compared)}")


#: the command's line when it was interrupted
INTERRUPTED = "sim verify: interrupted; the re-run was stopped"


def main(argv: list[str] | None = None) -> int:
    if (problem := environment_problem()) is not None:  # as python -m sim.report.verify
        print(f"sim verify: error: {problem}", file=sys.stderr)  # refuses it (from Python:
        return 2  # not a line of sim run's for each re-run)
    try:
        with ended_as_ctrl_c(), keep_lost_interrupts():  # Ctrl-C dropped in a C callback: kept
            code = _main(argv)
            check_interrupt()  # and never exit 0 after one
            return code
    except KeyboardInterrupt:
        print(INTERRUPTED, file=sys.stderr)
        return 130


def _main(argv: list[str] | None) -> int:
    comps = None
    try:
        try:
            a = _parser().parse_args(argv)
        except SystemExit as e:  # --help (or argparse's own error): an in-process caller goes on
            return exit_status(e.code)
        _defaults(a)
        _check_args(a)
        for key, where in (
            ("--results", a.results),
            ("--scratch", a.scratch or tempfile.gettempdir()),
        ):
            try:  # a locale whose file names are not UTF-8: Arrow's would be other files
                arrow_name(key, where)
            except ConfigError as e:
                raise VerifyError(str(e)) from None
        extra = [] if a.trials is None else ["--trials", str(a.trials)]
        extra += [x for s in a.set for x in ("--set", s)]
        mode = "full" if a.trials is None else "mc"
        if (why := _unrecordable(_record_path(a, mode))) is not None:
            raise VerifyError(why)
        if not a.scratch and (why := name_problem(tempfile.gettempdir())) is not None:
            raise VerifyError(  # each re-run's --out would be refused (a line break in TMPDIR)
                f"the temporary directory {tempfile.gettempdir()!r} (TMPDIR) {why}: "
                "set TMPDIR, or give --scratch DIR"
            )
        tmp = None if a.scratch else scratch_dir()  # (those of killed verifies cleared)
        try:
            comps = verify(
                Path(a.results),
                Path(a.scratch or tmp),
                workers=a.workers,
                only=a.study,
                rerun=not a.no_rerun,
                extra=extra,
                mode=mode,
                studies=Path(a.studies),
            )
        finally:
            with held_stops():  # Ctrl-C while removing it left it (in /tmp) for good
                left = _remove(tmp)
        check_interrupt()  # before the comparisons are printed and recorded
    except VerifyError as e:
        print(f"sim verify: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:  # a --scratch or results of another user's that may not be read:
        where = f": {e.filename}" if e.filename else ""  # it was a traceback
        print(f"sim verify: error: {e.strerror or e}{where}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(INTERRUPTED if comps is None else _after(a, mode, []), file=sys.stderr)
        return 130
    said: list[str] = []
    try:
        return _report(comps, _record_path(a, mode), left, said)
    except KeyboardInterrupt:  # it said "the re-run was stopped" of re-runs that had ended
        print(_after(a, mode, said), file=sys.stderr)
        return 130


def _record_path(a, mode: str) -> Path | None:
    """Where the comparisons are recorded (None: not recorded, a part of them or by trials)."""
    full = not a.no_record and mode == "full" and not a.study
    return Path(a.results) / "reproducibility.parquet" if full else None


def _unrecordable(where: Path | None) -> str | None:
    """Why the record ``where`` cannot be written, said before any re-run: results on a
    read-only share or another user's (or a directory in the record's place) were re-run for
    hours, then "cannot write <results>/reproducibility.parquet: Read-only file system" (or
    "Is a directory"), exit 2 (None: it can be)."""
    if where is None or not where.parent.is_dir():  # (a missing --results: named by verify)
        return None
    if where.is_dir():  # as read-only results: "cannot write ...: Is a directory" after them
        return (
            f"--results: {where} is a directory, where the re-runs' record is written after "
            "them: move it away, or give --no-record to compare only"
        )
    if where.exists() and (why := not_a_record(where)) is not None:  # a file of the user's
        return (  # was replaced by the record after the re-runs, without a word
            f"--results: {where} is not a record of make verify ({why}); the re-runs' record "
            "is written there after them: move it away, or give --no-record to compare only"
        )
    ids = os.access in os.supports_effective_ids
    if os.access(where.parent, os.W_OK | os.X_OK, effective_ids=ids):
        return None
    return (
        f"--results: you may not write in {where.parent} (read-only?), where the re-runs' "
        f"record {where.name} is written after them: give --no-record to compare only"
    )


def _after(a, mode: str, said: list[str]) -> str:
    """The line of an interrupt after every re-run ended and was compared (``said``: that the
    record was written, when it was)."""
    where = _record_path(a, mode)
    what = f"; they were not recorded in {where}" if where is not None else ""
    return f"sim verify: interrupted after the comparisons{(said or [what])[-1]}"


def _report(comps: list[Comparison], where: Path | None, left: str | None, said: list) -> int:
    """Print the comparisons ``comps`` and record them in ``where`` (None: not recorded; an
    interrupt while it is written is handled once it is, ``said`` then saying so); the exit
    code."""
    try:  # a long output (20 lines a failed study) into a full disk or a reader that left
        _print(comps)  # was a traceback here, and the record below was not written
        unprinted = None
    except OSError as e:
        unprinted = e
    code = 0 if all(c.ok for c in comps) else 1
    if unprinted is not None:
        code = stdout_failed("sim verify", unprinted, code)
    if where is not None:
        try:
            with held_stops():
                write_record(where.parent, comps)
                said.append(f"; they were recorded in {where}")
        except OSError as e:  # e.g. a directory where the record goes: one line, no traceback
            print(f"sim verify: error: cannot write {where}: {e.strerror or e}", file=sys.stderr)
            return 2
    if left:
        print(left, file=sys.stderr)
    return code


def _remove(tmp: str | None) -> str | None:
    """Remove the temporary scratch directory ``tmp`` of the re-runs; the note to print when
    it could not be removed (an I/O error, a file in it made read-only), else None. A
    finished check stands: the failure ended verify in exit 2 naming a bare file name
    ("Input/output error: claims.parquet"), its comparisons neither printed nor recorded."""
    if tmp is None:
        return None
    failed: list[str] = []

    def note(fn, path, exc) -> None:  # (onexc of Python 3.12 on: the exception itself)
        e = exc[1] if isinstance(exc, tuple) else exc
        failed.append(f"{getattr(e, 'strerror', None) or e}: {path}")

    shutil.rmtree(tmp, **{"onexc" if sys.version_info >= (3, 12) else "onerror": note})
    if not failed or not os.path.lexists(tmp):
        return None
    return (
        f"sim verify: note: its scratch directory {tmp} could not be removed ({failed[0]}): "
        "remove it by hand"
    )
