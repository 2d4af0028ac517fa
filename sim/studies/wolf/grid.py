"""The grid of ``wolf_polynomial``: the quadrille's intersections inside the calibrated area,
the cell centres used as check points, and the index of a node (Wolf & Pearsall 1976, seed
``000_668e60e68f004f98.txt``: a 20 mm quadrille, line ab from the origin along x). mm."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["grid_nodes", "mid_cells", "node_index"]


def grid_nodes(area, spacing: float) -> np.ndarray:
    """Intersections of a quadrille at ``spacing`` inside ``area`` = [xmin, xmax, ymin, ymax],
    on multiples of the spacing (so the origin ``a`` is one), rows from the top, ``(n, 2)`` mm."""
    x0, x1, y0, y1 = area
    xs = spacing * np.arange(math.ceil(x0 / spacing - 1e-9), math.floor(x1 / spacing + 1e-9) + 1)
    ys = spacing * np.arange(math.ceil(y0 / spacing - 1e-9), math.floor(y1 / spacing + 1e-9) + 1)
    yy, xx = np.meshgrid(ys[::-1], xs, indexing="ij")
    return np.column_stack([xx.ravel(), yy.ravel()])


def mid_cells(area, spacing: float) -> np.ndarray:
    """Check points at the centres of the grid cells, ``(m, 2)`` mm."""
    g = grid_nodes(area, spacing)
    xs, ys = np.unique(g[:, 0]), np.unique(g[:, 1])
    cx, cy = (xs[:-1] + xs[1:]) / 2, (ys[:-1] + ys[1:]) / 2
    yy, xx = np.meshgrid(cy[::-1], cx, indexing="ij")
    return np.column_stack([xx.ravel(), yy.ravel()])


def node_index(g: np.ndarray, p) -> int:
    """The index of the grid node at ``p`` (mm), or -1 when no node lies within 1 nm."""
    d = np.hypot(g[:, 0] - p[0], g[:, 1] - p[1])
    j = int(np.argmin(d))
    return j if d[j] < 1e-6 else -1
