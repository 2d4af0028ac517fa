"""``python -m sim.bench``: the benchmark's command line (:mod:`sim.bench.cli`)."""
from .cli import main

raise SystemExit(main())
