"""Command line of the benchmark: ``python -m benchmarks --out results/bench`` (``make bench``).

Sections (``--only``, default all): ``brown`` (``bench.parquet``, ``bench.png``:
:mod:`benchmarks.brown`), ``engines`` (``engines.parquet``: :mod:`benchmarks.engines`),
``studies`` (``studies.parquet``: :mod:`benchmarks.studies`) and ``rerun``
(``rerun.parquet``: :mod:`benchmarks.rerun`; ``--no-rerun`` leaves it out), engines and rerun
drawn in ``engines.png``; ``README.md`` (:mod:`benchmarks.page`) names each compiled module and
the row that keeps it; ``scaling`` (``scaling.parquet``, ``scaling.png``: the sparse path
from 100 to 10,000 points and blocks of 10 to 200 models, :mod:`benchmarks.scaling`); ``store``
(``store.parquet``: a chunk's kept arrays saved and loaded packed against ``.npz``,
:mod:`benchmarks.store`); ``startup`` (``startup.parquet``: the CPU time of a command before
it does its work, ``sim --version`` and a refused ``sim check`` against 0.45 s,
:mod:`benchmarks.startup`). ``--quick`` is a smoke run: small sizes, and the rerun rows with
the test suite's tiny configuration of each study (``tests/data/tiny/<study>.txt``), so its
rerun times say nothing about the 90 s target; without ``--out`` it writes
``scratch/bench-quick`` (:data:`QUICK_OUT`), and a directory holding a full benchmark's tables
(the committed ``results/bench``) is refused to it, naming ``--out``: a smoke run replaced the
committed measurements.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

from benchmarks import studies
from benchmarks.brown import brown_rows, million, peak_rss_mib
from benchmarks.engines import engine_rows
from benchmarks.figures import brown_figure, engines_figure
from benchmarks.outdir import OutLock, full_measurement, not_written_here
from benchmarks.page import write_page
from benchmarks.rerun import rerun_rows, study_files
from benchmarks.scaling import gama_local, scaling_figure, scaling_rows
from benchmarks.startup import startup_rows
from benchmarks.store import store_rows
from sim.env_vars import environment_problem
from sim.mc.argv import ONCE, OnceParser
from sim.mc.storage import provenance, write_table
from sim.places import base, shown_path
from sim.stops import ended_as_ctrl_c

__all__ = ["main", "run"]

SECTIONS = ("brown", "engines", "studies", "rerun", "scaling", "store", "startup")
TINY = Path(__file__).resolve().parent.parent / "tests" / "data" / "tiny"


def tiny_overrides(study_file: Path) -> tuple[str, ...]:
    """``--set`` arguments of the test suite's tiny configuration of a study file's study."""
    study = tomllib.loads(study_file.read_text()).get("study")
    f = TINY / f"{study}.txt"
    if not f.is_file():
        raise FileNotFoundError(f"bench --quick: no tiny configuration {f} for {study_file}")
    lines = [ln.strip() for ln in f.read_text().splitlines()]
    return tuple(a for ln in lines if ln and not ln.startswith("#") for a in ("--set", ln))


def run(
    out: Path,
    quick: bool = False,
    sections=SECTIONS,
    rerun_files: str = "studies/*.toml",
    rerun_workers=(1, 2),
) -> dict[str, dict]:
    """Measure ``sections`` and write their tables and figures under ``out``; returns the
    tables' columns by file name."""
    prov = {"study": "bench", "seed": 1, "quick": quick}
    tables: dict[str, dict] = {}
    if "brown" in sections:
        rows, extra = brown_rows(out, quick)
        write_table(out / "bench.parquet", rows, provenance(prov, **extra))
        brown_figure(rows, out / "bench.png", extra["solutions_agree_mm"])
        tables["bench.parquet"] = rows
    if "engines" in sections:
        tables["engines.parquet"] = engine_rows(quick)
        write_table(out / "engines.parquet", tables["engines.parquet"], provenance(prov))
    if "studies" in sections:
        files = [Path("studies") / f"{s}.toml" for s in studies.STUDIES]
        extra = {f.stem: tiny_overrides(f) for f in files} if quick else {}
        tables["studies.parquet"] = studies.study_rows(files, extra)
        write_table(out / "studies.parquet", tables["studies.parquet"], provenance(prov))
    if "engines" in sections or "studies" in sections:
        write_page(
            out / "README.md",
            tables.get("engines.parquet"),
            tables.get("studies.parquet"),
            quick,
        )
    if "rerun" in sections:
        files = study_files(rerun_files)
        extra = {f.stem: tiny_overrides(f) for f in files} if quick else {}
        tables["rerun.parquet"] = rerun_rows(files, rerun_workers, extra)
        write_table(
            out / "rerun.parquet",
            tables["rerun.parquet"],
            provenance(prov, files=[f.as_posix() for f in files], tiny_configurations=quick),
        )
    if "scaling" in sections:
        t0 = time.perf_counter()
        tables["scaling.parquet"] = scaling_rows(quick)
        write_table(
            out / "scaling.parquet",
            tables["scaling.parquet"],
            provenance(prov, gama_local=gama_local() or ""),
        )
        scaling_figure(tables["scaling.parquet"], out / "scaling.png")
        print(f"benchmarks: scaling took {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    if "store" in sections:
        tables["store.parquet"] = store_rows(quick)
        write_table(out / "store.parquet", tables["store.parquet"], provenance(prov))
    if "startup" in sections:
        tables["startup.parquet"] = startup_rows(quick)
        write_table(out / "startup.parquet", tables["startup.parquet"], provenance(prov))
    if "engines" in sections or "rerun" in sections:
        engines_figure(
            tables.get("engines.parquet"), tables.get("rerun.parquet"), out / "engines.png"
        )
    return tables


def _csv(kind, choices=None):
    def parse(text: str):
        items = [s.strip() for s in text.split(",") if s.strip()]
        try:
            vals = [kind(s) for s in items]
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"not a comma-separated list of {kind.__name__}: {text!r}"
            )
        bad = [
            v
            for v in vals
            if (choices is not None and v not in choices) or (kind is int and not 1 <= v <= 64)
        ]
        if not vals or bad:
            raise argparse.ArgumentTypeError(
                f"{text!r}: expected a comma-separated subset of "
                f"{', '.join(choices) if choices else '1 ... 64'}"
            )
        twice = sorted({str(v) for v in vals if vals.count(v) > 1})
        if twice:  # --rerun-workers 1,1 timed one setting twice: two rows of one key
            raise argparse.ArgumentTypeError(
                f"{text!r}: {', '.join(twice)} given twice: give each once"
            )
        return tuple(vals)

    return parse


class _ArgError(Exception):
    """A bad argument, found before anything is measured (one line, exit 2)."""


class _Parser(OnceParser):
    """argparse with the suite's one-line errors (``sim``'s style), exit 2; ``--out``,
    ``--only``, ``--rerun-files`` and ``--rerun-workers`` given once (a second one was taken
    and the first dropped without a word: ``--out A --out B`` wrote into B alone)."""

    once = ONCE | {"--only", "--rerun-files", "--rerun-workers"}

    def refuse(self, message: str):
        print(f"benchmarks: error: {message} (see {self.prog} --help)", file=sys.stderr)
        raise SystemExit(2)


def _check_args(a: argparse.Namespace, sections: tuple[str, ...]) -> None:
    """Refuse, before anything is measured, what would fail after minutes of work or be
    ignored: nothing to measure, rerun options without the rerun section, an --out that is
    empty, not a directory, a study's results directory or cannot be written, and rerun files
    that are not readable TOML study files."""
    if not sections:
        raise _ArgError("--only/--no-rerun: nothing to measure (the only section is left out)")
    if "rerun" not in sections:
        given = [
            n
            for n, v in (("--rerun-files", a.rerun_files), ("--rerun-workers", a.rerun_workers))
            if v is not None
        ]
        if given:
            raise _ArgError(f"{given[0]}: the rerun section is not measured (--only/--no-rerun)")
    if not a.out.strip():
        raise _ArgError("--out: is empty (give a directory)")
    out = Path(a.out)
    if out.exists() and not out.is_dir():
        raise _ArgError(f"--out: {out} exists and is not a directory")
    if any((out / f).exists() for f in ("claims.parquet", "sweep.parquet", "run.json")):
        raise _ArgError(f"--out: {out} is a study's results directory (give another)")
    if out.is_dir() and next(out.glob("*/claims.parquet"), None) is not None:
        raise _ArgError(f"--out: {out} holds studies' results directories (give {out / 'bench'})")
    foreign = not_written_here(out)
    if foreign:
        raise _ArgError(
            f"--out: {out / foreign} was not written by the benchmark, which would replace it"
            " (give a new directory, or one make bench wrote)"
        )
    if a.quick and (full := full_measurement(out)) is not None:
        raise _ArgError(
            f"--out: {out} holds the measurements of a full benchmark ({full}), which a smoke "
            "run (--quick) would replace: give another --out (make bench: BENCH_OUT=DIR)"
        )
    base = next(p for p in (out.absolute(), *out.absolute().parents) if p.exists())
    if not base.is_dir() or not os.access(base, os.W_OK | os.X_OK):
        raise _ArgError(f"--out: cannot write {out} ({base} is not a writable directory)")
    if "rerun" in sections:
        if a.rerun_files is not None and not a.rerun_files.strip():
            raise _ArgError("--rerun-files: is empty (give a glob, e.g. studies/*.toml)")
        for f in study_files(a.rerun_files or _ours("studies/*.toml")):
            try:
                study = tomllib.loads(f.read_text()).get("study") if f.is_file() else None
            except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
                raise _ArgError(f"--rerun-files: {f}: not a readable TOML file ({e})") from None
            if not isinstance(study, str):
                raise _ArgError(f"--rerun-files: {f} is not a study file (no study = ...)")


#: where a smoke run (``--quick``) writes without ``--out``: the committed ``results/bench``
#: holds a full benchmark's measurements (:func:`benchmarks.outdir.full_measurement`)
QUICK_OUT = "scratch/bench-quick"

#: the benchmark's line when it was interrupted
INTERRUPTED = "benchmarks: interrupted; nothing more was measured"


def _ours(path: str) -> str:
    """A default path of the project's: from a directory inside it, its root's (:func:`sim.
    places.base`: from ``docs/`` the benchmark wrote ``docs/scratch/bench-quick`` and found
    no ``studies/*.toml``)."""
    return shown_path(base() / path)


def main(argv=None) -> int:
    """The benchmark; SIGTERM and SIGHUP end it as Ctrl-C does (its child processes stopped:
    SIGTERM ended it at once, exit 143 without a word, and left its million-trial run
    writing into ``--out``): one line, exit 130. Called from Python, it refuses what ``python
    -m benchmarks`` refuses as it starts (``SIM_NO_JIT=0`` timed the Python path): one line,
    exit 2."""
    if (problem := environment_problem()) is not None:
        print(f"benchmarks: error: {problem}", file=sys.stderr)
        return 2
    try:
        with ended_as_ctrl_c():
            return _main(argv)
    except KeyboardInterrupt:
        print(INTERRUPTED, file=sys.stderr)
        return 130


def _main(argv) -> int:
    ap = _Parser(
        prog="python -m benchmarks",
        description="Benchmark of the batched solvers and of make rerun (see docs/benchmark.md)",
    )
    ap.add_argument(
        "--out",
        help=f"output directory (default results/bench; with --quick {QUICK_OUT})",
    )
    ap.add_argument(
        "--quick",
        action="store_true",
        help="small sizes and tiny study configurations (a smoke run)",
    )
    ap.add_argument(
        "--only",
        type=_csv(str, SECTIONS),
        default=SECTIONS,
        help=f"comma-separated sections to measure ({', '.join(SECTIONS)}; default all)",
    )
    ap.add_argument(
        "--rerun",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="time every study file run as make rerun runs it, with 1 and 2 workers "
        "(--no-rerun: leave it out)",
    )
    ap.add_argument(
        "--rerun-files",
        default=None,
        help="study files of the rerun rows (default studies/*.toml)",
    )
    ap.add_argument(
        "--rerun-workers",
        type=_csv(int),
        default=None,
        help="worker counts of the rerun rows (default 1,2)",
    )
    ap.add_argument("--million-child", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--chunk", type=int, default=10000, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    # the project's results/ and studies/ from a directory inside it (docs/), as sim run's
    a.out = a.out if a.out is not None else _ours(QUICK_OUT if a.quick else "results/bench")
    if a.million_child:
        try:
            million(Path(a.out), a.million_child, a.chunk)
        except OSError as e:  # its parent names it (benchmarks.brown.peak_memory)
            where = f": {e.filename}" if e.filename else ""
            print(f"benchmarks: error: {e.strerror or e}{where}".splitlines()[0], file=sys.stderr)
            return 2
        print(f"{peak_rss_mib():.1f}")
        return 0
    sections = tuple(s for s in a.only if a.rerun or s != "rerun")
    try:
        _check_args(a, sections)
        with OutLock(Path(a.out)):  # a second benchmark into --out stops at once
            tables = run(
                Path(a.out),
                a.quick,
                sections,
                a.rerun_files or _ours("studies/*.toml"),
                a.rerun_workers or (1, 2),
            )
    except (FileNotFoundError, RuntimeError, _ArgError) as e:
        print(f"benchmarks: error: {e}".splitlines()[0], file=sys.stderr)
        return 2
    except OSError as e:  # a failing write (a full disk, ulimit -f): one line, no traceback
        print(f"benchmarks: error: writing under {a.out}: {e}".splitlines()[0], file=sys.stderr)
        return 2
    if "bench.parquet" in tables:
        b = tables["bench.parquet"]
        case, tps = np.array(b["case"]), np.array(b["trials_per_s"])
        print(
            f"speed-up over the scipy loop: {tps[case == 'batched'][0] / tps[case == 'scipy_loop'][0]:.0f}x"
        )
    return 0
