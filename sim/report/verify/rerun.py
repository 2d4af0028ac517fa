"""Re-running the studies of a results directory into a scratch directory (only what the suite
wrote there is ever replaced) and comparing them with it (the record and the report's section:
:mod:`sim.report.verify.record`)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pyarrow as pa

from sim.ends import unshown
from sim.mc.children import child_env, child_text, ended, stop_children
from sim.mc.config import ConfigError
from sim.mc.file_kind import odd_table
from sim.mc.outputs import results_dirs
from sim.mc.overrides import listed, replayable, without
from sim.mc.paths import link_problem
from sim.mc.storage import LOCK, read_provenance, read_record
from sim.mc.study_source import other_source
from sim.mc.table_edits import edited_tables
from sim.mc.unfinished import unfinished, unfinished_in
from sim.report.read import check_claims_table
from sim.report.verify.child import launcher, refusal, set_refusal
from sim.report.verify.rules import Comparison, VerifyError, compare_dirs, tables_digest
from sim.report_due import due_words

__all__ = ["study_dirs", "study_file", "rerun_study", "verify"]


# --- re-running -------------------------------------------------------------------------------


def study_dirs(results: Path, only: list[str] | None = None) -> list[tuple[Path, str]]:
    """(directory, study) of every study with committed results, or of those named in
    ``only`` (a study or its directory name); VerifyError for none or an unknown name."""
    results = Path(results)
    if not results.is_dir():
        raise VerifyError(f"--results: {results} {link_problem(results) or 'is not a directory'}")
    for d in sorted(results_dirs(results)):  # a FIFO as claims.parquet: not "no results"
        named = not only or d.name in {Path(s).name.removesuffix(".toml") for s in only}
        if named and (odd := odd_table(d)) is not None:
            raise VerifyError(f"--results: {odd}")
    found = []
    for d in sorted(p for p in results_dirs(results) if (p / "claims.parquet").is_file()):
        try:
            study = read_provenance(d / "claims.parquet").get("study") or d.name
        except (OSError, pa.ArrowException, ValueError):
            study = d.name  # a damaged file: the comparison names it
        found.append((d, str(study)))
    if not found:
        sweeps = sorted(p.name for p in results_dirs(results) if (p / "sweep.parquet").is_file())
        if sweeps:  # "no study results" read as if the sweeps' runs were lost
            raise VerifyError(
                f"--results: {results} holds only sweeps' results ({', '.join(sweeps[:3])}"
                f"{', ...' if len(sweeps) > 3 else ''}: sweep.parquet): verify re-runs single "
                "studies; re-run a sweep with sim run to compare"
            )
        left = unfinished_in(results)  # a run in progress, or killed before it published
        raise VerifyError(
            f"--results: no study results in {results} (no */claims.parquet)"
            + (f"; {left}" if left else "")
        )
    if only:
        names = {n for d, s in found for n in (s, d.name)}
        unknown = [s for s in only if s not in names]
        sweeps = [s for s in unknown if (results / s / "sweep.parquet").is_file()]
        if sweeps:  # not "no results": results verify cannot compare
            raise VerifyError(
                f"--study: {results / sweeps[0]} holds a sweep's results (sweep.parquet): "
                "verify re-runs single studies; re-run the sweep with sim run to compare"
            )
        if unknown:  # named as its study file (brown_table1.toml): the name, D45
            bare = {s: Path(s).name.removesuffix(".toml") for s in unknown}
            guess = [bare[s] for s in unknown if bare[s] in names]
            raise VerifyError(
                f"--study: no results of {', '.join(map(repr, unknown))} in {results} "
                + (
                    f"(did you mean --study {guess[0]}? a study's name, not its file) "
                    if guess
                    else ""
                )
                + f"(there are: {', '.join(sorted(d.name for d, _ in found))})"
                + "".join(f"; {results / s}: {w}" for s in unknown[:1] if (w := _left(results, s)))
            )
        found = [(d, s) for d, s in found if s in only or d.name in only]
    return found


def _left(results: Path, name: str) -> str | None:
    """Words on an unfinished run of the study ``name`` in ``results`` (a run writing it now,
    or killed before it published), or None: verify said only "no results of" it."""
    if not name or "/" in name or name in (".", ".."):
        return None
    return unfinished(results / name)


def _target(scratch: Path, name: str) -> tuple[Path, bool]:
    """Where to re-run, and whether it holds an earlier re-run to replace (``--overwrite``).
    Anything else already there is refused: verify deletes nothing it did not write."""
    target = scratch / name
    if not target.exists() and not target.is_symlink():
        return target, False
    record = read_record(target) if target.is_dir() and not target.is_symlink() else None
    if record is not None:
        files = record.get("files")  # what its run wrote: a list of paths
        if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
            raise VerifyError(  # edited by hand ("files": 5 was a TypeError traceback)
                f"--scratch: {target / 'run.json'} lists no files its run wrote (edited by "
                "hand?): refusing to replace the directory; remove it or choose another --scratch"
            )
        listed = {f.split("/")[0] for f in files}
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
    # the lock file a run leaves in its results when it cannot remove it (an I/O error at its
    # very end, the run published): every later verify into --scratch refused it as the user's
    if p.name == LOCK:
        return p.is_file()
    return p.name == "run.json" or p.suffix in (".parquet", ".png", ".xml")


def study_file(d: Path, study: str, studies: Path = Path("studies")) -> Path:
    """The study file that made the results ``d`` of ``study``: ``studies/<d.name>.toml`` (a
    study kind with several files, ``network_*``, is named by its directory), else
    ``studies/<study>.toml``."""
    sf = studies / f"{d.name}.toml"
    return sf if sf.is_file() else studies / f"{study}.toml"


def rerun_study(
    d: Path,
    study: str,
    target: Path,
    overwrite: bool,
    workers: int,
    extra: list[str],
    studies: Path = Path("studies"),
    overrides: list[str] | tuple = (),
) -> str | None:
    """Run the study of committed results ``d`` into ``target`` from its file in ``studies``
    with the run's ``overrides`` (:mod:`sim.mc.overrides`); the failure, or None."""
    sf = study_file(d, study, studies)
    if not sf.is_file():
        return (
            f"no study file {studies / (d.name + '.toml')} to re-run (results of study files "
            "kept elsewhere: name their directory with --studies)"
        )
    # the comparison reads tables only: no figures drawn (half of some studies' time)
    # --out=DIR: a --scratch that begins with "-" is a value, not an option of sim run's
    cmd = [sys.executable, "-m", "sim", "run", str(sf), f"--out={target}", "--quiet"]
    cmd += ["--no-figures"]
    cmd += ["--workers", str(workers), *(["--overwrite"] if overwrite else [])]
    cmd += [f"--set={t}" for t in overrides] + extra  # (each checked: replayable)
    print(f"sim verify: re-running {d.name}", file=sys.stderr, flush=True)
    # its standard output is not verify's: the re-run's "results in /tmp/sim-verify-.../" named
    # a directory removed at exit, between verify's own lines, and a full or closed standard
    # output of verify's failed the re-run itself
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.PIPE}
    cmd, given = launcher(cmd)
    if given is not None:
        quiet["stdin"] = subprocess.PIPE
    with subprocess.Popen(cmd, **quiet, env=child_env(), **child_text()) as proc:
        try:
            _, err = proc.communicate(given)
        except KeyboardInterrupt:  # Ctrl-C reaches the re-run too, SIGTERM or SIGHUP only verify
            stop_children([proc], drain=True)  # as Ctrl-C does, without a word of its own
            raise
    lines = [ln for ln in err.splitlines() if ln.strip()]
    if (
        proc.returncode == 2
        and lines
        and (why := refusal(d.name, sf, lines[-1], target, overrides, extra))
    ):
        return why
    if proc.returncode < 0 or proc.returncode == 130:
        # ended by a signal of its own (the OOM killer, a kill -9 or SIGTERM of the re-run
        # alone): nothing was reproduced or not; it was recorded as a failed comparison ("no:
        # the re-run was killed by SIGKILL"), over the record of the last check
        raise VerifyError(
            f"{d.name}: the re-run {ended(proc.returncode)} before it ended: nothing compared "
            "or recorded (memory short? run verify again)"
        )
    sys.stderr.write(err)
    return None if proc.returncode == 0 else f"the re-run {ended(proc.returncode)}"


def verify(
    results: Path,
    scratch: Path,
    workers: int = 1,
    only: list[str] | None = None,
    rerun: bool = True,
    extra: list[str] | None = None,
    mode: str = "full",
    studies: Path = Path("studies"),
) -> list[Comparison]:
    """Re-run each study with committed results into ``scratch`` and compare (``rerun=False``:
    compare with what ``scratch`` holds). ``extra``: further ``sim run`` arguments (``--trials
    N``, ``--set K=V``); ``mode``: ``full``, or ``mc`` for a re-run with fewer trials;
    ``studies``: the directory of the study files (:func:`study_file`)."""
    scratch = Path(scratch)
    if scratch.exists() and not scratch.is_dir():
        raise VerifyError(f"--scratch: {scratch} is not a directory")
    todo = study_dirs(results, only)
    for d, _ in todo:  # its lines (and each re-run's) name them: a traceback after the re-runs
        if why := unshown(str(d)) or unshown(str(scratch / d.name / "README.md")):
            raise VerifyError(f"{d.name}: {why}")
    sweeps = sorted(  # (a study's results with an older version's sweep.parquet are not one)
        p.name
        for p in results_dirs(results)
        if (p / "sweep.parquet").is_file() and not (p / "claims.parquet").is_file()
    )
    if sweeps and not only:  # skipped without a word, they read as verified
        print(
            f"sim verify: not verified: {', '.join(sweeps[:5])}{', ...' if len(sweeps) > 5 else ''}"
            " (sweeps: verify re-runs single studies; re-run a sweep with sim run to compare)",
            file=sys.stderr,
        )
    if (due := due_words(results)) is not None:  # a batch's report killed (kill -9)
        print(f"sim verify: note: {due}", file=sys.stderr)
    try:
        inside = scratch.resolve() == Path(results).resolve() or Path(results).resolve() in (
            scratch.resolve().parents
        )
    except (OSError, RuntimeError) as e:  # a symlink loop
        raise VerifyError(f"--scratch: {scratch} cannot be resolved: {e}") from None
    if inside:
        raise VerifyError(f"--scratch: {scratch} is (inside) the committed results {results}")
    # every target checked before anything runs: a foreign directory stops it at once
    replace = {d: _target(scratch, d.name)[1] for d, _ in todo} if rerun else {}
    missing = [d.name for d, _ in todo if not rerun and not (scratch / d.name).is_dir()]
    if missing:  # nothing to compare: a request error, not a failed comparison to record
        raise VerifyError(
            f"--no-rerun: no re-run of {', '.join(missing)} in {scratch} "
            "(run without --no-rerun, or choose the --scratch that holds them)"
        )
    files = [(d.name, study_file(d, study, Path(studies))) for d, study in todo]
    if rerun and (why := set_refusal(files, extra or [])) is not None:
        raise VerifyError(why)  # before any re-run, as python -m sim.batch does
    out = []
    for d, study in todo:
        target = scratch / d.name
        # tables of two runs (...), another study's results (copied): no reproduction to check
        mixed = _not_as_written(d) or other_source(d, d.name, studies=Path(studies))
        if mixed:
            out.append(Comparison(d.name, failures=[mixed]))
            continue
        given: list[str] = []  # the run's overrides, re-run with it (sim.mc.overrides)
        ran = None  # the config of the run the re-run reproduces
        if rerun:
            ran = (read_record(d) or {}).get("config")
            given, bad = replayable(read_record(d) or {})
            if bad:  # never passed on: a run.json edited by hand adds no option to a re-run
                why = f"{d / 'run.json'}: {bad} (edited by hand?): not re-run"
                out.append(Comparison(d.name, failures=[why]))
                continue
            given = without(given, extra or [])
            overwrite = replace[d]
            why = rerun_study(d, study, target, overwrite, workers, extra or [], studies, given)
            if why:
                out.append(Comparison(d.name, failures=[why], overrides=given))
                continue
        sf = study_file(d, study, Path(studies)) if rerun else None
        out.append(_settled(d, target, sf, mode, given, ran))
    return out


#: how many times a comparison is made again when the committed results change while it reads
SETTLE = 3


def _settled(
    d: Path, target: Path, sf: Path | None, mode: str, given: list[str], ran: object = None
) -> Comparison:
    """:func:`_judge` of the committed results ``d``, made again when they changed while it
    read them: a ``make reproduce`` in another terminal that published new results of the
    study between its first table and its last (or after their run record was read) made a
    comparison of two runs' tables, a FAILED line of deviations that no re-run had."""
    for _ in range(SETTLE):
        before = _state(d)
        comp = _judge(d, target, sf, mode, given, ran)
        if _state(d) == before:
            comp.tables, comp.overrides = before[-1], given
            return comp
    return Comparison(
        d.name,
        failures=[
            f"{d} changed while verify read it, {SETTLE} times (a run publishing its results "
            "there?): verify it when that run has ended"
        ],
    )


def _state(d: Path) -> tuple:
    """What :func:`_settled` compares before and after: the directory (a publish swaps in
    another) and its tables' content (:func:`tables_digest`)."""
    try:
        st = os.stat(d)
    except OSError:
        return (None, None, None)
    return (st.st_dev, st.st_ino, tables_digest(d))


def _judge(
    d: Path, target: Path, sf: Path | None, mode: str, given: list[str], ran: object = None
) -> Comparison:
    """The comparison of the committed results ``d`` with the re-run ``target``: tables of two
    runs, results of another config, else every table by its rules (and, when one fails,
    whether the results were made by other code)."""
    why = _not_as_written(d) or _replaced_since(d, ran)
    why = why or (_other_config(d, target, sf, given) if mode == "full" else None)
    if why:  # not a reproduction failure of these numbers: results of another input
        return Comparison(d.name, failures=[why])
    comp = compare_dirs(d, target, d.name, mode)
    if not comp.ok and (edited := _edited(d)):  # the user's edit, not the code's failure
        comp.failures.insert(0, edited)
    if not comp.ok and (older := _other_code(d, target)):  # why, before the deviations
        comp.failures.insert(0, older)  # (first: stale results are made again, edits and all)
    return comp


def _replaced_since(d: Path, ran: object) -> str | None:
    """That the committed results ``d`` are no longer those of the config ``ran`` they held when
    their re-run started (``make rerun`` in another terminal published a run of other
    overrides there meanwhile), or None: the re-run reproduces the replaced results, and the
    comparison said that these were "stale against the study file (edited since the run?)"
    and recorded them as failing, results no re-run had been made of."""
    now = (read_record(d) or {}).get("config")
    if not isinstance(ran, dict) or not isinstance(now, dict) or now == ran:
        return None
    keys = sorted(k for k in set(ran) | set(now) if ran.get(k) != now.get(k))
    return (
        f"{d} was replaced while verify re-ran it, by a run of another config (keys "
        f"{', '.join(keys[:5])}{', ...' if len(keys) > 5 else ''}): the re-run reproduces the "
        "results it replaced; verify again"
    )


def _edited(d: Path) -> str | None:
    """The tables of the committed results ``d`` changed after their run wrote them (their
    sha256 is not the one ``run.json`` records), or None: a verdict edited by hand, rows
    reordered or duplicated were listed as deviations of a failed reproduction."""
    changed = edited_tables(d)
    if not changed:
        return None
    return (
        f"{', '.join(changed[:3])}{', ...' if len(changed) > 3 else ''} changed after the run "
        "that wrote them (sha256 not the one in run.json: edited by hand or copied?): the "
        "deviations below are of that change, not of the code; run make reproduce, then verify"
    )


def _not_as_written(d: Path) -> str | None:
    """Why ``sim show`` and ``sim report`` would refuse the committed results ``d`` (a claims
    table without its provenance, as a tool that drops Parquet metadata rewrites it; an older
    version's; another study's; tables of two runs), or None. Verify called such results ok
    when their numbers matched, and make verify's report step then refused them."""
    try:
        check_claims_table(d / "claims.parquet", None)
    except ConfigError as e:
        return f"{e}"
    return None


def _other_code(d: Path, target: Path) -> str | None:
    """That the committed results ``d`` were made by other code than the re-run ``target``
    (their run records' code hashes differ), or None: deviations are then expected of stale
    results, and the FAILED line listed them without saying so."""
    a, b = read_record(d), read_record(target)
    if not (a and b) or a.get("code_hash") == b.get("code_hash"):
        return None
    return (
        f"the committed results were made by other code (code hash {a.get('code_hash')}, this "
        f"version's {b.get('code_hash')}): they are stale; run make reproduce, then verify"
    )


def _other_config(d: Path, target: Path, sf: Path | None = None, given=()) -> str | None:
    """Why the committed results ``d`` cannot be compared with the re-run ``target`` (of the
    study file ``sf``): their run records hold different configs (results left by a run with
    other options, stale against the study file, or made from another file of its name: a
    study author's own ``brown_table1.toml`` re-run as the project's), so numbers that differ
    would be no failure to reproduce. ``given``: the run's overrides the re-run was made with."""
    a, b = read_record(d), read_record(target)
    if not isinstance(a, dict) or not isinstance(b, dict) or "config" not in a:
        return None  # no record to tell: the comparison decides
    ca, cb = a.get("config"), b.get("config")
    if not isinstance(ca, dict) or not isinstance(cb, dict) or ca == cb:
        return None
    if ca.get("study") != cb.get("study"):  # another study's results under this name: its
        # ~70 keys were listed as "another config" with `study` among them
        return (
            f"the committed results are of the study {ca.get('study')!r}, not of "
            f"{cb.get('study')!r} the re-run is (copied under this name?); run make reproduce, "
            "then verify"
        )
    keys = sorted(k for k in set(ca) | set(cb) if ca.get(k) != cb.get(k))
    why = "they are stale or were made with other options"
    rerun = f"the re-run with the run's overrides ({listed(given)})" if given else "the re-run"
    if sf is not None and given:  # its options are on record: the file is not what it was
        why = f"they are stale against {sf} (edited since the run?) or of another study file"
    elif sf is not None:  # re-run from a file of ours: the results may be of a file of theirs
        why = (
            f"they are stale, were made with other options, or from another study file than "
            f"{sf} (name its directory with --studies)"
        )
    return (
        f"the committed results are of another config than {rerun} (keys {', '.join(keys)}): "
        f"{why}; run make reproduce, then verify"
    )
