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
import shutil
import signal
import sys
from pathlib import Path

from sim.mc.config import ConfigError, StudyError, check_chunks, load_study

__all__ = ["main", "execute"]

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


def _check_out(out: Path, shown: str, record: dict, overwrite: bool) -> None:
    """Refuse an output path the suite did not write (with or without ``--overwrite``) and,
    without ``--overwrite``, results of a different config or code version."""
    from sim.mc.storage import read_record

    if not out.name or out == out.parent:
        raise ConfigError("--out", f"{shown} is not a directory the suite can write into")
    if out.is_symlink():
        raise ConfigError("--out", f"{shown} is a symbolic link; sim never replaces it")
    if not out.exists():
        return
    if not out.is_dir():
        raise ConfigError(
            "--out",
            f"{shown} is a file, not a results directory; sim never "
            "replaces it (choose another --out)",
        )
    old = read_record(out)
    if old is None:
        if any(out.iterdir()):
            raise ConfigError(
                "--out",
                f"{shown} holds files but no sim run record (run.json); "
                "sim never replaces it, with or without --overwrite",
            )
        return
    if _same(old, record) or overwrite:
        return
    why = (
        "a different config"
        if old.get("config") != record["config"]
        else "a different code version"
    )
    raise ConfigError("--out", f"{shown} holds results of {why}; use --overwrite to replace it")


def _same(a: dict | None, b: dict) -> bool:
    return bool(a) and a.get("config") == b["config"] and a.get("code_hash") == b["code_hash"]


def _clear(stage: Path) -> None:
    """Remove everything in a staging directory we hold the lock of, but the lock file."""
    from sim.mc.storage import LOCK

    for p in stage.iterdir():
        if p.name == LOCK:
            continue
        if p.is_dir() and not p.is_symlink():
            shutil.rmtree(p)
        else:
            p.unlink()


def _chunks(stage: Path) -> int:
    t = stage / "trials"
    return sum(1 for _ in t.rglob("chunk-*.parquet")) if t.is_dir() else 0


def _prepare_stage(stage: Path, out: Path, shown: str, record: dict, overwrite: bool):
    """Lock the staging directory and make it hold ``record``. Returns ``(lock, resumed)``."""
    from sim.mc.storage import LOCK, Locked, StageLock, read_record, write_record

    if stage.is_symlink() or (stage.exists() and not stage.is_dir()):
        raise ConfigError(
            "--out",
            f"{stage} is in the way (not a staging directory of sim); sim never replaces it",
        )
    if (
        stage.is_dir()
        and read_record(stage) is None
        and not (stage / LOCK).exists()
        and any(stage.iterdir())
    ):
        raise ConfigError(
            "--out", f"{stage} holds files but no sim run record; sim never replaces it"
        )
    lock = StageLock(stage)
    try:
        lock.acquire()
    except Locked as e:
        who = f"pid {e.pid}" if e.pid else "another process"
        raise ConfigError(
            "--out",
            f"{shown} is being written by a running sim ({who}); wait "
            "for it to finish or choose another --out",
        ) from None
    except OSError as e:
        raise ConfigError("--out", f"cannot write to {out.parent}: {e.strerror}") from None
    try:
        old = read_record(stage)
        resumed = 0
        if old is not None and _same(old, record) and not old.get("failed"):
            resumed = _chunks(stage)
        elif old is not None and _same(old, record):
            resumed = _chunks(stage)  # a failed run of the same command: try again, resume
        elif old is None or old.get("failed") or overwrite:
            _clear(stage)  # ours (locked, a record or a lock file), and not resumable
        else:
            why = (
                "a different config"
                if old.get("config") != record["config"]
                else "a different code version"
            )
            raise ConfigError(
                "--out",
                f"{stage} holds an unfinished run of {why}; run that "
                "command again to finish it, or use --overwrite to replace it",
            )
        for tmp in stage.rglob("*.tmp"):  # a write cut short by a kill
            tmp.unlink(missing_ok=True)
        write_record(stage, record)
    except BaseException:
        _drop_stage(stage, lock)
        raise
    return lock, resumed


def _drop_stage(stage: Path, lock, reason: str | None = None) -> None:
    """After a failure: remove a staging directory with no finished chunk; otherwise mark it
    failed (so the corrected command may replace it) and keep it for resumption."""
    from sim.mc.storage import read_record, write_record

    try:
        if _chunks(stage) == 0:
            shutil.rmtree(stage, ignore_errors=True)
        elif reason is not None and (rec := read_record(stage)) is not None:
            write_record(stage, {**rec, "failed": reason})
    finally:
        lock.release()


def _numeric_failure(e: BaseException, study, cfg: dict) -> StudyError:
    """One line for an exception raised inside a study's run: the study part (the innermost
    frame in study code) and, where the message says which, the config key to change."""
    import traceback

    frames = [
        f
        for f in traceback.extract_tb(e.__traceback__)
        if "/sim/" in f.filename.replace(os.sep, "/")
    ]
    plumbing = ("runner.py", "cli.py", "storage.py", "sweep.py", "claims.py")
    study_code = [f for f in frames if "/sim/studies/" in f.filename.replace(os.sep, "/")]
    model = [f for f in frames if not f.filename.replace(os.sep, "/").endswith(plumbing)]
    part = None
    for f in (study_code or model)[-1:]:
        mod = f.filename.replace(os.sep, "/").rsplit("/sim/", 1)[1][:-3].replace("/", ".")
        part = f"sim.{mod}.{f.name}"
    msg = (str(e).strip().splitlines() or [""])[0][:300]
    hint = _hint(msg, type(e).__name__, study.schema)
    where = f" in {part}" if part else ""
    return StudyError(f"{cfg['study']}: the run failed{where}: {type(e).__name__}: {msg}{hint}")


_HINTS = (  # message words -> config keys (the first that the study has is named)
    (("iteration", "converge"), ("solver.max_iter", "solver.tol_mm")),
    (("overflow",), ("errors.setting_sigma_um", "plate.format_mm")),
    (("svd", "singular", "degenerate", "collinear"), ("plate.grid", "plate.points", "marks.grid")),
)


def _hint(msg: str, kind: str, schema) -> str:
    low = (msg + " " + kind).lower()
    for words, keys in _HINTS:
        if any(w in low for w in words):
            have = [k for k in keys if k in schema]
            if have:
                return f" (check {have[0]})"
    if "memory" in low:
        return " (reduce trials, chunk or the sizes in the study file)"
    return ""


def _run(args) -> int:
    from sim.mc.sweep import read_sweep

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


def execute(
    study,
    cfg: dict,
    sweep: dict,
    out: Path,
    shown: str | None = None,
    *,
    executor: str = "local",
    workers: int = 1,
    scheduler: str | None = None,
    overwrite: bool = False,
    quiet: bool = False,
    max_memory_gb: float | None = None,
    max_adjustments: float | None = None,
):
    """Run a validated study config (and its sweep) into ``out`` (absolute): estimate and
    limits, output checks, executor, locked staging directory, the run, and the final
    replacement of ``out``. Raises ConfigError/StudyError (one line) on any failure.
    Returns the run's :class:`sim.mc.estimate.Estimate`."""
    from sim.mc.estimate import check_limits, estimate
    from sim.mc.runner import ChunkStore, make_executor
    from sim.mc.storage import code_hash, provenance, versions
    from sim.mc.sweep import run_sweep
    from sim.studies import RunContext

    shown = shown or str(out)
    check_chunks(cfg)
    est = estimate(cfg, sweep)
    check_limits(est, max_memory_gb, max_adjustments, workers)
    record = {
        "config": {**cfg, "sweep": sweep} if sweep else cfg,
        "code_hash": code_hash(cfg["study"]),
        "versions": versions(),
    }
    _check_out(out, shown, record, overwrite)
    stage = out.parent / f".{out.name}.partial"
    try:
        ex = make_executor(executor, workers, scheduler)
    except (RuntimeError, OSError, TimeoutError, ValueError, TypeError) as e:
        key = "--scheduler" if scheduler else "--executor"
        msg = (str(e).strip().splitlines() or [type(e).__name__])[0]
        raise ConfigError(key, f"cannot start the {executor} executor: {msg}") from None
    lock = None
    try:
        lock, resumed = _prepare_stage(stage, out, shown, record, overwrite)
        if resumed:
            print(f"sim: resuming {cfg['study']}: {resumed} finished chunks found", file=sys.stderr)
        ctx = RunContext(
            quiet=quiet,
            executor=ex,
            store=ChunkStore(stage / "trials", provenance(cfg)),
            estimate=est,
        )
        try:
            with ctx.progress_bar(cfg["study"]):
                run_sweep(study, cfg, sweep, stage, ctx) if sweep else study.run(cfg, stage, ctx)
        except (ConfigError, StudyError):
            raise
        except (ArithmeticError, ValueError, MemoryError) as e:  # numbers the model cannot take
            raise _numeric_failure(e, study, cfg) from None
        except (OSError, KeyboardInterrupt, SystemExit):
            raise
        except Exception as e:  # noqa: BLE001 - a bug: one line, the traceback on request
            if os.environ.get("SIM_DEBUG"):
                raise
            err = _numeric_failure(e, study, cfg)
            err.internal = True
            raise err from None
    except BaseException as e:
        ex.close(kill=True)
        if lock is not None:  # a failure of the run (not an interrupt) is marked replaceable
            failed = isinstance(e, (ConfigError, StudyError))
            _drop_stage(stage, lock, reason=str(e) if failed else None)
        raise
    ex.close()
    try:
        _check_out(out, shown, record, True)  # again, under the lock: still ours or absent
        _publish(stage, out)
    except BaseException:
        _drop_stage(stage, lock)
        raise
    lock.release()
    return est


def _publish(stage: Path, out: Path) -> None:
    """Replace ``out`` (checked: ours or absent) by the finished staging directory."""
    from sim.mc.storage import LOCK

    for tmp in stage.rglob("*.tmp"):
        tmp.unlink(missing_ok=True)
    old = out.parent / f".{out.name}.old.{os.getpid()}"
    if out.exists():
        os.replace(out, old)
    os.replace(stage, out)
    (out / LOCK).unlink(missing_ok=True)  # we still hold it through the open descriptor
    shutil.rmtree(old, ignore_errors=True)


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
            from sim.report.markdown import write_report

            print(write_report(Path(args.results)))
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
