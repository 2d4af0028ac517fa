"""The benchmark (``make bench``, ``python -m benchmarks --out results/bench``).

Three tables under the output directory, each with a figure:

* ``bench.parquet``, ``bench.png`` (:mod:`benchmarks.brown`): Brown's batched multilateration
  against a per-trial ``scipy.optimize.least_squares`` loop, its cost against the number of
  points, the executors, and the peak memory of a million-trial streamed run.
* ``engines.parquet``, ``engines.png`` (:mod:`benchmarks.engines`,
  :mod:`benchmarks.engines_linear`): each adjustment on the engine of :mod:`sim.lsq`
  (P-position design cell, two-grid-plate combined adjustment, independent-model block,
  Wolf's polynomial calibration) against a per-trial SciPy loop of the same adjustment on the
  same observations; both sides must agree before anything is timed.
* ``rerun.parquet`` (:mod:`benchmarks.rerun`, drawn in ``engines.png``): the wall time of
  every study file run as ``make rerun`` runs it, with 1 and 2 workers, against the 90 s target.

The command line is :mod:`benchmarks.cli`. Nothing here is study code (:mod:`sim.mc.codehash`).
"""

from __future__ import annotations

import sys

from sim.env_vars import refuse_bad_variables
from sim.threads import refuse_bad_environment

if sys.argv[:1] == ["-m"]:  # python -m benchmarks, while this package loads (as sim.report.verify)
    refuse_bad_environment("benchmarks")  # a variable NumPy cannot load with: one line, exit 2
    refuse_bad_variables("benchmarks")  # SIM_NO_JIT=0 (timed the Python path), exit 2 too
else:  # imported from Python (benchmarks.main([...])): a sim.ConfigError naming the variable
    import sim.entry_env  # noqa: F401

from benchmarks.cli import main  # noqa: E402
from benchmarks.timing import cpu_time, numpy_path  # noqa: E402

__all__ = ["main", "cpu_time", "numpy_path"]
