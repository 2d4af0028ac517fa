"""One thread per process for BLAS: the suite parallelises over chunks of trials in worker
processes (``--workers``); a multi-threaded BLAS inside each would oversubscribe the cores and
make the small batched solves several times slower. BLAS reads these variables when it loads,
so the entry points (:mod:`sim.__main__`, :mod:`sim.batch`) call :func:`single_threaded_blas`
before anything imports NumPy; the environment of the caller wins.
"""

import os
import signal
import sys
import threading

BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def single_threaded_blas() -> None:
    for v in BLAS_THREAD_VARIABLES:
        os.environ.setdefault(v, "1")


def interrupted(e: BaseException | None) -> bool:
    """Whether ``e`` comes of Ctrl-C (or SIGTERM, raised as one): an extension module whose
    initialisation is interrupted (pybind11's, as SciPy's modules imported on first use) raises
    ``ImportError: initialization failed`` from the KeyboardInterrupt, which a run reported as
    its own failure (exit 3) instead of an interruption (exit 130)."""
    seen = set()
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt):
            return True
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return False


def interrupt_while_loading(prog: str):
    """Ctrl-C while an entry point imports the suite (a second or two): one line
    ``<prog>: interrupted`` and exit 130, as later, not a traceback from whichever import
    was running (nothing has been written yet). Returns the function that puts Python's own
    handler back once the command handles Ctrl-C itself; a SIGINT the caller ignores (a
    background job) stays ignored."""
    if (
        threading.current_thread() is not threading.main_thread()
        or signal.getsignal(signal.SIGINT) is not signal.default_int_handler
    ):
        return lambda: None

    def handler(signum, frame):
        os.write(2, f"{prog}: interrupted\n".encode())
        os._exit(130)

    signal.signal(signal.SIGINT, handler)
    return lambda: signal.signal(signal.SIGINT, signal.default_int_handler)


def refuse_bad_environment(prog: str) -> None:
    """Exit 2 with one line when the environment holds a value that breaks loading NumPy or
    SciPy: ``SOURCE_DATE_EPOCH`` that is not an integer ended every command in a traceback
    from ``numpy.f2py`` (imported by ``scipy.sparse``). Called by the entry points before
    anything imports NumPy."""
    v = os.environ.get("SOURCE_DATE_EPOCH")
    if v is None:
        return
    try:
        int(v)  # as numpy.f2py reads it
    except ValueError:
        sys.stderr.write(
            f"{prog}: error: SOURCE_DATE_EPOCH: must be an integer, seconds since 1970 "
            f"(got {v!r}); NumPy reads it while loading\n"
        )
        sys.exit(2)
