"""Brown's Multilaterative Comparator (seed 004, Brown 1968): the one instrument of the Brown
studies (``brown_dilution``, ``brown_table1``, ``brown_design``).

What the paper prints (hardware): a 245 x 245 mm format; a scale 29 mm wide, graduated over
261 mm, translated by a micrometer by at most 1 mm (so a range reads 0 to 262 mm); the scale
pivots about a ball bearing and the plate is turned by nominally 90 degrees between four
positions, i.e. four stations on the axes, "a short distance from the midsides" of the format,
with the pivot offsets alpha (along the scale) and beta (across it). Ranges in Brown's model:
``(r + alpha)^2 + beta^2 = |point - station|^2``.

What it does not print, with the range the hardware allows (:data:`INPUTS`, a declaration for
:func:`sim.claims.inference.parse_declaration`): the station offset outside the midsides (the
pivot stands beside the plate, not on it: >= 0.5 mm; the scale bounds it from above through
:func:`max_range_mm`), beta (the pivot ball lies under the 29 mm wide scale: |beta| <= 14.5
mm), and the extent of the Concept's "about 25 well-distributed points". alpha enters every
range as a constant and no standard deviation; it is fixed at 0.5 mm.

Every function is batched over a leading geometry axis ``G``. Lengths in mm.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.plates import grid_points
from sim.instruments.ranges import multilateration as ml

__all__ = [
    "FORMAT_MM",
    "SCALE_MM",
    "MICROMETER_MM",
    "REACH_MM",
    "SCALE_WIDTH_MM",
    "ALPHA_MM",
    "TABLE1_GRID",
    "TABLE1_SPACING_MM",
    "INPUTS",
    "TABLE1",
    "thetas",
    "table1_points",
    "table1_cofactors",
    "table1_sigma_stats",
    "grid_of_extent",
    "max_range_mm",
    "min_range_mm",
    "feasible",
    "max_offset_mm",
]

FORMAT_MM = 245.0
SCALE_MM = 261.0
MICROMETER_MM = 1.0
REACH_MM = SCALE_MM + MICROMETER_MM
SCALE_WIDTH_MM = 29.0
ALPHA_MM = 0.5
#: Table 1's plate: a 5 x 5 array of PUG points evenly spaced at 45 mm
TABLE1_GRID = 5
TABLE1_SPACING_MM = 45.0

#: the unprinted inputs and the ranges the hardware allows (declaration data)
INPUTS = {
    "inputs": {
        "station_offset_mm": {
            "low": 0.5,
            "high": 80.0,
            "why": "'a short distance from the midsides' (not printed): the pivot stands beside "
            "the plate, not on its edge (>= 0.5 mm); above, the 261 + 1 mm scale bounds it "
            "(every range must read: at most 71.5 mm out for a grid spread over half the "
            "format), so 80 mm is never reached",
        },
        "beta_mm": {
            "low": 0.0,
            "high": SCALE_WIDTH_MM / 2,
            "why": "pivot offset across the scale (not printed): the ball lies under the 29 mm "
            "wide scale",
        },
        "half_extent_mm": {
            "low": FORMAT_MM / 4,
            "high": FORMAT_MM / 2,
            "why": "the Concept's 'about 25 well-distributed points' (layout not printed): a 5 x 5 "
            "grid spread over at least half the format, at most all of it",
        },
        "sigma0_um": {
            "low": 1.45,
            "high": 2.05,
            "why": "the plate's rms error of closure: production models 'range typically from "
            "1.5 to 2.0 microns' (at their rounding); Table 1 prints 1.6",
        },
    }
}


_T1 = "brown.table1_point_sigma."
#: Table 1's printed statements, declared once for every Brown study (declaration data for
#: :func:`sim.claims.inference.parse_declaration`): the plate's rms error of closure, which
#: bounds sigma0, and the four statements about its 50 printed point sigmas
#: (:func:`table1_sigma_stats`, :func:`table1_cofactors`), each with the zone its printed
#: number stands for (``form``, ``ref``, ``decimals``, ``tol``). brown_table1 scores them as
#: claim rows (its claim book takes their zones from here); brown_design's region and
#: brown_dilution's reading of the built comparator take them as constraints.
TABLE1 = {
    "inputs": {k: INPUTS["inputs"][k] for k in ("station_offset_mm", "beta_mm", "sigma0_um")},
    "statements": {
        "brown.table1_closure.rms_um": {
            "form": "one-plate",
            "ref": 1.6,
            "decimals": 1,
            "tol": 0.0,
            "paper": "the rms error of closure turned out to be 1.6 microns (Table 1)",
            "source": "004, Results (Table 1)",
        },
        _T1 + "share_1p1_1p3": {
            "form": "share",
            "ref": 0.8,
            "decimals": 2,
            "tol": 0.05,
            "paper": "80 percent of the standard deviations in x and y ranged between 1.1 and "
            "1.3 microns (share of the 50 sigmas printing 1.1-1.3 um; '80 percent' read as "
            "75-85 %)",
            "source": "004, Results",
        },
        _T1 + "points_ge_1p45": {
            "form": "range",
            "ref": [2, 4],
            "tol": 0.0,
            "paper": "2 points had standard deviations as large as 1.5 microns (points whose "
            "larger sigma prints >= 1.5 um; the model's points come in fours: 2-4)",
            "source": "004, Results",
        },
        _T1 + "max_um": {
            "form": "value",
            "ref": 1.5,
            "decimals": 1,
            "tol": 0.0,
            "paper": "2 points had standard deviations as large as 1.5 microns (the largest, um)",
            "source": "004, Results",
        },
        _T1 + "below_closure": {
            "form": "range",
            "ref": [0.0, 1.0],
            "tol": 0.0,
            "paper": "the standard deviations ... will be somewhat smaller than the rms error of "
            "closure (every sigma / sigma0)",
            "source": "004, Results",
        },
    },
}


def thetas(offset_mm, beta_mm, alpha_mm: float = ALPHA_MM, format_mm: float = FORMAT_MM):
    """Brown's 7 globals ``(G, 7)`` of stations ``offset_mm`` outside the midsides."""
    o, b = np.broadcast_arrays(np.atleast_1d(offset_mm), np.atleast_1d(beta_mm))
    h = format_mm / 2 + o
    z = np.zeros_like(h, dtype=float)
    return np.stack([h, h, z, -h, -h, z + alpha_mm, b**2], -1).astype(float)


def table1_points() -> np.ndarray:
    """Table 1's 5 x 5 points at 45 mm ``(25, 2)``."""
    return grid_points(TABLE1_GRID, TABLE1_SPACING_MM)


def table1_cofactors(offset_mm, beta_mm, alpha_mm: float = ALPHA_MM) -> np.ndarray:
    """sigma / sigma0 = sqrt(Q_xx), sqrt(Q_yy) of Table 1's 25 points in the pivot model
    ``(G, 25, 2)`` at ``G`` (station offset, beta) pairs (exact, analytic; NaN where the
    geometry is singular)."""
    o = np.atleast_1d(np.asarray(offset_mm, float))
    P = np.broadcast_to(table1_points(), (len(o), 25, 2)).copy()
    with np.errstate(invalid="ignore"):
        Q = ml.covariance(P, thetas(o, beta_mm, alpha_mm), "pivot")[0]
        return np.sqrt(np.stack([Q[..., 0, 0], Q[..., 1, 1]], -1))


def table1_sigma_stats(sig_um: np.ndarray) -> dict[str, np.ndarray]:
    """Table 1's one-plate statistics of point sigmas ``(..., n, 2)`` (um) as the paper prints
    them (one decimal): ``share`` in 1.1-1.3, ``count`` of points whose larger sigma prints
    >= 1.5, ``max`` the largest."""
    larger = np.maximum(sig_um[..., 0], sig_um[..., 1])  # per point (exact: a max)
    return {
        "share": ((sig_um >= 1.05) & (sig_um < 1.35)).mean(axis=(-1, -2)),
        "count": (larger >= 1.45).sum(-1).astype(float),
        "max": larger.max(-1),
    }


def table1_statement_evidence(cof: np.ndarray, s0_um: np.ndarray) -> dict[str, np.ndarray]:
    """The evidence of :data:`TABLE1`'s four point-sigma statements at ``N`` input vectors,
    by statement id, from the cofactors ``(N, 25, 2)`` (:func:`table1_cofactors`) and sigma0
    ``(N,)`` (um): the 50 sigmas as printed (:func:`table1_sigma_stats`), and every sigma /
    sigma0 for "somewhat smaller than the rms error of closure"."""
    st = table1_sigma_stats(np.asarray(s0_um, float)[:, None, None] * cof)
    return {
        _T1 + "share_1p1_1p3": st["share"],
        _T1 + "points_ge_1p45": st["count"],
        _T1 + "max_um": st["max"],
        _T1 + "below_closure": cof.reshape(len(cof), -1),
    }


def grid_of_extent(k: int, half_extent_mm) -> np.ndarray:
    """k x k grids reaching +-half_extent_mm ``(G, k*k, 2)``."""
    e = np.atleast_1d(np.asarray(half_extent_mm, float))
    return grid_points(k, 2.0 / (k - 1))[None] * e[:, None, None]


def max_range_mm(P: np.ndarray, TH: np.ndarray) -> np.ndarray:
    """The longest range of each geometry ``(G,)`` (points ``(G, n, 2)``, globals ``(G, 7)``)."""
    return ml.ranges(P, TH).max(axis=(1, 2))


def min_range_mm(P: np.ndarray, TH: np.ndarray) -> np.ndarray:
    return ml.ranges(P, TH).min(axis=(1, 2))


def feasible(P: np.ndarray, TH: np.ndarray) -> np.ndarray:
    """True where every range reads on the scale plus micrometer (0 to 262 mm)."""
    return (min_range_mm(P, TH) >= 0) & (max_range_mm(P, TH) <= REACH_MM)


def max_offset_mm(half_extent_mm, beta_mm=0.0, alpha_mm: float = ALPHA_MM) -> np.ndarray:
    """Largest station offset at which every range of a grid reaching +-half_extent_mm reads:
    the farthest point from station 1 (0, h) is (+-e, -e), r = sqrt(e^2 + (h + e)^2 - beta^2)
    - alpha <= 262 mm. NaN where no offset >= 0 reads (the scale is too short)."""
    e = np.asarray(half_extent_mm, float)
    d2 = (REACH_MM + alpha_mm) ** 2 + np.asarray(beta_mm, float) ** 2 - e**2
    with np.errstate(invalid="ignore"):
        o = np.sqrt(d2) - e - FORMAT_MM / 2
    return np.where((d2 > 0) & (o >= 0), o, np.nan)
