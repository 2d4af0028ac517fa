"""``sim run STUDY.toml`` (:mod:`sim.cli` imports it when the command runs): the options a
run needs (:func:`check_run_args`) and the run itself, of the study and config they resolve
(:func:`sim.cli_load.load_run`, which ``sim check`` and ``python -m sim.batch`` use too)."""

from __future__ import annotations

import sim.entry_env  # noqa: F401 - imported from Python: the environment, before tqdm loads

# isort: split
import os
import re
from pathlib import Path

from tqdm import tqdm  # noqa: F401 - loaded with the command: a shadowing tqdm.py is named

from sim.cli_load import load_run
from sim.ends import unshown
from sim.execute import execute
from sim.mc.config import ConfigError
from sim.mc.overrides import as_read, command_values, listed, recorded
from sim.mc.path_names import name_problem
from sim.mc.paths import absolute
from sim.mc.sweep import read_sweep
from sim.path_args import arrow_name, too_long
from sim.places import default_out
from sim.report.run_summary import terminal_summary, write_run_readme
from sim.stops import check_interrupt
from sim.studies import design_config, get_study

__all__ = ["check_run_args", "load_run", "run"]  # load_run: sim.cli_load's, for its callers

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
        if why := too_long(args.out):  # it was the system's words and the whole path, of 6 kB
            raise ConfigError("--out", why)  # (a name over 255 bytes: named with the suffix)
    return absolute(args.out) if args.out else None


def run(args) -> int:
    """``sim run STUDY.toml``: run the study, write its results directory, print its verdicts."""
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
