"""``python -m benchmarks``: the benchmark's command line (:mod:`benchmarks.cli`)."""

from benchmarks.cli import main
from sim.stops import flush_stdout


def _program() -> int:
    """:func:`main`, its standard output flushed while a failure can still be said in one
    line (``> /dev/full`` was Python's "Exception ignored" at exit and exit 120)."""
    try:
        code = main()
    except SystemExit as e:  # --help, a bad argument: their code stands as well
        if not (e.code is None or isinstance(e.code, int)):
            raise
        code = e.code or 0
    return flush_stdout("benchmarks", code)


raise SystemExit(_program())
