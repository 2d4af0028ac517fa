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

from benchmarks.cli import main
from benchmarks.timing import cpu_time, numpy_path

__all__ = ["main", "cpu_time", "numpy_path"]
