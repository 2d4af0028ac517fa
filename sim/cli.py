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
import importlib
import os
import signal
import sys

from sim.cli_args import module_doc, parser
from sim.cli_errors import cwd_exists, from_stdout, os_reason
from sim.ends import stdout_failed
from sim.env_vars import environment_problem
from sim.long_words import clipped
from sim.mc.config import ConfigError, StudyError
from sim.mc.memory_limit import memory_given
from sim.mc.path_names import name_problem
from sim.path_args import absolute_path, arrow_name, too_long
from sim.stops import check_interrupt, exit_status, in_main_thread, keep_lost_interrupts
from sim.threads import import_words, interrupted, memory_words, shadowed, short_of_memory

__all__ = ["main", "COMMANDS"]

#: the usage text of ``sim`` (the module docstring, also under ``python -OO``)
DOC = module_doc(__doc__, __file__)

#: exit code of an internal error (a bug, not bad input): one line, traceback with SIM_DEBUG=1
INTERNAL = 3

#: each command's module and function, imported when the command runs: ``sim --version``,
#: ``--help``, a refused option or path load no study, no runner and no SciPy (every
#: command loaded them all: about 1.2 s of CPU before the arguments were read)
COMMANDS = {
    "run": ("sim.cli_run", "run"),
    "check": ("sim.cli_check", "check"),
    "show": ("sim.cli_read", "show"),
    "report": ("sim.cli_read", "report_command"),
}


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
    if args.cmd not in COMMANDS:
        return 1
    module, name = COMMANDS[args.cmd]
    return getattr(_loaded(module), name)(args)


def _loaded(module: str):
    """The command's module, imported now: a library it cannot import (missing, or shadowed
    by a file of its name on the path) is one line naming it (:func:`sim.threads.import_words`),
    as when the suite loads (:func:`sim.threads.interrupt_while_loading`)."""
    try:
        return importlib.import_module(module)
    except (ImportError, AttributeError) as e:
        if (words := import_words(e)) is None:
            raise
        raise ConfigError(None, words) from None


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
