"""``python -m benchmarks``: the benchmark's command line (:mod:`benchmarks.cli`)."""

from benchmarks.cli import main
from sim.ends import finish

raise SystemExit(finish("benchmarks", main))  # its standard output flushed: sim.ends
