"""One thread per process for BLAS: the suite parallelises over chunks of trials in worker
processes (``--workers``); a multi-threaded BLAS inside each would oversubscribe the cores and
make the small batched solves several times slower. BLAS reads these variables when it loads,
so the entry points (:mod:`sim.__main__`, :mod:`sim.batch`) call :func:`single_threaded_blas`
before anything imports NumPy; the environment of the caller wins.
"""

import io
import os
import re
import resource
import signal
import sys
import threading
import time
import types

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
    itself (or a handler of the caller's: ``restore(then=handler)``); a signal the caller
    ignores (SIGINT of a background job, SIGHUP under nohup) stays ignored. Until then a library that cannot be loaded for want of memory
    (``ulimit -v``) ends the command with one line "not enough memory ..." and exit 2, not a
    traceback (or a crash while Python shuts down); a library that is missing, or shadowed by
    a file of its name on the path, is one line naming it (:func:`import_words`), exit 2."""
    hook = sys.excepthook

    def short(kind, e, tb):  # ulimit -v: a library that cannot be mapped, not a traceback
        if not short_of_memory(e):
            words = import_words(e)
            if words is None:
                return hook(kind, e, tb)
            os.write(2, f"{prog}: error: {words}\n".encode(errors="replace"))
            os._exit(2)
        os.write(2, f"{prog}: error: {memory_words(e)}\n".encode())
        os._exit(2)  # not Python's finalisation: short of memory, it may crash (SIGSEGV)

    sys.excepthook = short

    def handler(signum, frame):
        os.write(2, f"{prog}: interrupted\n".encode())
        os._exit(130)

    taken = []
    if threading.current_thread() is threading.main_thread():
        for name, default in LOADING_SIGNALS:
            s = getattr(signal, name, None)
            if s is not None and signal.getsignal(s) is default:
                signal.signal(s, handler)
                taken.append((s, default))

    def restore(then=None) -> list:
        """Put back the default handlers (or ``then``, the handler of the command's phase,
        :func:`sim.stops.run_program`); returns the signals it handles."""
        sys.excepthook = hook
        for s, default in taken:
            signal.signal(s, default if then is None else then)
        return [s for s, _ in taken]

    return restore


def import_words(e: BaseException | None) -> str | None:
    """The one line for a library the suite cannot import while an entry point loads, or None
    if ``e`` is neither an ImportError nor a shadowed module (:func:`shadowed`): a file of the
    library's name ahead of it on the path (an empty ``tqdm.py`` or ``numpy.py`` in
    ``PYTHONPATH`` or the working directory) is named as the cause; a library missing
    altogether (the suite run by a Python it was not installed into) says so. Both ended in a
    traceback."""
    if e is None or interrupted(e):  # Ctrl-C inside an import
        return None
    first = (str(e).splitlines() or [type(e).__name__])[0][:300]
    words = shadowed(e)
    if words is not None:
        return f"cannot load the suite: {first}; {words}"
    if not isinstance(e, ImportError):
        return None
    name = (e.name or "").split(".")[0]
    if own_venv():  # `make venv` would do nothing here: its stamp is newer than pyproject.toml
        return (
            f"cannot load {name or 'a library'}: {first}; the suite's virtual environment "
            f"{sys.prefix} lacks it: make clean venv installs it again (results/ is kept)"
        )
    return (
        f"cannot load {name or 'a library'}: {first}; run the suite with the Python it was "
        f"installed into (make venv; .venv/bin/sim), not {sys.executable}"
    )


def script_of_another_copy() -> str | None:
    """The words for the ``sim`` script of a ``.venv`` copied or moved with its project (``cp -a
    project copy``): the script starts the suite where the ``.venv`` was made, so ``copy/.venv/
    bin/sim`` silently ran the original's code (its edits, its code hash) in the copy; None
    otherwise (``python -m sim`` runs the code of the working directory, as meant)."""
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    argv = getattr(sys, "argv", None) or [""]  # a host process may have none
    script = os.path.abspath(argv[0]) if isinstance(argv[0], str) and argv[0] else ""
    venv = os.path.dirname(os.path.dirname(script))
    project = os.path.dirname(venv)
    if os.path.basename(script) != "sim" or os.path.basename(venv) != ".venv":
        return None
    try:
        if not os.path.isfile(os.path.join(project, "sim", "__init__.py")):
            return None
        if os.path.samefile(project, here):
            return None
    except OSError:
        return None
    return (
        f"{script} runs the suite in {here}, where its .venv was made, not the one in "
        f"{project}: a .venv cannot be copied or moved; make clean venv in {project} makes its own"
    )


def own_venv() -> bool:
    """Whether this Python is the suite's own ``.venv`` (the one ``make venv`` makes beside
    ``sim/``): a library missing there was removed from it, and running another Python would
    not help (the message said "run the suite with the Python it was installed into (make venv;
    .venv/bin/sim), not .venv/bin/python")."""
    suite = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    venv = os.path.join(suite, ".venv")
    try:
        return sys.prefix != sys.base_prefix and os.path.samefile(sys.prefix, venv)
    except OSError:
        return False


def _installed(path: str) -> bool:
    """Whether ``path`` is part of this Python's installation or of the suite itself."""
    suite = os.path.dirname(os.path.abspath(__file__))
    return path.startswith((sys.prefix, sys.base_prefix, suite + os.sep))


def shadowed(e: BaseException | None, forget: bool = False) -> str | None:
    """Words naming a file of the user's that shadows a library (``tomllib.py``,
    ``matplotlib.py``, an empty ``numba/`` directory on ``PYTHONPATH`` or in the working
    directory), if ``e`` (or an exception it came from) is an ImportError of that library or
    an AttributeError read from that module; else None. Such a file ended a command in an
    "internal error" (exit 3) or a traceback, wherever the library was first used.
    ``forget``: the file's module (and its submodules) is dropped from ``sys.modules``, so a
    process that goes on (the API's caller) imports the library once the file is renamed."""
    seen = set()
    while e is not None and id(e) not in seen:
        seen.add(id(e))
        module = getattr(e, "obj", None) if isinstance(e, AttributeError) else None
        said = re.match(r"module '([\w.]+)' has no attribute", str(e))  # from C (pyarrow)
        if module is None and isinstance(e, AttributeError) and said:
            module = sys.modules.get(said.group(1))
        if isinstance(e, ImportError):
            module = sys.modules.get((e.name or "").split(".")[0])
        if isinstance(module, types.ModuleType):
            where = getattr(module, "__file__", None)
            where = where or next(iter(getattr(module, "__path__", None) or ()), None)
            if where and not _installed(str(where)):
                if forget:
                    top = module.__name__.split(".")[0]
                    for name in [n for n in sys.modules if n.split(".")[0] == top]:
                        del sys.modules[name]
                return (
                    f"{where} shadows the library {module.__name__} (PYTHONPATH or the working "
                    "directory): rename it or leave that directory"
                )
        e = e.__cause__ or e.__context__
    return None


#: what the loader and llvmlite say of a library they cannot map into memory (ulimit -v)
_MAP_WORDS = ("failed to map segment", "cannot allocate memory", "could not find/load shared")


def short_of_memory(e: BaseException | None) -> bool:
    """Whether ``e`` (or an exception it came from) says the process ran out of address space:
    a MemoryError, or, under a limit of address space (``ulimit -v``), a shared library that
    could not be mapped (an ImportError or OSError that blamed the library itself)."""
    limited = resource.getrlimit(resource.RLIMIT_AS)[0] != resource.RLIM_INFINITY
    seen = set()
    while e is not None and id(e) not in seen:
        if isinstance(e, MemoryError):
            return True
        text = str(e).lower()
        if isinstance(e, (ImportError, OSError)) and any(w in text for w in _MAP_WORDS):
            return limited or "cannot allocate memory" in text
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return False


def memory_words(e: BaseException | None = None) -> str:
    """The one line's words for :func:`short_of_memory`: what could not be had (a library, or
    NumPy's "Unable to allocate ..."), and the limit if one is set."""
    cap = resource.getrlimit(resource.RLIMIT_AS)[0]
    limit = f" (ulimit -v is {cap // 1024} kB)" if cap != resource.RLIM_INFINITY else ""
    what = "to load the suite and its libraries"  # a library that could not be mapped
    if isinstance(e, MemoryError):  # the command's own work (a run, a huge table to show):
        what = "for this command" + (f": {str(e).splitlines()[0][:200]}" if str(e) else "")
    return f"not enough memory {what}{limit}"


#: address space (kB) below which no command starts: the suite's libraries (NumPy, SciPy,
#: pyarrow, numba's LLVM) map about 700 MB before any work; under a limit just above that,
#: OpenBLAS retried each failed allocation inside SuperLU and a small network ran for hours
MIN_ADDRESS_SPACE_KB = 1024 * 1024


def address_space_problem() -> str | None:
    """The words for an address-space limit under :data:`MIN_ADDRESS_SPACE_KB`, or None (the
    commands exit on it as they start; ``sim.load`` raises it)."""
    cap = resource.getrlimit(resource.RLIMIT_AS)[0]
    if cap == resource.RLIM_INFINITY or cap // 1024 >= MIN_ADDRESS_SPACE_KB:
        return None
    return (
        f"not enough memory: ulimit -v is {cap // 1024} kB, and the suite needs at least "
        f"{MIN_ADDRESS_SPACE_KB} kB of address space (its libraries map about 700 MB)"
    )


def _refuse_small_address_space(prog: str) -> None:
    if (words := address_space_problem()) is not None:
        sys.stderr.write(f"{prog}: error: {words}\n")
        sys.exit(2)


def refuse_bad_environment(prog: str) -> None:
    """Exit 2 with one line when the environment cannot load the suite: an address-space
    limit under :data:`MIN_ADDRESS_SPACE_KB` (``ulimit -v``), or a value that breaks loading
    NumPy or SciPy (``SOURCE_DATE_EPOCH`` that is not an integer ended every command in a
    traceback from ``numpy.f2py``, imported by ``scipy.sparse``), or an allocator Arrow does
    not have (:func:`arrow_variables_problem`). Called by the entry points
    before anything imports NumPy."""
    _refuse_small_address_space(prog)
    _refuse_bad_tqdm_variables(prog)
    if (problem := source_date_epoch_problem() or arrow_variables_problem()) is not None:
        sys.stderr.write(f"{prog}: error: {problem}\n")
        sys.exit(2)


def source_date_epoch_problem() -> str | None:
    """What is wrong with ``SOURCE_DATE_EPOCH`` for ``numpy.f2py`` (imported by SciPy, which
    reads it as an integer while it loads), or None; None too once ``numpy.f2py`` is loaded
    (it has read it). The words name the variable, without the program: ``sim.load`` raises
    them (``sim._refuse_unloadable``), as the commands refuse them."""
    v = os.environ.get("SOURCE_DATE_EPOCH")
    if v is None or "numpy.f2py" in sys.modules:
        return None
    try:
        time.gmtime(int(v))  # as numpy.f2py reads it (99999999999999999999: OverflowError)
    except (ValueError, OverflowError, OSError):
        return (
            f"SOURCE_DATE_EPOCH: must be an integer, seconds since 1970 within the system's "
            f"dates (got {v[:40]!r}); NumPy reads it while loading"
        )
    return None


#: the allocators Arrow's ``ARROW_DEFAULT_MEMORY_POOL`` names (its words when it refuses one)
ARROW_POOLS = ("mimalloc", "jemalloc", "system")


def arrow_variables_problem() -> str | None:
    """What is wrong with ``ARROW_DEFAULT_MEMORY_POOL``, or None (None too once pyarrow is
    loaded: it has read it). Arrow reads it when it loads, in the middle of a command: another
    value (``System``, ``malloc``) was a line of Arrow's own on standard error
    ("/arrow/cpp/src/arrow/memory_pool.cc:106: Unsupported backend ...") and a run on Arrow's
    default allocator, mimalloc, exit 0, under ``ulimit -v`` or ``-d`` too, where the suite
    asks for the system's (:mod:`sim`). The variable is one of :data:`ARROW_POOLS`, or empty
    or unset. The words name the variable, without the program."""
    v = os.environ.get("ARROW_DEFAULT_MEMORY_POOL")
    if not v or v in ARROW_POOLS or "pyarrow" in sys.modules:
        return None
    return (
        f"ARROW_DEFAULT_MEMORY_POOL: must be {', '.join(ARROW_POOLS[:-1])} or {ARROW_POOLS[-1]} "
        f"(Arrow's allocators), or empty or unset, got {v[:40]!r}"
    )


def tqdm_variables_problem() -> str | None:
    """What is wrong with the ``TQDM_<option>`` variables, or None. tqdm (the progress bar)
    converts each to its option's type, some while it is imported (``TQDM_NCOLS=abc`` ended
    every command, and ``import sim.api``, in a traceback from ``tqdm.utils``), some only when a
    bar is drawn (``TQDM_LOCK_ARGS=x``): so a bar is drawn here, into memory. tqdm is imported
    only when such a variable is set. The words name the variables, without the program."""
    given = sorted(k for k in os.environ if k.upper().startswith("TQDM_"))
    if not given:
        return None
    try:
        from tqdm import tqdm  # its import reads the variables

        sink = io.TextIOWrapper(io.BytesIO(), encoding="utf-8")
        bar = tqdm(total=2, file=sink, disable=False, leave=False, mininterval=0)
        bar.update(1)
        bar.close()
    except (ValueError, TypeError, KeyError, AttributeError, OverflowError) as e:
        return (
            f"{', '.join(given)}: tqdm cannot read "
            f"{'it' if len(given) == 1 else 'them'} ({str(e).splitlines()[0][:200]})"
        )
    return None


def _refuse_bad_tqdm_variables(prog: str) -> None:
    if (problem := tqdm_variables_problem()) is not None:
        sys.stderr.write(f"{prog}: error: {problem}\n")
        sys.exit(2)
