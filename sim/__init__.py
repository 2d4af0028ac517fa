"""sim: Monte-Carlo reproduction of classic comparator and plotter calibration papers.

The public surface: ``sim.load(study_file, **overrides).run()`` (:mod:`sim.api`), the Brown
multilateration kernels, and the claims and storage helpers every study uses. Everything
else is internal.

The suite parallelises over chunks of trials (processes, ``--workers``); a multi-threaded
BLAS inside each process would oversubscribe the cores and make the small batched solves
several times slower, so BLAS runs single-threaded unless the environment says otherwise.
"""

import os as _os

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    _os.environ.setdefault(_v, "1")
from sim.api import Results, StudyHandle, load  # noqa: E402
from sim.mc.config import ConfigError, StudyError, load_study  # noqa: E402
from sim.mc.runner import run_chunks  # noqa: E402
from sim.mc.storage import read_provenance, write_table  # noqa: E402

__all__ = [
    "load",
    "StudyHandle",
    "Results",
    "ConfigError",
    "StudyError",
    "load_study",
    "run_chunks",
    "adjust",
    "covariance",
    "design_theta",
    "ranges",
    "simulate_ranges",
    "write_table",
    "read_provenance",
]
__version__ = "0.1.0"

_LAZY = {"adjust", "covariance", "design_theta", "ranges", "simulate_ranges"}


def __getattr__(name: str):
    """The Brown kernels load on first use: they pull in numba, which a study that does not
    range has no need to import."""
    if name in _LAZY:
        from sim.instruments.ranges import multilateration

        return getattr(multilateration, name)
    raise AttributeError(f"module 'sim' has no attribute {name!r}")
