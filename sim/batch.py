"""Run many study files side by side: the driver of ``make reproduce`` and ``make rerun``.

``python -m sim.batch [--jobs J] [--stale-only] [--results DIR] [--timings F] FILE ...
[-- RUN_OPTIONS]``

Each study file runs in a process of its own, exactly as ``python -m sim run FILE --out
DIR/<file name> --overwrite RUN_OPTIONS`` (so its ``--workers`` pool, its staging directory
and its lock are as for one run), ``J`` of them at a time. Two studies side by side keep both
cores busy while one of them waits on its last chunk, draws a figure or writes its tables;
the slowest studies (:data:`SLOW_FIRST`) are started first so that the side-by-side runs end
together. Each run is a fresh ``python -m sim run`` (a driver that imported the suite once
and forked a child per study saved 4 % of ``make rerun``'s time, 57.3 against 59.6 s, under
the 20 % that keeps such machinery, issue 22, so it went). With ``J > 1`` the runs are quiet (progress bars of several runs
would overwrite each other); each study's line is printed when it ends. ``--stale-only``:
only the studies whose results are not current (:func:`is_current`: their run record holds
the config this run would resolve, run options included, and the current code), the others
are reported up to date; each study run is named with the reason (:func:`why_stale`). A run that fails prints its own one-line message, which starts with the name of its study
file; the others go on,
and the exit code is that of the first failure (1 when a run was killed). After the last run one
line on standard output says how many ran and which failed (:func:`summary`). Bad input is
refused before any run starts, exit 2, one line for each bad file (every one named): a file
that is missing or a directory, two runs into one results directory, and a study file whose
config its run would refuse (resolved here with the run options, as ``sim run`` resolves it:
a file ported from another study, a bad value). Without ``--results`` (the default
``results/``, the project's study files as written), run options that set a key or
``--no-figures``, and in the project's root a study file that is not ``studies/<name>.toml``,
are refused naming ``--results`` (``sim run`` without ``--out`` sends such runs to
``scratch/``; ``make reproduce`` and ``make rerun`` name ``--results results``).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from sim.env_vars import environment_problem, refuse_bad_variables
from sim.threads import interrupt_while_loading, refuse_bad_environment, single_threaded_blas

if __name__ == "__main__":  # 2>&-: before any file takes its descriptor (sim.ends)
    from sim.ends import open_standard_streams

    open_standard_streams()
_loaded = interrupt_while_loading("sim.batch")  # Ctrl-C during the imports: one line, exit 130
if __name__ == "__main__":
    refuse_bad_environment("sim.batch")  # a variable NumPy cannot load with: one line, exit 2
else:  # imported from Python (sim.batch.main([...])): a ConfigError naming the variable
    import sim.entry_env  # noqa: F401
single_threaded_blas()  # before NumPy loads (the study modules import it)
if __name__ == "__main__":
    refuse_bad_variables("sim.batch")  # SIM_NO_JIT=0, NUMBA_OPT=fast: one line, exit 2

from sim.api_paths import gone_cwd, too_long  # noqa: E402
from sim.batch_checks import (  # noqa: E402
    _clashes,
    _configs_problems,
    _default_results_problem,
    _files_after,
    _in_batch_words,
    _parsed,
    _replaces_project_results,
    _run_options_problem,
    _timings_problem,
    _unknown_sets,
    is_current,
    why_stale,
)
from sim.batch_memory import MemoryGate  # noqa: E402
from sim.batch_order import SLOW_FIRST, order  # noqa: E402
from sim.batch_report import not_rebuilt, rebuild_report, report_problem  # noqa: E402
from sim.batch_summary import _Named, _Stdout, summary  # noqa: E402
from sim.batch_timings import TimingsLock  # noqa: E402
from sim.cli_args import module_doc  # noqa: E402
from sim.ends import finish  # noqa: E402
from sim.held_stops import held_stops  # noqa: E402
from sim.mc.argv import OnceParser, integer  # noqa: E402
from sim.mc.children import STOP_SIGNALS, child_env, child_text, ended, stop_children  # noqa: E402
from sim.mc.outputs import name_problem  # noqa: E402
from sim.mc.paths import link_problem  # noqa: E402
from sim.mc.storage import atomic_path  # noqa: E402
from sim.mc.study_file import study_file_problem  # noqa: E402
from sim.option_words import Meant  # noqa: E402
from sim.places import base, shown_path  # noqa: E402
from sim.report_due import due_words  # noqa: E402
from sim.stops import (  # noqa: E402
    check_interrupt,
    exit_status,
    in_main_thread,
    keep_lost_interrupts,
    run_program,
)

if __name__ != "__main__":  # imported: the default handlers (the program: run_program's)
    _loaded()

__all__ = ["SLOW_FIRST", "order", "run_all", "main", "summary", "is_current", "why_stale"]


def run_all(
    files: list[Path],
    results: Path,
    jobs: int = 2,
    run_args=(),
    stale_only=False,
    log=print,
    extra=None,
    loaded=None,
    memory=None,
) -> dict[str, tuple[int, float, float]]:
    """Run every study file of ``files`` into ``results/<stem>``, ``jobs`` at a time, with
    ``run_args`` (and ``extra[stem]``, more arguments of one study's run). ``log`` gets the
    up-to-date lines and, for runs side by side, each run's output when it ends. Returns
    ``{stem: (exit code, wall seconds, start in seconds after the first start)}`` of the runs
    made (up-to-date studies are left out). ``loaded``: ``{file: (args, study, cfg, sweep)}``
    of the files the batch resolved before (:func:`sim.batch_checks._configs_problems`),
    which ``--stale-only`` does not resolve again. ``memory``: ``({file: estimated bytes},
    the runs' --max-memory-gb)``, what the runs side by side may hold (:mod:`sim.batch_memory`)."""
    todo = []
    try:
        for f in order(files):
            if stale_only:  # is_current's question, asked once (seconds: the tables' sha256)
                why = why_stale(f, results / f.stem, run_args, (loaded or {}).get(f))
                if why is None:
                    log(f"{f.stem}: up to date")
                    continue
                log(f"{f.stem}: out of date ({why}): running it")
            todo.append(f)
    except KeyboardInterrupt as e:  # before any run started (the driver says so)
        e.started = False
        raise
    quiet = ["--quiet"] if jobs > 1 and "--quiet" not in run_args else []

    def argv(f: Path) -> list[str]:
        # a name "-r" (--results=-r, ./-x.toml) is a value: sim run read "--out -r/x" as no --out
        return [
            "run",
            str(f) if not str(f).startswith("-") else f"./{f}",
            f"--out={results / f.stem}",
            "--overwrite",
            *run_args,
            *quiet,
            *(extra or {}).get(f.stem, ()),
        ]

    t0 = time.perf_counter()
    procs: list[subprocess.Popen] = []
    written: list[str] = []  # the study files whose runs published their results
    stop = threading.Event()  # set on an interrupt: start no more runs, print nothing of theirs
    starting = threading.Lock()

    gate = MemoryGate(*(memory or ({}, None)))

    def one(f: Path):  # started when its estimate fits beside the runs going
        return gate.around(f, stop, started, lambda: (f.stem, None, 0.0, time.perf_counter() - t0))

    def started(f: Path):
        cmd = [sys.executable, "-m", "sim", *argv(f)]
        t = time.perf_counter()
        with starting:
            if stop.is_set():
                return f.stem, None, 0.0, t - t0
            try:
                proc = subprocess.Popen(
                    cmd,
                    # its lines reach standard output through the driver's log, --jobs 1 too
                    # (where a full or closed one was a line per run, and a reader that left
                    # the exit code of the first run's, not the driver's)
                    stdout=subprocess.PIPE,
                    stderr=subprocess.PIPE,
                    env=child_env(),  # ends with the driver, even after kill -9
                    **child_text(),  # the child's encoding, which is the driver's
                )
            except OSError as e:  # no process or pipe to be had (ulimit -n, -u): one line
                why = e.strerror or str(e)
                print(f"sim.batch: {f.name}: cannot start its run: {why}", file=sys.stderr)
                return f.stem, 2, time.perf_counter() - t, t - t0
            procs.append(proc)
        with proc:
            stdout, stderr = proc.communicate()
        wall = time.perf_counter() - t
        if proc.returncode == 0 or PUBLISHED in (stderr or ""):  # (interrupted as it published)
            written.append(f.name)
        if stop.is_set():  # interrupted: the driver says so in one line
            return f.stem, None, wall, t - t0
        if proc.returncode < 0:  # killed by a signal (kill -9, the OOM killer): it said not a word
            why = ended(proc.returncode)
            stderr = f"{stderr or ''}its run {why}; the same command again resumes it\n"
        named = _Named(sys.stderr, f.name)
        named.write(_in_batch_words(stderr))
        named.flush()
        if stdout:
            log(stdout.rstrip())
        return f.stem, proc.returncode, wall, t - t0

    out: dict[str, tuple[int, float, float]] = {}
    pool = ThreadPoolExecutor(max_workers=jobs)
    try:
        for stem, code, wall, start in pool.map(one, todo):
            out[stem] = (code, wall, start)
            check_interrupt()  # one Python dropped (a C callback): the other runs end too
    except KeyboardInterrupt as e:
        stop_children(procs, first=lambda: _set(stop, starting))
        pool.shutdown(wait=True, cancel_futures=True)
        e.written = written  # for the driver's line: results replaced are not "unfinished"
        e.started = bool(procs)  # (complete: no run starts once stop_children set the flag)
        raise
    pool.shutdown()
    return out


def _set(stop: threading.Event, starting: threading.Lock) -> None:
    """Start no more runs (under the lock that starts one, so none starts after this)."""
    with starting:
        stop.set()


def _on_sigterm(signum, frame):
    raise KeyboardInterrupt


class _BadArgs(ValueError):
    """A refusal of the command line (main prints its one line)."""


class _Parser(Meant, OnceParser):  # -j, --out, --workers: what they mean here
    words = "batch"

    def refuse(self, message: str):  # one line, exit 2 (main prints it)
        raise _BadArgs(message)


#: the driver's line when it was interrupted
INTERRUPTED = "sim.batch: interrupted; the same command again resumes the unfinished runs"
#: what a run of ``sim run`` interrupted while it published its results says
PUBLISHED = "interrupted after the results were written to"
#: the driver's line when it was interrupted before its first run started (checking its files)
NOTHING_RUN = "sim.batch: interrupted before any run started: nothing was run"


def main(argv: list[str] | None = None) -> int:
    signals = (signal.SIGINT, *STOP_SIGNALS) if in_main_thread() else ()
    old = {s: signal.getsignal(s) for s in signals}
    phase: list[str] = []  # "run": the runs started; "ended": every run ended
    if (problem := environment_problem()) is not None:  # as python -m sim.batch refuses it
        print(f"sim.batch: error: {problem}", file=sys.stderr)  # (from Python: not a line
        return 2  # of sim run's for each study)
    try:
        with keep_lost_interrupts():  # Ctrl-C that Python drops in a C callback: kept
            code = _main(list(sys.argv[1:] if argv is None else argv), phase)
            phase.append("ended")
            check_interrupt()  # and never exit 0 after one
            return code
    except KeyboardInterrupt:  # while it checked its files it said it "resumes the unfinished
        said = {"run": INTERRUPTED, "ended": _ENDED}  # runs" of a batch that had started none
        said.update({p: f"{_ENDED}; {not_rebuilt(p[7:])}" for p in phase if p[:7] == "report "})
        print(said.get(phase[-1], INTERRUPTED) if phase else NOTHING_RUN, file=sys.stderr)
        return 130
    finally:  # in-process callers (the tests) get their handlers back
        for s, h in old.items():
            if h is not None:
                signal.signal(s, h)


def _main(argv: list[str], phase: list[str]) -> int:
    run_args = []
    if "--" in argv:
        i = argv.index("--")
        argv, run_args = argv[:i], argv[i + 1 :]
    ap = _Parser(
        prog="python -m sim.batch",
        usage="python -m sim.batch [-h] [--jobs JOBS] [--results RESULTS] "
        "[--stale-only] [--report] [--timings TIMINGS] files [files ...] [-- RUN_OPTIONS]",
        description=module_doc(__doc__, __file__).partition("\n")[0].replace("``", ""),
        epilog="RUN_OPTIONS after -- are sim run's (--trials, --set KEY=VALUE, --workers, ...), "
        "read once before any run starts; each study writes RESULTS/<file name>, so --out is "
        "refused.",
    )
    ap.add_argument("files", nargs="+", help="study files")
    ap.add_argument(
        "--jobs", type=integer("jobs", 1, 64), default=2, help="studies run at a time (default 2)"
    )
    ap.add_argument("--results", help="results directory (default results, the project's)")
    ap.add_argument(
        "--stale-only", action="store_true", help="only the studies whose results are not current"
    )
    ap.add_argument(
        "--report",
        action="store_true",
        help="then rebuild RESULTS/REPORT.md (sim report); after a failed or interrupted batch "
        "when a run published its results",
    )
    ap.add_argument("--timings", help="write {study: [exit code, wall s, start s]} (JSON) here")
    try:
        args = ap.parse_args(argv)
    except SystemExit as e:  # --help: printed; an in-process caller (a notebook) goes on
        return exit_status(e.code)
    except _BadArgs as e:
        print(
            f"sim.batch: {e}{_files_after(str(e), run_args)} (see python -m sim.batch --help)",
            file=sys.stderr,
        )
        return 2
    default = args.results is None  # the project's results/ (from docs/ too): the files as written
    args.results = shown_path(base() / "results") if default else args.results
    if name_problem(args.results):
        why = name_problem(args.results)
        print(f"sim.batch: --results: {why} (got {args.results!r})", file=sys.stderr)
        return 2
    if why := link_problem(args.results):  # a loop: every run would fail on it, one by one
        print(f"sim.batch: --results: {args.results} {why}", file=sys.stderr)
        return 2
    for name, v in [("FILE", f) for f in args.files] + [("--results", args.results)]:
        if (why := gone_cwd(name, v)) is not None:  # not "no such study file" (sim check's)
            print(f"sim.batch: {why}", file=sys.stderr)
            return 2
    if os.path.lexists(args.results) and not os.path.isdir(args.results):
        # each run would name --out, an option this command line does not hold, one by one
        print(f"sim.batch: --results: {args.results} is not a directory", file=sys.stderr)
        return 2
    for name, v in [("FILE", f) for f in args.files] + [("--timings", args.timings)]:
        if v is not None and name_problem(v):
            print(f"sim.batch: {name}: {name_problem(v)} (got {v!r})", file=sys.stderr)
            return 2
    for name, v in [("FILE", f) for f in args.files] + [("--results", args.results)]:
        if (why := too_long(str(v))) is not None:  # pathlib's OSError traceback otherwise
            print(f"sim.batch: {name}: {why}", file=sys.stderr)
            return 2
    files = [Path(f) for f in args.files]
    problems = [study_file_problem(f) for f in files]  # sim check's own check of a file
    bad = [why for why in problems if why]  # every one, not the first only
    bad += _clashes([f for f, why in zip(files, problems) if not why], run_args, args.results)
    for why in bad:
        print(f"sim.batch: {why}", file=sys.stderr)
    if bad:
        return 2
    why = _run_options_problem(run_args)
    if why:
        print(f"sim.batch: run options: {why}", file=sys.stderr)
        return 2
    why, note = _unknown_sets(files, run_args)
    if why:
        print(f"sim.batch: run options: {why}", file=sys.stderr)
        return 2
    args.memory = ({}, _parsed(run_args).max_memory_gb)  # each run's estimate (batch_memory)
    bad, loaded = _configs_problems(
        files, run_args, Path(args.results), args.stale_only, args.memory[0]
    )
    for why in bad:
        print(f"sim.batch: {why}", file=sys.stderr)
    if bad:
        return 2
    why = _timings_problem(args.timings) if args.timings is not None else None
    lock = TimingsLock(args.timings) if args.timings is not None and not why else None
    why = why or (lock.acquire() if lock else None)
    if why:
        print(f"sim.batch: --timings: {why}", file=sys.stderr)
        return 2
    try:
        return _run(args, files, run_args, note, loaded, default, phase)
    finally:
        if lock:
            lock.release()


def _run(args, files: list[Path], run_args: list[str], note, loaded, default, phase) -> int:
    """Run the checked ``files`` and write their timings; the batch's exit code. ``default``:
    no ``--results`` was given; ``phase``: told when the runs start and end (:func:`main`)."""
    whys = [_replaces_project_results(f, Path(args.results)) for f in files]
    for why in [*whys, args.report and report_problem(Path(args.results))]:
        if why:  # (a REPORT.md of the user's: refused after the runs, which ran for nothing)
            print(f"sim.batch: {why}", file=sys.stderr)
            return 2
    if default and (why := _default_results_problem(files, run_args)):
        print(f"sim.batch: {why}", file=sys.stderr)
        return 2
    for s in STOP_SIGNALS if in_main_thread() else ():
        if signal.getsignal(s) is signal.SIG_DFL:
            signal.signal(s, _on_sigterm)  # end the runs as Ctrl-C does
    if note:  # once, not one line per run that refuses it
        print(f"sim.batch: note: {note}", file=sys.stderr)
    if not args.report and (due := due_words(Path(args.results))):  # (--report rebuilds it)
        print(f"sim.batch: note: {due}", file=sys.stderr)
    log = _Stdout()
    phase.append("run")
    try:
        todo, out, jobs, stale = files, Path(args.results), args.jobs, args.stale_only
        done = run_all(todo, out, jobs, run_args, stale, log, loaded=loaded, memory=args.memory)
        check_interrupt()  # before the timings are written
    except KeyboardInterrupt as e:  # the runs were stopped and cleaned up
        if getattr(e, "started", True) is False:  # (--stale-only's checks: seconds) it said
            print(NOTHING_RUN, file=sys.stderr)  # it "resumes the unfinished runs" of none
            return 130
        w = getattr(e, "written", None)  # it said nothing of a run's results published meanwhile
        named = f" (the results of {', '.join(w)} were written)" if w else ""
        print(INTERRUPTED + named, file=sys.stderr)
        if w and args.report:  # (Ctrl-C or SIGTERM again: one line of the report's)
            rebuild_report(Path(args.results))
        return 130
    written: list[str] = []
    report = args.report and (not done or any(v[0] == 0 for v in done.values()))
    phase.append(f"report {args.results}" if report else "ended")  # (the report is due)
    try:
        code = _finish(args, files, done, log, written)
    except KeyboardInterrupt:  # it said "resumes the unfinished runs" of a batch with none
        print(_ENDED + "".join(written), file=sys.stderr)
        code = 130
    rc = rebuild_report(Path(args.results)) if report else 0  # (after its summary line)
    phase.append("ended")
    return rc if rc == 130 else code or rc


#: the driver's line when interrupted after every run ended (writing the timings, the summary)
_ENDED = "sim.batch: interrupted after every run ended"


def _finish(args, files: list[Path], done: dict, log, written: list[str]) -> int:
    """Write the timings of the ended runs ``done`` (an interrupt meanwhile is handled once
    they are written: ``written`` then says so) and print the summary; the exit code."""
    if args.timings is not None:
        try:
            with held_stops(), atomic_path(args.timings) as tmp:  # a write cut short (a full
                tmp.write_text(json.dumps(done), encoding="utf-8")  # disk) keeps the earlier
                written.append(f"; their timings were written to {args.timings}")
        except OSError as e:  # a full disk, ulimit -f: the runs stand, their timings do not
            print(f"sim.batch: --timings: {e.strerror or e}: {args.timings}", file=sys.stderr)
            return 2
    failed = [v[0] for v in done.values() if v[0] != 0]
    code = (failed[0] if failed[0] > 0 else 1) if failed else 0
    log(summary(files, done, code))
    if log.error is not None and not isinstance(log.error, BrokenPipeError):
        print(f"sim.batch: standard output: {log.error.strerror or log.error}", file=sys.stderr)
        return code if failed else 2
    if log.error is not None and not failed:  # a reader that left (| head -1): as sim does
        return 141
    return code


if __name__ == "__main__":  # a signal after main returned: its exit code stands
    sys.exit(finish("sim.batch", lambda: run_program("sim.batch", main, _loaded)))
