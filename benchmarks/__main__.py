"""``python -m benchmarks``: the benchmark's command line (:mod:`benchmarks.cli`)."""

from sim.ends import finish, open_standard_streams

open_standard_streams()  # 2>&-: before any file takes its descriptor

from benchmarks.cli import main  # noqa: E402

raise SystemExit(finish("benchmarks", main))  # its standard output flushed: sim.ends
