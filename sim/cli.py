"""Command line: ``sim run STUDY.toml``, ``sim check STUDY.toml``, ``sim report``.

Bad input (a bad study file, a bad override, an unwritable output directory) gives one
line on standard error naming the problem and exit code 2, with no partial result left.
"""
from __future__ import annotations

import argparse
import os
import shutil
import sys
from pathlib import Path

from .config import ConfigError, load_study

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
    c = sub.add_parser("check", help="validate a study file and print the resolved config")
    c.add_argument("study")
    c.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    rep = sub.add_parser("report", help="rebuild results/REPORT.md from the Parquet files")
    rep.add_argument("--results", default="results")
    return p


def _run(args) -> int:
    from .studies import RunContext

    study, cfg = load_study(args.study, args.set, args.trials, args.seed)
    out = Path(args.out) if args.out else Path("results") / cfg["study"]
    stage = out.parent / f".{out.name}.partial"
    try:
        if stage.exists():
            shutil.rmtree(stage)
        stage.mkdir(parents=True)
    except OSError as e:
        raise ConfigError("--out", f"cannot write to {out.parent}: {e.strerror}") from None
    try:
        study.run(cfg, stage, RunContext(quiet=args.quiet))
        old = out.parent / f".{out.name}.old"
        if old.exists():
            shutil.rmtree(old)
        if out.exists():
            os.replace(out, old)
        os.replace(stage, out)
        shutil.rmtree(old, ignore_errors=True)
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
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
    except ConfigError as e:
        print(f"sim: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("sim: interrupted", file=sys.stderr)
        return 130
    return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
