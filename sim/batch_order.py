"""The order in which ``python -m sim.batch`` starts its study runs (moved out of
:mod:`sim.batch`, which is at the module size limit): the slowest studies first, so that the
runs side by side end together."""

from __future__ import annotations

from pathlib import Path

__all__ = ["SLOW_FIRST", "order"]

#: the studies that take longest (``make bench``'s rerun rows), started first in this order
SLOW_FIRST = (
    "wolf_polynomial",
    "brown_design",
    "agnard_block",
    "salsig_encoders",
    "gridplate_two_plates",
    "brown_dilution",
)


def order(files: list[Path]) -> list[Path]:
    """``files`` with those named in :data:`SLOW_FIRST` first (in its order), then the rest in
    the given order."""
    rank = {s: i for i, s in enumerate(SLOW_FIRST)}
    return sorted(files, key=lambda f: rank.get(f.stem, len(rank)))
