"""Which key a user changed to push a comparator range off Brown's scale (seed
``004_f5bd9e86c308241f.txt``), so that ``sim check``'s refusal ("ranges run ... move the
stations in, or use alpha") names it: the ranges grow with the plate's points and the
stations, the scale reads ``comparator.scale_length_mm`` plus the micrometer, and a refusal
that always named the scale sent a user who had widened the grid to the one key they had
not touched; and whether the personal bias ``errors.bias_um``, which the comparator reads
with every range, pushes a reading off the scale that the range alone keeps on it.
"""

from __future__ import annotations

import numpy as np

from sim.mc.config import ConfigError

__all__ = ["RANGE_KEYS", "moved_from_paper", "check_scale"]

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


def check_scale(cfg: dict, points_key: str, r: np.ndarray, defaults: dict) -> None:
    """Every reading of the plate lies on the scale, 0 to ``comparator.scale_length_mm`` plus
    the micrometer (not enforced at a length of 0): the true ranges ``r`` (mm), named by the
    keys that moved them (:func:`moved_from_paper`), then the ranges plus ``errors.bias_um``,
    which the simulation adds to every reading (a 10 mm bias with the stations 30 mm out
    read 268 mm on the 262 mm scale, and the run scored the plate as Brown's comparator)."""
    if cfg["comparator.scale_length_mm"] <= 0:
        return
    reach = cfg["comparator.scale_length_mm"] + cfg["comparator.micrometer_mm"]
    scale = "the scale (comparator.scale_length_mm + comparator.micrometer_mm) reads 0 to"
    if r.max() > reach or r.min() < 0:
        moved = moved_from_paper(cfg, points_key, defaults)
        raise ConfigError(
            moved[0] if moved else "comparator.scale_length_mm",
            f"ranges run from {r.min():.1f} to {r.max():.1f} mm but {scale} {reach:g} mm "
            "(move the stations in, or use alpha)"
            + (
                f"; changed from their paper or nominal values: {', '.join(moved)}" if moved else ""
            ),
        )
    b = cfg["errors.bias_um"] * 1e-3
    if r.max() + b > reach or r.min() + b < 0:
        raise ConfigError(
            "errors.bias_um",
            f"a bias of {b:g} mm on every range reads them from {r.min() + b:.1f} to "
            f"{r.max() + b:.1f} mm, but {scale} {reach:g} mm (the ranges alone run from "
            f"{r.min():.1f} to {r.max():.1f} mm)",
        )
