"""The environment checked when a module of the API is imported directly (``import sim.api``,
``from sim.api_helpers import run_chunks``), before it loads NumPy and Arrow: a
``SOURCE_DATE_EPOCH`` that is not an integer, an ``ARROW_DEFAULT_MEMORY_POOL`` Arrow does
not have or an ``ARROW_USER_SIMD_LEVEL`` it does not know (read as ``pyarrow.compute`` loads) is a :class:`sim.ConfigError` naming the variable, as ``sim.load`` raises it (through
``sim``'s own names only: ``import sim.api`` ended in a traceback from ``numpy.f2py``, or ran
after a line of Arrow's own). Importing this module checks; it holds nothing else.
"""

from __future__ import annotations

from sim.env_vars import arrow_simd_problem
from sim.threads import arrow_variables_problem, source_date_epoch_problem

__all__: list[str] = []

_problem = source_date_epoch_problem() or arrow_variables_problem() or arrow_simd_problem()
if _problem is not None:
    from sim.mc.config import ConfigError

    raise ConfigError(None, _problem)
