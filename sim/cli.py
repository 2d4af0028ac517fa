"""Command line: ``sim run STUDY.toml``, ``sim check STUDY.toml``, ``sim report``.

Bad input (a bad study file, a bad override, an unwritable output directory) gives one
line on standard error naming the problem and exit code 2, with no partial result left.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
from pathlib import Path

from .config import ConfigError, StudyError, load_study

__all__ = ["main"]


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="sim", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run a study and write its results directory")
    r.add_argument("study", help="study file, e.g. studies/brown_dilution.toml")
    r.add_argument("--out", help="output directory (default results/<study>)")
    r.add_argument("--trials", type=int, help="override the number of Monte-Carlo trials")
    r.add_argument("--seed", type=int, help="override the root seed")
    r.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override any config key with its dotted name (repeatable)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.add_argument("--executor", choices=("local", "dask"), default="local",
                   help="local (in-process, or a process pool with --workers) or dask")
    r.add_argument("--workers", type=int, default=1, help="worker processes (default 1)")
    r.add_argument("--scheduler", help="dask scheduler address tcp://HOST:PORT (default: a "
                   "LocalCluster started for the run)")
    r.add_argument("--overwrite", action="store_true",
                   help="replace results of a different config or code version")
    c = sub.add_parser("check", help="validate a study file and print the resolved config")
    c.add_argument("study")
    c.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    rep = sub.add_parser("report", help="rebuild results/REPORT.md from the Parquet files")
    rep.add_argument("--results", default="results")
    return p


def _run_record(cfg: dict) -> dict:
    from .storage import code_hash

    return {"config": cfg, "code_hash": code_hash(cfg["study"])}


def _read_record(d: Path) -> dict | None:
    try:
        return json.loads((d / "run.json").read_text())
    except (OSError, ValueError):
        return None


def _run(args) -> int:
    from .runner import ChunkStore, make_executor
    from .storage import provenance
    from .studies import RunContext

    study, cfg = load_study(args.study, args.set, args.trials, args.seed)
    if args.workers < 1:
        raise ConfigError("--workers", f"must be >= 1 (got {args.workers})")
    out = Path(args.out) if args.out else Path("results") / cfg["study"]
    stage = out.parent / f".{out.name}.partial"
    from .sweep import read_sweep, run_sweep
    sweep = read_sweep(args.study, study.schema)  # a [sweep] table: run every cell
    record = _run_record({**cfg, "sweep": sweep} if sweep else cfg)
    for d, what in ((out, "results"), (stage, "an unfinished run")):
        old = _read_record(d) if d.exists() else None
        if d.exists() and old != record and not args.overwrite:
            why = ("no run record" if old is None else "a different config" if
                   old.get("config") != cfg else "a different code version")
            raise ConfigError("--out", f"{d} holds {what} of {why}; use --overwrite to replace it")
    try:
        if stage.exists() and _read_record(stage) != record:
            shutil.rmtree(stage)
        stage.mkdir(parents=True, exist_ok=True)
        (stage / "run.json").write_text(json.dumps(record, sort_keys=True, indent=1))
    except OSError as e:
        raise ConfigError("--out", f"cannot write to {out.parent}: {e.strerror}") from None
    resumed = len(list((stage / "trials").rglob("chunk-*.parquet"))) if (stage / "trials").exists() else 0
    if resumed:
        print(f"sim: resuming {cfg['study']}: {resumed} finished chunks found", file=sys.stderr)
    try:
        executor = make_executor(args.executor, args.workers, args.scheduler)
    except RuntimeError as e:
        raise ConfigError("--executor", str(e)) from None
    try:
        ctx = RunContext(quiet=args.quiet, executor=executor, store=ChunkStore(stage / "trials", provenance(cfg)))
        run_sweep(study, cfg, sweep, stage, ctx) if sweep else study.run(cfg, stage, ctx)
    finally:
        executor.close()
    # only a complete run replaces the output directory
    old = out.parent / f".{out.name}.old"
    if old.exists():
        shutil.rmtree(old)
    if out.exists():
        os.replace(out, old)
    os.replace(stage, out)
    shutil.rmtree(old, ignore_errors=True)
    print(f"{cfg['study']}: results in {out}/")
    return 0


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        if args.cmd == "run":
            return _run(args)
        if args.cmd == "check":
            _, cfg = load_study(args.study, args.set)
            for k, v in cfg.items():
                print(f"{k} = {v!r}")
            return 0
        if args.cmd == "report":
            from .report import write_report

            print(write_report(Path(args.results)))
            return 0
    except (ConfigError, StudyError) as e:
        print(f"sim: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("sim: interrupted; run the same command again to finish the missing chunks",
              file=sys.stderr)
        return 130
    except OSError as e:  # a failing write (full disk, vanished directory): one line, no traceback
        print(f"sim: error: {e.strerror or e}: {getattr(e, 'filename', '') or ''}".rstrip(": "),
              file=sys.stderr)
        return 2
    return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
