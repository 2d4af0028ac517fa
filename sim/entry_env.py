"""The environment checked when a command's module is imported from Python, not run as the
command (``import sim.cli``, ``sim.batch``, ``sim.report.verify``, ``sim.report.verify.cli``),
before it loads tqdm, NumPy and Arrow: what :mod:`sim.api_env` checks (``SOURCE_DATE_EPOCH``,
``ARROW_DEFAULT_MEMORY_POOL``, ``ARROW_USER_SIMD_LEVEL``) and a ``TQDM_`` variable tqdm cannot
read (those modules load tqdm, which reads them as it loads), each a :class:`sim.ConfigError`
naming the variable. ``import sim.cli`` with ``SOURCE_DATE_EPOCH=abc`` or ``TQDM_NCOLS=abc``
ended in a traceback from ``numpy.f2py`` or ``tqdm.utils`` (the commands refuse them as they
start, :func:`sim.threads.refuse_bad_environment`, so this finds nothing there). Importing this
module checks; it holds nothing else. Run as ``python -m sim.cli``, the module says it in
one line and exits 2, as ``python -m sim`` does.
"""

from __future__ import annotations

import sys

from sim.env_vars import arrow_simd_problem
from sim.threads import arrow_variables_problem, source_date_epoch_problem, tqdm_variables_problem

__all__: list[str] = []

#: the modules run as a command by ``python -m`` that are not checked before they load
#: (``python -m sim.cli``, as ``python -m sim``): the program their one line names
_AS_MAIN = {"sim.cli": "sim"}

_problem = (
    source_date_epoch_problem()
    or arrow_variables_problem()
    or arrow_simd_problem()
    or tqdm_variables_problem()
)
if _problem is not None:
    _spec = getattr(sys.modules.get("__main__"), "__spec__", None)
    if (_prog := _AS_MAIN.get(getattr(_spec, "name", None))) is not None:
        sys.stderr.write(f"{_prog}: error: {_problem}\n")  # a traceback of ConfigError
        sys.exit(2)
    from sim.mc.config import ConfigError

    raise ConfigError(None, _problem)
