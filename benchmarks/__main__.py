"""``python -m benchmarks``: the benchmark's command line (:mod:`benchmarks.cli`)."""

from benchmarks.cli import main

raise SystemExit(main())
