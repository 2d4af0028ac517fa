"""The refusal of a configuration over a limit of the machine the command runs on."""

from __future__ import annotations

from sim.mc.config import ConfigError

__all__ = ["LimitError"]


class LimitError(ConfigError):
    """A configuration over a limit of the machine (``--max-memory-gb``), not of its design:
    a sweep's cell refused for it refuses the sweep, naming the cell (recorded infeasible, the
    sweep's results would depend on the limit of the machine that ran it)."""
