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
#: the signals an entry point takes over while it loads, with their default handlers
LOADING_SIGNALS = (
    ("SIGINT", signal.default_int_handler),
    ("SIGTERM", signal.SIG_DFL),
    ("SIGHUP", signal.SIG_DFL),
)


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
    """Ctrl-C (or SIGTERM, SIGHUP) while an entry point imports the suite (a second or two):
    one line ``<prog>: interrupted`` and exit 130, as later, not a traceback from whichever
    import was running nor a silent death by SIGTERM (nothing has been written yet). Returns
    the function that puts the default handlers back once the command handles the signals
    itself; a signal the caller ignores (SIGINT of a background job, SIGHUP under nohup)
    stays ignored."""
    if threading.current_thread() is not threading.main_thread():
        return lambda: None

    def handler(signum, frame):
        os.write(2, f"{prog}: interrupted\n".encode())
        os._exit(130)

    taken = []
    for name, default in LOADING_SIGNALS:
        s = getattr(signal, name, None)
        if s is not None and signal.getsignal(s) is default:
            signal.signal(s, handler)
            taken.append((s, default))

    def restore() -> None:
        for s, default in taken:
            signal.signal(s, default)

    return restore


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
