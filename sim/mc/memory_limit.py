"""The memory limit a command was given (``--max-memory-gb``), for the checks made while it
loads a study: the size check of a network at load (:mod:`sim.studies.network.validate`)
read ``SIM_MAX_MEMORY_GB`` alone, so ``sim run --max-memory-gb 64`` of a large network was
refused at the default 8 GiB, naming the environment variable, while the run's own estimate
(:func:`sim.mc.estimate.check_limits`) took the option."""

from __future__ import annotations

import math
import os
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

from sim.mc.config import ConfigError
from sim.mc.numtext import UnheldError, float_text

__all__ = ["DEFAULT_MAX_MEMORY_GB", "limit_value", "memory_given", "memory_limit_gb"]

#: the memory limit in GiB when neither ``--max-memory-gb`` nor ``SIM_MAX_MEMORY_GB`` gives one
DEFAULT_MAX_MEMORY_GB = 8.0

#: the command's ``--max-memory-gb`` while it runs (None: not given)
_GIVEN: ContextVar[float | None] = ContextVar("max_memory_gb", default=None)


def memory_limit_gb() -> float:
    """The memory limit in GiB: the command's, else ``SIM_MAX_MEMORY_GB``, else the default."""
    return limit_value(_GIVEN.get(), "SIM_MAX_MEMORY_GB", DEFAULT_MAX_MEMORY_GB, "--max-memory-gb")


@contextmanager
def memory_given(gb: float | None) -> Iterator[None]:
    """The checks inside take ``gb`` (a command's ``--max-memory-gb``; None: the environment's)."""
    token = _GIVEN.set(gb)
    try:
        yield
    finally:
        _GIVEN.reset(token)


def limit_value(given: float | None, env: str, default: float, key: str) -> float:
    """A limit: ``given`` (a command's option, named ``key``), else the environment variable
    ``env`` (named in its refusal), else ``default``; a number that is not finite and positive
    is refused in one line."""
    if given is None:
        txt = os.environ.get(env)
        if txt is None or not txt.strip():
            return default
        try:  # ASCII digits, as --max-memory-gb reads them ('٨' was read as 8); 1e-400 is
            given = float_text(txt) if txt.isascii() else float("x")  # no 0 (the digits said)
        except UnheldError as e:
            raise ConfigError(env, str(e)) from None
        except ValueError:
            raise ConfigError(env, f"must be a number (got {txt!r})") from None
        key = env
    if not math.isfinite(given) or given <= 0:
        raise ConfigError(key, f"must be a finite positive number (got {given!r})")
    return given
