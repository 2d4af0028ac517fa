"""Which key a user changed to push a comparator range off Brown's scale (seed
``004_f5bd9e86c308241f.txt``), so that ``sim check``'s refusal ("ranges run ... move the
stations in, or use alpha") names it: the ranges grow with the plate's points and the
stations, the scale reads ``comparator.scale_length_mm`` plus the micrometer, and a refusal
that always named the scale sent a user who had widened the grid to the one key they had
not touched.
"""

from __future__ import annotations

__all__ = ["RANGE_KEYS", "moved_from_paper"]

#: the keys that set how long the ranges are (stations, plate) and what the scale reads, in
#: the order a refusal names them; the point pattern's own keys join them (see below)
RANGE_KEYS = (
    "comparator.scale_length_mm",
    "comparator.micrometer_mm",
    "plate.format_mm",
    "comparator.station_offset_mm",
    "comparator.alpha_mm",
    "comparator.beta_mm",
)

#: the keys of each point pattern that move the points
PATTERN_KEYS = {
    "grid": ("plate.spacing_mm", "plate.grid"),
    "random": ("plate.random_half_extent_mm",),
}


def moved_from_paper(cfg: dict, points_key: str, defaults: dict) -> list[str]:
    """The range keys (:data:`RANGE_KEYS` and the pattern's, ``points_key`` for a list) whose
    value in ``cfg`` differs from ``defaults`` (the schema's: the paper's values, or its
    nominal ones), the scale's first, then the points', then the stations'."""
    pattern = PATTERN_KEYS.get(cfg["plate.pattern"], (points_key,))
    keys = [*RANGE_KEYS[:2], *pattern, *RANGE_KEYS[2:]]
    return [k for k in keys if k in defaults and cfg.get(k) != defaults[k]]
