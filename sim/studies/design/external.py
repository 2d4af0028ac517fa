"""The paper's tolerances and external comparisons as functions of its unprinted inputs
(seed ``004``, *Operation*, *Calibration*, *Results*).

Linearised and cheap, so each can be evaluated at every swept value of an input the paper
does not print (the station offset, beta, the screw pitch, the layout of the Zeiss grid's 33
calibrated points):

* tolerances: a lateral offset ``d`` of the image from the scale's radial line costs
  ``d^2 / (2 r)`` of range at range ``r`` (worst case: the shortest range of the plate); so a
  1 um accuracy tolerates ``d = sqrt(2 r_min x 1 um)`` of microscope non-linearity; a tilt of
  the microscope axis by ``t`` across the gap ``g`` between scale and plate shifts the reading
  by ``g tan t``; a drum graduation error of ``a`` arc seconds is ``a / 1296000`` of the pitch.
* one plate's rms coordinate error after a translation and rotation (the paper's external
  comparisons): Gaussian plates ``N(0, S F S^T sigma^2)`` with ``F`` the pivot model's
  cofactor (:func:`sim.instruments.ranges.positions.full_point_covariance`), ``S`` the rigid-fit projector and
  ``sigma`` the range sigma (Table 1's model: double settings of 1.7 um and 1.1 um of random
  comparator error); the Zeiss comparison adds the grid's 0.8 um per coordinate. The plates
  are drawn as ``z R`` with ``R`` the symmetric square root of ``S F S^T`` (unique, and a
  continuous function of ``F``). Drawn along its eigenvectors instead, as before, a plate
  turned with the last bits of ``F`` within the repeated eigenvalues of the symmetric grid:
  another BLAS kernel redrew the plates and moved the spread of the plates' rms by a percent
  (issue 27). The rigid fit's three null eigenvalues (rounding, about 1e-17 of the largest)
  are set to zero; the smallest real one is about 4e-2 of the largest.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.plates import grid_points
from sim.instruments.ranges import positions as po
from sim.lsq import datum as dm
from sim.mc.runner import chunk_rng

__all__ = [
    "shortest_range_mm",
    "tolerances",
    "plate_rms",
    "zeiss_points",
    "external_at",
    "paper_points",
]


def paper_points(cfg: dict) -> np.ndarray:
    return grid_points(cfg["paper.grid"], 2 * cfg["paper.extent_mm"] / (cfg["paper.grid"] - 1))


def _theta(cfg, offset, beta, P=None):
    return po.design_theta(
        P or cfg["paper.positions"],
        cfg["plate.format_mm"] / 2 + offset,
        cfg["comparator.alpha_mm"],
        beta,
    )


def shortest_range_mm(cfg: dict, pts: np.ndarray, offset: float, beta: float) -> float:
    return float(po.ranges(pts[None], _theta(cfg, offset, beta)[None]).min())


def longest_range_mm(cfg: dict, pts: np.ndarray, offset: float, beta: float) -> float:
    return float(po.ranges(pts[None], _theta(cfg, offset, beta)[None]).max())


def tolerances(cfg: dict, r_min_mm: float, pitch_mm: float) -> dict:
    """Analytic tolerances (see the module doc): lateral-offset error (um), linearity
    tolerance (um), axis tilt tolerance (degrees), drum graduation error (um)."""
    d = cfg["operation.lateral_offset_um"] * 1e-3
    acc = cfg["calibration.accuracy_um"] * 1e-3
    return {
        "lateral_error_um": d**2 / (2 * r_min_mm) * 1e3,
        "linearity_tol_um": np.sqrt(2 * r_min_mm * acc) * 1e3,
        "axis_tilt_deg": float(
            np.degrees(np.arctan(cfg["calibration.accuracy_um"] / cfg["operation.gap_um"]))
        ),
        "drum_graduation_um": cfg["calibration.drum_dividing_arcsec"] / 1296000.0 * pitch_mm * 1e3,
    }


def zeiss_points(cfg: dict, half_extent_mm: float) -> np.ndarray:
    """Stand-in for the Zeiss grid's 33 calibrated intersections (layout not printed):
    ``zeiss.points`` distinct 1 cm lattice intersections within +-``half_extent_mm``, drawn
    once from ``zeiss.layout_seed`` (the same permutation stream for every extent), never from
    the run's ``seed``: a layout is a design, and ``--seed`` or a sweep's cells (each its own
    seed) drew another one, so a sweep over an error compared other layouts."""
    m = int(half_extent_mm // 10)
    ax = np.arange(-m, m + 1) * 10.0
    lat = np.stack(np.meshgrid(ax, ax, indexing="ij"), -1).reshape(-1, 2)
    order = chunk_rng(cfg["zeiss.layout_seed"], 90, 0).permutation(len(lat))
    return lat[np.sort(order[: cfg["zeiss.points"]])]


#: eigenvalues of ``S F S^T`` below this share of the largest are the rigid fit's null space
NULL_EIGENVALUE = 1e-9


def range_sigma_um(cfg: dict) -> float:
    """Table 1's model: the mean of the paper's settings plus the random comparator error."""
    return float(
        np.sqrt(
            cfg["paper.setting_sigma_um"] ** 2 / cfg["paper.settings"]
            + cfg["comparator.sigma_um"] ** 2
        )
    )


def plate_rms(
    cfg: dict, pts: np.ndarray, offset: float, beta: float, sr_um: float, extra_um: float, part: int
) -> tuple[np.ndarray, np.ndarray]:
    """rms coordinate error (um) of ``unprinted.plates`` Gaussian plates after a rigid fit over
    all points: without and with ``extra_um`` of independent per-coordinate error (a reference
    grid's) added before the fit."""
    th = _theta(cfg, offset, beta)
    with np.errstate(invalid="ignore"):  # the dense reference route of the engine
        F = po.full_point_covariance(pts[None], th[None], "pivot", "inner", dense=True)[0]
    S = dm.s_matrix(dm.null_basis(pts))
    C = S @ F @ S.T * sr_um**2
    w, V = np.linalg.eigh((C + C.T) / 2)
    w = np.where(w > NULL_EIGENVALUE * w.max(), w, 0.0)  # the rigid fit's null space: zero
    R = (V * np.sqrt(w)) @ V.T  # symmetric square root: does not turn with F's last bits
    rng = chunk_rng(cfg["seed"], part, 0)
    z = rng.standard_normal((cfg["unprinted.plates"], len(w)))
    e = z @ R
    g = e + rng.normal(0.0, extra_um, e.shape) @ S.T
    return np.sqrt((e**2).mean(1)), np.sqrt((g**2).mean(1))


def external_at(
    cfg: dict,
    offset: float,
    beta: float,
    zeiss_extent: float,
    pitch: float,
    plates: bool = True,
    two_screw_um: float | None = None,
    sigma0_um: float | None = None,
) -> dict:
    """Every linearised claim value at one setting of the unprinted inputs (``plates=False``:
    the tolerances only). Plates use fixed streams (parts 91, 92), so a sweep compares like
    with like. ``two_screw_um``: the conventional two-screw comparator's error per coordinate
    (not printed), added to the plate before the rigid fit; ``None`` (the labelled example)
    takes the paper's equal attribution, sqrt(2) x the plate's rms. ``sigma0_um``: the range
    sigma of the plates (um), the plate's closure at a point of the region (Table 1's sigma0);
    ``None`` (the labelled example) takes :func:`range_sigma_um`, Table 1's error model."""
    pts = paper_points(cfg)
    sr = range_sigma_um(cfg) if sigma0_um is None else float(sigma0_um)
    r_min = shortest_range_mm(cfg, pts, offset, beta)
    out = {
        "r_min_mm": r_min,
        "r_max_mm": longest_range_mm(cfg, pts, offset, beta),
        **tolerances(cfg, r_min, pitch),
    }
    out["feasible"] = out["r_max_mm"] <= cfg["scale.graduated_mm"] + cfg["scale.micrometer_mm"]
    zp = zeiss_points(cfg, zeiss_extent)
    zr = longest_range_mm(cfg, zp, offset, beta)
    out["zeiss_feasible"] = zr <= cfg["scale.graduated_mm"] + cfg["scale.micrometer_mm"]
    if plates:
        out["table1_rms"], mixed = plate_rms(cfg, pts, offset, beta, sr, two_screw_um or 0.0, 91)
        out["zeiss_comparator_rms"], out["zeiss_rms"] = plate_rms(
            cfg, zp, offset, beta, sr, cfg["zeiss.grid_sigma_um"], 92
        )
        equal = two_screw_um is None  # the paper's equal attribution (the labelled example)
        out["two_screw_rms"] = np.sqrt(2) * out["table1_rms"] if equal else mixed
    return out
