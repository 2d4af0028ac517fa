"""sim: Monte-Carlo checks of classic comparator and plotter calibration papers.

Commands:
  sim run STUDY.toml      run a study; prints its verdicts and writes DIR/README.md
  sim show DIR            print one results directory (--markdown: its README.md)
  sim check STUDY.toml    validate a study file; print each key, its meaning and the work
  sim report              rebuild results/REPORT.md and every results/<study>/README.md

Bad input (a bad study file, a bad override or option, an output path the suite did not
write, a run that fails on its numbers) gives one line on standard error naming the problem
and exit code 2, never a traceback. What the suite did not write is never deleted or
replaced: --out must be a new path, an empty directory, or a results directory of an
earlier run (its run.json). A run works in a locked staging directory .<out>.partial/ that
replaces <out> only when everything succeeded. Without --out a run writes into
results/<study>/ only when it runs the study file as written (no --set, --trials, --seed,
--chunk or --no-figures) and its config and code are those of the committed results there;
any other run goes to scratch/<study>-<config hash>/ and says so (make reproduce and
make rerun pass --out results/<study>).
"""

from __future__ import annotations

import sim.entry_env  # noqa: F401 - imported from Python: the environment, before tqdm loads

# isort: split
import os
import re
import signal
import sys
from pathlib import Path

from tqdm import tqdm  # noqa: F401 - loaded with the command line: a shadowing tqdm.py is named

from sim.api_paths import absolute_path, arrow_name, too_long
from sim.claims.rules import printed_differs
from sim.cli_args import module_doc, parser
from sim.cli_errors import cwd_exists, from_stdout, os_reason
from sim.cli_read import report, show
from sim.ends import stdout_failed, unshown
from sim.env_vars import environment_problem
from sim.execute import check_sweep, execute, sweep_limits
from sim.long_words import clipped
from sim.mc.config import ConfigError, StudyError, check_chunks, parse_override
from sim.mc.memory_limit import memory_given
from sim.mc.outputs import name_problem
from sim.mc.overrides import as_read, command_values, listed, recorded
from sim.mc.paths import absolute
from sim.mc.progress import set_quiet
from sim.mc.read_when import read_in_a_cell
from sim.mc.sweep import expand, read_sweep
from sim.mc.toml_text import toml_key, toml_value
from sim.option_words import two_sets
from sim.places import base, default_out, shown_path
from sim.report.run_summary import off_setup, terminal_summary, write_run_readme
from sim.stops import check_interrupt, exit_status, in_main_thread, keep_lost_interrupts
from sim.studies import design_config, get_study, unread_keys
from sim.studies.picking import load_picking_chunk
from sim.threads import interrupted, memory_words, shadowed, short_of_memory

__all__ = ["main", "check_run_args"]

#: the usage text of ``sim`` (the module docstring, also under ``python -OO``)
DOC = module_doc(__doc__, __file__)

#: exit code of an internal error (a bug, not bad input): one line, traceback with SIM_DEBUG=1
INTERNAL = 3
_SCHEDULER = re.compile(
    r"^(?:(?:tcp|tls|ucx|ws|wss)://)?(?:\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+)"
    r":(\d{1,5})/?$"
)


def check_run_args(args) -> Path:
    """Options that need no study: one line each. Returns the output path (absolute)."""
    if args.workers < 1 or args.workers > max(4 * (os.cpu_count() or 1), 8):
        raise ConfigError(
            "--workers",
            f"must be between 1 and {max(4 * (os.cpu_count() or 1), 8)} (got {args.workers})",
        )
    if args.scheduler is not None:
        m = _SCHEDULER.match(args.scheduler)
        if not m or not 0 < int(m.group(1)) < 65536:
            raise ConfigError(
                "--scheduler",
                f"not a scheduler address like tcp://HOST:8786 (got {args.scheduler!r})",
            )
        if args.executor != "dask":
            raise ConfigError("--scheduler", "needs --executor dask")
    if args.out is not None:
        if not args.out.strip():
            raise ConfigError("--out", "is empty: name an output directory")
        if args.out == "-":  # read as standard output by many programs: it made a directory "-"
            raise ConfigError(
                "--out", "'-' is not standard output here: name a directory (./- for one named '-')"
            )
        why = name_problem(args.out)
        if why:
            raise ConfigError("--out", f"{why} (got {args.out!r})")
    return absolute(args.out) if args.out else None


def _keys_set(overrides: list[str]) -> set[str]:
    """The keys of the ``--set`` overrides; a key set twice is refused (one of its values
    would be dropped silently)."""
    keys = set()
    for text in overrides:
        try:
            key = parse_override(text)[0]
        except ConfigError:
            continue  # load_study names the bad override
        if key in keys:
            raise ConfigError(key, "given twice by --set: give one value")
        keys.add(key)
    return keys


def load_run(args):
    """The study and its resolved config, as ``sim run`` (or ``check``) with the parsed
    ``args`` resolves them. ``--trials`` (or ``--set trials=``) without a chunk
    size picks the largest chunk giving at least MIN_CHUNKS chunks; ``--chunk`` sets it
    (:func:`sim.studies.picking.load_picking_chunk`, :func:`sim.load`'s rule too)."""
    set_quiet(getattr(args, "quiet", False))  # the check of a large network shows its steps
    overrides = list(args.set) + ([f"chunk={args.chunk}"] if args.chunk is not None else [])
    given = _keys_set(args.set)
    for opt, key in (("--trials", "trials"), ("--seed", "seed"), ("--chunk", "chunk")):
        if getattr(args, key) is not None and key in given:  # one would be dropped silently
            raise ConfigError(opt, f"given twice, as {opt} and as --set {key}=: give one")
    trials = args.trials is not None or "trials" in given
    picks = trials and args.chunk is None and "chunk" not in given  # --trials's chunk
    try:
        with memory_given(getattr(args, "max_memory_gb", None)):  # a network's size (sim.batch)
            return load_picking_chunk(args.study, picks, overrides, args.trials, args.seed)
    except ConfigError as e:  # --set trials=40,seed=3: two overrides in one, named
        if hint := two_sets(args.set, e.key):
            raise ConfigError(e.key, e.detail + hint) from None
        raise


def _run(args) -> int:
    out = check_run_args(args)
    study, cfg = load_run(args)
    sweep = read_sweep(args.study, study.schema)  # a [sweep] table: run every cell
    overwrite = args.overwrite
    given = command_values(args.set, trials=args.trials, seed=args.seed, chunk=args.chunk)
    overrides = recorded(as_read(given, cfg))  # --set trials=1e3 as --trials 1e3: trials=1000
    if out is None:
        out, shown, scratch = default_out(cfg, sweep, Path(args.study), _off(overrides, args))
        overwrite = overwrite or scratch
    else:
        shown = args.out
    if (why := unshown(f"{shown.rstrip('/')}/README.md")) is not None:  # its closing lines
        raise ConfigError("--out" if args.out is not None else None, why)
    arrow_name("--out" if args.out is not None else None, out)
    execute(
        study,
        cfg,
        sweep,
        out,
        shown,
        executor=args.executor,
        workers=args.workers,
        scheduler=args.scheduler,
        overwrite=overwrite,
        quiet=args.quiet,
        max_memory_gb=args.max_memory_gb,
        max_adjustments=args.max_adjustments,
        figures=not args.no_figures,
        readme=lambda stage, name: write_run_readme(stage, get_study, name, out, design_config),
        overrides=overrides,
        source=args.study,
    )
    args.published = shown  # an interrupt from now on finds the results written
    check_interrupt()  # dropped by Python since the results were published: not exit 0
    try:  # (its README.md was written before the results were published)
        summary = terminal_summary(out, shown=shown, get_study=get_study)
    except (OSError, ValueError, KeyError) as e:  # the results stand; only their summary failed
        summary = f"(no summary: {type(e).__name__}: {e})".splitlines()[0]
    print(f"{cfg['study']}: results in {shown.rstrip('/')}/")  # (--out DIR/: not DIR//)
    if not args.quiet:
        print(summary)
    return 0


def _off(overrides: list[str], args) -> str | None:
    """What makes a run other than its study file as written (the words of
    :func:`sim.places.default_out`), or None."""
    what = [f"the overrides {listed(overrides)}"] if overrides else []
    what += ["--no-figures"] if args.no_figures else []
    return " and ".join(what) or None


def _n(x: float) -> str:
    """A bound as ``sim check`` lists it: an integer exactly (``seed``'s 2**63 - 1 was
    ``9.22337e+18``, below the value it let the key hold), a float's whole number with its
    digits grouped, another float as ``%g``."""
    if isinstance(x, int):
        return f"{x:_}"
    return f"{int(x):_}" if float(x).is_integer() and abs(x) < 1e16 else f"{x:g}"


def _bounds(f) -> str:
    if f.choices:
        return "one of " + ", ".join(map(str, f.choices))
    if f.lo is None and f.hi is None:
        return ""
    lo = "" if f.lo is None else (f"> {_n(f.lo)}" if f.lo_open else f">= {_n(f.lo)}")
    hi = "" if f.hi is None else f"<= {_n(f.hi)}"
    return ", ".join(x for x in (lo, hi) if x)


#: ``sim check``'s note on a printed key: another value, or the paper's setup in other keys
_PRINTED = ("another value is off its setup", "the paper's setup spelled another way")


def _check(args) -> int:
    # the config sim run would resolve: --set trials= without a chunk picks the chunk
    args.trials = args.chunk = args.seed = None
    study, cfg = load_run(args)
    check_chunks(cfg)  # what sim run refuses, sim check refuses too
    sweep = read_sweep(args.study, study.schema)
    est = sweep_limits(study, cfg, sweep, args.max_memory_gb, args.max_adjustments)  # at one worker
    check_sweep(study, cfg, sweep)  # a sweep of only refused cells is refused (sim run too)
    print(f"# {cfg['study']}: {study.title}")
    # listed commented out (set, they would be refused); one a sweep's cells read is kept
    cells = expand(sweep)[1] if sweep else []
    skip = {
        k: w
        for k, w in unread_keys(study, cfg).items()
        if not read_in_a_cell(study.schema[k], cfg, cells)
    }
    off = printed_differs(study.schema, cfg, study.as_printed)
    # a printed key spelling the paper's setup another way (Table 1's 25 points as a list)
    spelled = {s.split(" = ")[0] for s in printed_differs(study.schema, cfg)}
    spelled -= {s.split(" = ")[0] for s in off}
    for k, v in cfg.items():
        f = study.schema.get(k)
        if f is None:
            print(f"{k} = {toml_value(v)}")
            continue
        unit = f.unit or ""
        notes = "; ".join(
            x
            for x in (
                unit and f"unit {unit}",
                _bounds(f),
                f.compared
                and "settings compared: each once"
                + ("" if f.kind == "list[str]" else ", read in increasing order"),
                "paper input" if f.input else "",
                f.printed and f"printed by the paper: {_PRINTED[k in spelled]}",
                k in skip and f"not read: {skip[k]}",
            )
            if x
        )
        line = f"{k} = {toml_value(v)}  # {f.doc}" + (f" ({notes})" if notes else "")
        print(f"# {line}" if k in skip else line)
    if sweep:  # as the file gives it: the listing saved is the same study, sweep and all
        print("[sweep]")
        for k, v in sweep.items():
            print(f"{toml_key(k)} = {toml_value(v)}")
    if off:  # said before the run: its predictions will be findings (sim.claims.rules)
        print(f"# {off_setup(study, cfg, before=True)}")
    print(f"# work: {est.describe()}; {est.core_time()}")
    for note in study.notes(dict(cfg)) if study.notes else []:  # N45: said before the run
        print(f"# note: {note}")
    return 0


#: signals that end a command as Ctrl-C does; SIGXCPU: the soft CPU limit (``ulimit -S -t``),
#: which killed a run with "CPU time limit exceeded" and no line of its own
_STOPS = (signal.SIGTERM, signal.SIGHUP, signal.SIGXCPU)
_cpu_limit = []  # set when SIGXCPU ended the command: its one line says why


def _on_sigterm(signum, frame):
    if signum == signal.SIGXCPU:  # sent again every second: once is enough (the cleanup runs)
        signal.signal(signal.SIGXCPU, signal.SIG_IGN)
        _cpu_limit.append(signum)
    raise KeyboardInterrupt


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    # signal handlers are the main thread's to set: main() called from another thread (a
    # notebook's worker, a test runner) ended in "ValueError: signal only works in main thread"
    old = {s: signal.getsignal(s) for s in _STOPS} if in_main_thread() else {}
    _cpu_limit.clear()
    try:
        if not argv:  # usage, not an error message
            parser(DOC).print_help()
            return 2
        if (problem := environment_problem()) is not None:  # as the sim command refuses it
            print(f"sim: error: {problem}", file=sys.stderr)  # (sim.cli.main from Python)
            return 2
        with keep_lost_interrupts():  # Ctrl-C that Python drops in a C callback: kept
            return _main(argv)
    except BrokenPipeError as e:  # sim check ... | head: the reader left, nothing to say
        return stdout_failed("sim", e, 0)
    finally:  # in-process callers (the tests, the API) get their handlers back
        for s, h in old.items():
            if h is not None:
                signal.signal(s, h)


def _interrupted_line(args) -> str:
    """The one line of an interrupted command: a run says how to finish it (its finished
    chunks are kept), or where its results are when they were written before the interrupt."""
    why = " by the CPU time limit (ulimit -t)" if _cpu_limit else ""
    again = ""
    if args is not None and getattr(args, "cmd", None) == "run":
        again = "; run the same command again to finish the missing chunks"
        if getattr(args, "chunks_done", False):  # none is missing: the re-run only writes
            again = (
                "; every chunk was done and is kept: run the same command again to write the "
                "results from them (no trial is computed again)"
            )
    if getattr(args, "published", None):  # nothing is missing: say where the results are
        again = f" after the results were written to {args.published}/"
    return f"sim: interrupted{why}{again}"


def _main(argv: list[str]) -> int:
    args = None
    try:
        try:
            args = parser(DOC).parse_args(argv)
        except SystemExit as e:  # --help, --version: printed; the caller (a notebook) goes on
            return exit_status(e.code)
        if args.cmd in ("run", "check") and name_problem(args.study):
            why = name_problem(args.study)
            raise ConfigError("STUDY", f"not a study file name: {why} (got {args.study!r})")
        if args.cmd in ("run", "check") and (why := too_long(args.study)) is not None:
            raise ConfigError("STUDY", why)  # it was the system's words and the whole path
        if args.cmd in ("run", "check"):  # the working directory gone: not "no such study file"
            absolute_path("STUDY", args.study)
        if args.cmd == "show":
            absolute_path("DIR", args.dir)
            arrow_name("DIR", args.dir)
        if sys.stdout is None:  # >&-: print() wrote nowhere (every command, as sim.ends.finish)
            raise ConfigError(None, "standard output is closed (>&-): nothing to print to")
        for s in _STOPS if in_main_thread() else ():
            if signal.getsignal(s) is signal.SIG_DFL:  # clean up like Ctrl-C (nohup: ignored):
                signal.signal(s, _on_sigterm)  # a run's stage, report's temporary files
        code = _command(args)
        check_interrupt()  # an interrupt Python dropped (a C callback) never ends in exit 0
        return code
    except (ConfigError, StudyError) as e:
        print(clipped(f"sim: error: {e}".splitlines()[0]), file=sys.stderr)  # 100 KB of a key
        return INTERNAL if getattr(e, "internal", False) else 2
    except KeyboardInterrupt as e:
        if getattr(e, "published", None) and args is not None:  # as the run published
            args.published = e.published
        if getattr(e, "chunks_done", False) and args is not None:
            args.chunks_done = True
        print(_interrupted_line(args), file=sys.stderr)
        return 130
    except BrokenPipeError:
        raise
    except OSError as e:  # a failing write (full disk, vanished directory): one line, no traceback
        if short_of_memory(e):  # ulimit -v: a library loaded on first use could not be mapped
            print(f"sim: error: {memory_words(e)}", file=sys.stderr)
            return 2
        name = getattr(e, "filename", "") or ""
        if not name and not e.strerror and len(e.args) == 1 and isinstance(e.args[0], str):
            name = e.args[0]  # pyarrow's FileNotFoundError(path)
        if not name and not cwd_exists():
            name = "the working directory (it was deleted)"
        if not name and from_stdout(e):
            name = "standard output"
        print(f"sim: error: {os_reason(e)}: {name}".rstrip(": "), file=sys.stderr)
        return 2
    except UnicodeEncodeError as e:  # a text the terminal's encoding cannot show (ascii)
        what = ascii(e.object[e.start : e.end]) if isinstance(e.object, str) else "a character"
        print(
            f"sim: error: the output (encoding {e.encoding}) cannot show {what}: "
            "set PYTHONIOENCODING=utf-8",
            file=sys.stderr,
        )
        return 2
    except (ArithmeticError, ValueError, MemoryError, RecursionError) as e:  # e.g. a sweep
        # cell table; a file nested too deep to read (a run.json of 100,000 brackets)
        if short_of_memory(e):
            print(f"sim: error: {memory_words(e)}", file=sys.stderr)
            return 2
        print(f"sim: error: {type(e).__name__}: {e}".splitlines()[0], file=sys.stderr)
        return 2
    except Exception as e:  # noqa: BLE001 - a bug outside a run (check, show, report, loading):
        if interrupted(e):  # Ctrl-C inside an import: ImportError from the KeyboardInterrupt;
            print(_interrupted_line(args), file=sys.stderr)  # a second one in a run's clean-up
            return 130
        if short_of_memory(e):  # an ImportError: a library that could not be mapped
            print(f"sim: error: {memory_words(e)}", file=sys.stderr)
            return 2
        if (words := shadowed(e)) is not None:  # a user's tomllib.py: not a bug of ours
            print(f"sim: error: {words}", file=sys.stderr)
            return 2
        if os.environ.get("SIM_DEBUG"):  # one line as docs/cli.md promises, the traceback on
            raise  # request
        what = f"{type(e).__name__}: {e}".splitlines()[0]
        print(f"sim: internal error: {what} (SIM_DEBUG=1 shows where)", file=sys.stderr)
        return INTERNAL


def _command(args) -> int:
    with memory_given(getattr(args, "max_memory_gb", None)):  # a network's size at load too
        return _dispatch(args)


def _dispatch(args) -> int:
    if args.cmd == "run":
        return _run(args)
    if args.cmd == "check":
        return _check(args)
    if args.cmd == "show":
        return show(args)
    if args.cmd == "report":
        if args.results is None:  # from a directory inside the project (docs/): the project's
            args.results = shown_path(base() / "results")
        if name_problem(args.results):
            why = name_problem(args.results)
            raise ConfigError("--results", f"not a directory name: {why} (got {args.results!r})")
        return report(Path(args.results))
    return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
