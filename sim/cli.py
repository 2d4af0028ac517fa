"""Command line: ``sim run STUDY.toml``, ``sim check STUDY.toml``, ``sim report``.

Bad input (a bad study file, a bad override or option, an output path the suite did not
write, a run that fails on its numbers) gives one line on standard error naming the problem
and exit code 2, never a traceback. What the suite did not write is never deleted or
replaced: ``--out`` must be a new path, an empty directory, or a results directory of an
earlier run (its ``run.json``). A run works in a locked staging directory
``.<out>.partial/`` that replaces ``<out>`` only when everything succeeded.
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import sys
from pathlib import Path

from sim.execute import execute
from sim.mc.config import ConfigError, StudyError
from sim.mc.sweep import read_sweep
from sim.report.markdown import write_report
from sim.studies import get_study, load_study

__all__ = ["main"]

#: exit code of an internal error (a bug, not bad input): one line, traceback with SIM_DEBUG=1
INTERNAL = 3


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (exit 2 through :func:`main`, no usage dump)."""

    def error(self, message: str):
        raise ConfigError(None, f"{self.prog}: {message} (see {self.prog} --help)")


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="sim", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run a study and write its results directory")
    r.add_argument("study", help="study file, e.g. studies/brown_dilution.toml")
    r.add_argument("--out", help="output directory (default results/<study>)")
    r.add_argument("--trials", type=int, help="override the number of Monte-Carlo trials")
    r.add_argument("--seed", type=int, help="override the root seed")
    r.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override any config key with its dotted name (repeatable)",
    )
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.add_argument(
        "--executor",
        choices=("local", "dask"),
        default="local",
        help="local (in-process, or a process pool with --workers) or dask",
    )
    r.add_argument("--workers", type=int, default=1, help="worker processes (default 1)")
    r.add_argument(
        "--scheduler",
        help="dask scheduler address tcp://HOST:PORT (default: a LocalCluster started for the run)",
    )
    r.add_argument(
        "--overwrite",
        action="store_true",
        help="replace results of a different config or code version (only results "
        "directories the suite wrote are ever replaced)",
    )
    r.add_argument(
        "--max-memory-gb",
        type=float,
        default=None,
        help="refuse a run whose estimated memory exceeds this (env SIM_MAX_MEMORY_GB)",
    )
    r.add_argument(
        "--max-adjustments",
        type=float,
        default=None,
        help="refuse a run with more least-squares adjustments than this (env SIM_MAX_ADJUSTMENTS)",
    )
    c = sub.add_parser("check", help="validate a study file and print the resolved config")
    c.add_argument("study")
    c.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    rep = sub.add_parser("report", help="rebuild results/REPORT.md from the Parquet files")
    rep.add_argument("--results", default="results")
    return p


_SCHEDULER = re.compile(
    r"^(?:(?:tcp|tls|ucx|ws|wss)://)?(?:\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+)"
    r":(\d{1,5})/?$"
)


def _check_args(args) -> Path:
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
        if "\0" in args.out:
            raise ConfigError("--out", "contains a NUL character")
    return Path(os.path.abspath(args.out)) if args.out else None


def _run(args) -> int:
    out = _check_args(args)
    study, cfg = load_study(args.study, args.set, args.trials, args.seed)
    shown = args.out if args.out else str(Path("results") / cfg["study"])
    sweep = read_sweep(args.study, study.schema)  # a [sweep] table: run every cell
    execute(
        study,
        cfg,
        sweep,
        out or Path(os.path.abspath(shown)),
        shown,
        executor=args.executor,
        workers=args.workers,
        scheduler=args.scheduler,
        overwrite=args.overwrite,
        quiet=args.quiet,
        max_memory_gb=args.max_memory_gb,
        max_adjustments=args.max_adjustments,
    )
    print(f"{cfg['study']}: results in {shown}/")
    return 0


def _on_sigterm(signum, frame):
    raise KeyboardInterrupt


def main(argv: list[str] | None = None) -> int:
    try:
        args = _parser().parse_args(argv)
        if args.cmd == "run":
            if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
                signal.signal(signal.SIGTERM, _on_sigterm)  # clean up like Ctrl-C
            return _run(args)
        if args.cmd == "check":
            _, cfg = load_study(args.study, args.set)
            for k, v in cfg.items():
                print(f"{k} = {v!r}")
            return 0
        if args.cmd == "report":
            print(write_report(Path(args.results), get_study))
            return 0
    except (ConfigError, StudyError) as e:
        print(f"sim: error: {e}".splitlines()[0], file=sys.stderr)
        return INTERNAL if getattr(e, "internal", False) else 2
    except KeyboardInterrupt:
        print(
            "sim: interrupted; run the same command again to finish the missing chunks",
            file=sys.stderr,
        )
        return 130
    except OSError as e:  # a failing write (full disk, vanished directory): one line, no traceback
        print(
            f"sim: error: {e.strerror or e}: {getattr(e, 'filename', '') or ''}".rstrip(": "),
            file=sys.stderr,
        )
        return 2
    except (ArithmeticError, ValueError, MemoryError) as e:  # e.g. a sweep cell table
        print(f"sim: error: {type(e).__name__}: {e}".splitlines()[0], file=sys.stderr)
        return 2
    return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
