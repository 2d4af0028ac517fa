"""One thread per process for BLAS: the suite parallelises over chunks of trials in worker
processes (``--workers``); a multi-threaded BLAS inside each would oversubscribe the cores and
make the small batched solves several times slower. BLAS reads these variables when it loads,
so the entry points (:mod:`sim.__main__`, :mod:`sim.batch`) call :func:`single_threaded_blas`
before anything imports NumPy; the environment of the caller wins.
"""

import os

BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def single_threaded_blas() -> None:
    for v in BLAS_THREAD_VARIABLES:
        os.environ.setdefault(v, "1")
