"""The environment checked when a command's module is imported from Python, not run as the
command (``import sim.cli``, ``sim.batch``, ``sim.report.verify``, ``sim.report.verify.cli``),
before it loads tqdm, NumPy and Arrow: what :mod:`sim.api_env` checks (``SOURCE_DATE_EPOCH``,
``ARROW_DEFAULT_MEMORY_POOL``, ``ARROW_USER_SIMD_LEVEL``) and a ``TQDM_`` variable tqdm cannot
read (those modules load tqdm, which reads them as it loads), each a :class:`sim.ConfigError`
naming the variable. ``import sim.cli`` with ``SOURCE_DATE_EPOCH=abc`` or ``TQDM_NCOLS=abc``
ended in a traceback from ``numpy.f2py`` or ``tqdm.utils`` (the commands refuse them as they
start, :func:`sim.threads.refuse_bad_environment`, so this finds nothing there). Importing this
module checks; it holds nothing else.
"""

from __future__ import annotations

import sim.api_env  # noqa: F401 - SOURCE_DATE_EPOCH and Arrow's variables: a ConfigError
from sim.threads import tqdm_variables_problem

__all__: list[str] = []

_problem = tqdm_variables_problem()
if _problem is not None:
    from sim.mc.config import ConfigError

    raise ConfigError(None, _problem)
