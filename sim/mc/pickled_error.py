"""An exception of the suite made again from its pickle, as it was: its whole line and its
attributes (a :class:`sim.mc.config.ConfigError`'s ``key``, its notes). A ``ConfigError``
takes ``(key, message)`` but holds one line as its ``args``, so the pickle of one (a worker of
the caller's ``multiprocessing.Pool`` refusing a handle) called ``ConfigError(line)``: a
``TypeError`` in the Pool's result thread, and the caller's ``map`` waited for good."""

from __future__ import annotations

from typing import Any

__all__ = ["remade"]


def remade(cls: type, args: tuple, state: dict) -> Any:
    """An instance of the exception class ``cls`` with ``args`` and the attributes ``state``,
    its ``__init__`` not called again."""
    e = cls.__new__(cls, *args)
    e.args = args
    e.__dict__.update(state)
    return e
