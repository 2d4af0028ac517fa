"""sim: Monte-Carlo reproduction of classic comparator and plotter calibration papers.

The public surface: ``sim.load(study_file, **overrides).run()`` (:mod:`sim.api`), the
configuration errors, and the claims and storage helpers every study uses. Everything else is
internal. Importing ``sim`` does nothing else: the names load on first use (as SciPy's
subpackages do), so the command line (:mod:`sim.__main__`) can set up its processes first.
"""

import importlib

#: public name -> the module that defines it
_EXPORTS = {
    "load": "sim.api",
    "StudyHandle": "sim.api",
    "Results": "sim.api",
    "StaleResultsWarning": "sim.api_tables",
    "ConfigError": "sim.mc.config",
    "StudyError": "sim.mc.config",
    "load_study": "sim.studies",
    "run_chunks": "sim.mc.runner",
    "write_table": "sim.mc.storage",
    "read_provenance": "sim.mc.storage",
}
__all__ = list(_EXPORTS)
__version__ = "0.1.0"


def __getattr__(name: str):
    if name in _EXPORTS:
        return getattr(importlib.import_module(_EXPORTS[name]), name)
    raise AttributeError(f"module 'sim' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + __all__)
