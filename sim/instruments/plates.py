"""Point patterns on a square plate (coordinates in mm, plate centre at the origin)."""

from __future__ import annotations

import numpy as np

__all__ = ["grid_points", "random_points", "pattern_points"]


def grid_points(k: int, spacing_mm: float) -> np.ndarray:
    """A ``k`` x ``k`` grid at ``spacing_mm`` centred on the origin, shape ``(k*k, 2)``.

    Points are numbered row by row from the top left (largest y, smallest x).
    """
    c = (np.arange(k) - (k - 1) / 2) * spacing_mm
    yy, xx = np.meshgrid(c[::-1], c, indexing="ij")
    return np.column_stack([xx.ravel(), yy.ravel()])


def random_points(n: int, half_extent_mm: float, rng: np.random.Generator) -> np.ndarray:
    """``n`` points uniform in the square ``|x|, |y| <= half_extent_mm``, shape ``(n, 2)``."""
    return rng.uniform(-half_extent_mm, half_extent_mm, size=(n, 2))


def pattern_points(
    pattern: str,
    *,
    grid: int = 5,
    spacing_mm: float = 45.0,
    n_random: int = 25,
    half_extent_mm: float = 100.0,
    points=None,
    rng=None,
) -> np.ndarray:
    """Dispatch on the pattern name: ``grid``, ``random`` (needs ``rng``) or ``list``."""
    if pattern == "grid":
        return grid_points(grid, spacing_mm)
    if pattern == "random":
        if rng is None:
            raise ValueError("pattern 'random' needs a Generator (rng)")
        return random_points(n_random, half_extent_mm, rng)
    if pattern == "list":
        return np.asarray(points, float).reshape(-1, 2)
    raise ValueError(f"unknown point pattern {pattern!r}")
