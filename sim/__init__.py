"""sim: Monte-Carlo reproduction of classic comparator and plotter calibration papers.

The public surface: ``sim.load(study_file, **overrides).run()`` (:mod:`sim.api`), the
configuration errors, and the claims and storage helpers every study uses. Everything else is
internal. Importing ``sim`` does nothing else: the names load on first use (as SciPy's
subpackages do), so the command line (:mod:`sim.__main__`) can set up its processes first.
"""

import importlib as _importlib  # underscored: dir(sim) (a notebook's completion) listed
import os as _os  # os, resource and importlib as names of the suite's public surface
import resource as _resource
import sys as _sys


def _system_pool_under_limits() -> None:
    """Under ``ulimit -v`` or ``-d``, Arrow's tables come from the system's allocator
    (``ARROW_DEFAULT_MEMORY_POOL=system``, unless the variable is set, not empty), read by Arrow
    when it loads, so set before: Arrow's default, mimalloc, maps up to 1 GiB of the address
    space it is given at its first table. A 10,000-point network (0.93 GiB mapped at its peak
    with the system's) peaked at 1,999,916 kB under ``ulimit -v 2000000``, 84 kB from the limit:
    the room checked before the run (:mod:`sim.room`) was not there, a Parquet read with no room
    left for Arrow's threads hung for good, and the API's next run in the process was refused."""
    caps = (_resource.getrlimit(r)[0] for r in (_resource.RLIMIT_AS, _resource.RLIMIT_DATA))
    if any(c != _resource.RLIM_INFINITY for c in caps):  # an empty value is Arrow's default
        if not _os.environ.get("ARROW_DEFAULT_MEMORY_POOL"):
            _os.environ["ARROW_DEFAULT_MEMORY_POOL"] = "system"


_system_pool_under_limits()

#: public name -> the module that defines it
_EXPORTS = {
    "load": "sim.api",
    "StudyHandle": "sim.api",
    "Results": "sim.api",
    "StaleResultsWarning": "sim.api_tables",
    "ConfigError": "sim.mc.config",
    "StudyError": "sim.mc.config",
    "load_study": "sim.api_helpers",  # the helpers every study uses, checked as the API's
    "run_chunks": "sim.api_helpers",
    "write_table": "sim.api_helpers",
    "read_provenance": "sim.api_helpers",
}
__all__ = list(_EXPORTS)
__version__ = "0.1.0"


#: names a user likely tries on ``sim`` (``sim.run(...)``: Python's bare AttributeError), and
#: what does their work
_MEANT = {
    "run": "sim.load(STUDY_FILE).run() runs a study",
    "check": "sim.load(STUDY_FILE) checks a study file, as sim check does",
    "show": "sim.Results(DIR, STUDY).names() and .table(NAME) read a run's results",
    "read": "sim.Results(DIR, STUDY).table(NAME) reads a run's table",
    "results": "sim.Results(DIR, STUDY) reads a run's results",
    "report": "the report is made by the command sim report",
    "batch": "the batch is the command python -m sim.batch",
}


def __getattr__(name: str):
    if name in _EXPORTS:
        _refuse_unloadable(_EXPORTS[name])
        try:
            module = _importlib.import_module(_EXPORTS[name])
        except (ImportError, AttributeError) as e:  # a user's scipy.py, numpy.py in the cwd
            _refuse_shadowed(e)
            raise
        return getattr(module, name)
    lower = {n.lower(): n for n in _EXPORTS}  # sim.LOAD, sim.results
    if name.lower() in lower or name.lower() in _MEANT:
        meant = lower.get(name.lower())
        raise AttributeError(  # an AttributeError still: hasattr(sim, "run") is False
            f"module 'sim' has no attribute {name!r}: "
            + (f"did you mean sim.{meant}?" if meant else _MEANT[name.lower()])
        )
    raise AttributeError(f"module 'sim' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + __all__)


def _refuse_unloadable(module: str) -> None:
    """Raise :class:`ConfigError` naming a variable of the environment that keeps ``module``
    from loading, as the commands refuse it when they start: ``sim.load`` with a
    ``SOURCE_DATE_EPOCH`` that is not an integer (``abc``) ended in a traceback from
    ``numpy.f2py`` (imported by ``scipy.sparse``), "ValueError: invalid literal for int()";
    with ``ARROW_DEFAULT_MEMORY_POOL=System`` it ran on Arrow's default allocator after a line
    of Arrow's own (:func:`sim.threads.arrow_variables_problem`)."""
    if module in _sys.modules or module == "sim.mc.config":  # loaded, or loads no NumPy
        return
    from sim.threads import arrow_variables_problem, source_date_epoch_problem

    if (problem := source_date_epoch_problem() or arrow_variables_problem()) is not None:
        from sim.mc.config import ConfigError

        raise ConfigError(None, problem)


def _refuse_shadowed(e: BaseException) -> None:
    """Raise :class:`ConfigError` naming a file of the user's that shadows a library the API
    loads on first use (an empty ``scipy.py``, ``numpy.py`` or ``pyarrow.py`` in the working
    directory of a notebook): ``sim.load`` ended in an ImportError traceback from the suite's
    imports, where the commands say one line (:func:`sim.threads.shadowed`). The file's module
    is dropped, so the process loads the library once the file is renamed."""
    from sim.threads import shadowed

    if (words := shadowed(e, forget=True)) is not None:
        from sim.mc.config import ConfigError

        first = (str(e).splitlines() or [type(e).__name__])[0][:300]
        raise ConfigError(None, f"cannot load the suite: {first}; {words}") from None
