"""Simulation of ``salsig_encoders`` (seed ``002_fb81c7b0481438c4.txt``).

* :func:`decompositions` -- the column decomposition ``SX, SY, E`` of the printed parameters
  A-F of FIG. 2 and FIG. 3 (exact), with the range the 9-decimal rounding of A-F allows.
* :func:`simulate_chain` -- 25 steel-point marks tapped with the B8S (readings in digits),
  measured on a comparator together with 25 grid intersections; affine comparator -> grid
  (FIG. 2) and B8 -> grid (FIG. 3); recovered ``SX, SY, E`` and their detectability.
* :func:`simulate_zscale` -- the z encoder: ``H = S z + z0`` from the glass-scale elevations.
* :func:`simulate_vertical` -- stereomodels digitised with z at 12.5 against x, y at 12.7
  mm/digit, fitted to control by a 3-D conformal transformation, before and after the
  12.500/12.700 correction.

Chunk functions are module-level (bind the config with functools.partial: they pickle).
Model/grid coordinates in mm, B8 readings in digits, errors in um.
"""

from __future__ import annotations

import numpy as np

from sim.instruments import encoders as enc
from sim.instruments import transforms2d as t2
from sim.instruments.plates import grid_points
from sim.lsq import distributions as D
from sim.studies.salsig.printed import FIG2, FIG2_PRINTED, FIG3, FIG3_PRINTED
from sim.studies.salsig.schema import UM


def b8_truth(cfg: dict) -> np.ndarray:
    """True affine B8 digits -> model mm (x axis along model x), (6,)."""
    return t2.affine_from_columns(
        cfg["b8.sx_mm_per_digit"],
        cfg["b8.sy_mm_per_digit"],
        cfg["b8.e_arcsec"] * t2.ARCSEC,
        0.0,
        (0.0, 0.0),
    )


def _marks(cfg: dict, rng: np.random.Generator, n: int, k: int, sb8: float):
    """The marks (model mm, ``k x k`` nominal array plus placement scatter) and their B8
    readings (digits: the inverse of the true B8 affine of the marks plus the marking error
    ``sb8`` mm)."""
    nom = grid_points(k, cfg["marks.extent_mm"] / (k - 1))
    M = nom.shape[0]
    marks = nom + rng.normal(0.0, cfg["marks.placement_sd_mm"], (n, M, 2))  # model mm
    b8_inv = t2.invert_affine(b8_truth(cfg))
    b8_read = t2.apply_affine(
        np.broadcast_to(b8_inv, (n, 6)), marks + rng.normal(0.0, sb8, (n, M, 2))
    )  # digits
    return marks, b8_read


def _comparator(cfg: dict, rng: np.random.Generator, n: int, marks: np.ndarray):
    """The film laid on the grid at a random small rotation and offset, and the comparator's
    readings of the grid intersections and the marks through its FIG. 2-like affine with
    ``comparator.sigma_um``. Returns the grid (mm) and the two sets of readings."""
    sc = cfg["comparator.sigma_um"] * UM
    M = marks.shape[1]
    # film on the grid: rotation and offset of the film (model) frame in the grid frame
    rot = rng.uniform(-2, 2, n) * np.pi / 180
    off = rng.uniform(-10, 10, (n, 2))
    c, s = np.cos(rot), np.sin(rot)
    film2grid = np.stack([c, -s, off[:, 0], s, c, off[:, 1]], -1)
    marks_grid_true = t2.apply_affine(film2grid, marks)
    G = grid_points(cfg["grid.points"], cfg["grid.spacing_mm"])
    # comparator: grid frame -> comparator readings through the FIG. 2-like affine (inverse)
    cg = t2.affine_from_columns(
        cfg["comparator.sx"],
        cfg["comparator.sy"],
        cfg["comparator.e_arcsec"] * t2.ARCSEC,
        rng.uniform(-1, 1, n) * np.pi / 180,
        (rng.uniform(-120, -110, n), rng.uniform(-120, -110, n)),
    )
    g2c = t2.invert_affine(cg)
    comp_grid = t2.apply_affine(g2c, G) + rng.normal(0.0, sc, (n, G.shape[0], 2))
    comp_marks = t2.apply_affine(g2c, marks_grid_true) + rng.normal(0.0, sc, (n, M, 2))
    return G, comp_grid, comp_marks


def _recovered(cfg: dict, f2, f3) -> tuple[dict[str, np.ndarray], dict]:
    """SX, SY, E of the B8 from the FIG. 3 fit ``f3``, their sds, SX - SY (ppm), whether E and
    SX - SY differ from zero at ``analysis.alpha``, and both fits' unit-weight errors; and
    the decomposition itself."""
    d3 = t2.inverse_decomposition(f3.params, f3.cov)
    sd = np.sqrt(np.einsum("tii->ti", d3["cov"]))
    diff = d3["SX"] - d3["SY"]
    sd_diff = np.sqrt(d3["cov"][:, 0, 0] + d3["cov"][:, 1, 1] - 2 * d3["cov"][:, 0, 1])
    zc = D.norm_ppf(1 - cfg["analysis.alpha"] / 2)
    return {
        "SX": d3["SX"],
        "SY": d3["SY"],
        "E_arcsec": d3["E"] / t2.ARCSEC,
        "sd_SX": sd[:, 0],
        "sd_SY": sd[:, 1],
        "sd_E_arcsec": sd[:, 2] / t2.ARCSEC,
        "scale_diff_ppm": diff / d3["SX"] * 1e6,
        "sd_scale_diff_ppm": sd_diff / d3["SX"] * 1e6,
        "detect_E": np.abs(d3["E"]) > zc * sd[:, 2],
        "detect_scale": np.abs(diff) > zc * sd_diff,
        "s0_fig2_mm": f2.s0,
        "s0_fig3_digits": f3.s0,
    }, d3


def simulate_chain(
    cfg: dict,
    rng: np.random.Generator,
    n: int,
    k_marks: int | None = None,
    sigma_b8_um: float | None = None,
    return_all: bool = False,
):
    """Simulate ``n`` calibrations and reduce them as the paper does.

    Marks: ``k x k`` nominal array over ``marks.extent_mm`` plus placement scatter (model
    mm). B8 readings (digits) = inverse of the true B8 affine applied to the marks, plus the
    marking error. The film is laid on the comparator at a random small rotation and offset
    relative to the grid plate; the comparator measures the marks and the grid intersections
    through its own (FIG. 2-like) affine, with ``comparator.sigma_um``.

    Returns per-trial arrays (and with ``return_all`` the intermediate coordinates).
    """
    k = cfg["marks.grid"] if k_marks is None else k_marks
    sb8 = (cfg["b8.sigma_um"] if sigma_b8_um is None else sigma_b8_um) * UM
    marks, b8_read = _marks(cfg, rng, n, k, sb8)
    G, comp_grid, comp_marks = _comparator(cfg, rng, n, marks)
    # FIG. 2: comparator (X2, observed) as a function of the grid (X1, control)
    f2 = t2.fit_affine(G, comp_grid)
    p2 = t2.invert_affine(f2.params)  # X1 = A X2 + B Y2 + C
    marks_grid = t2.apply_affine(p2, comp_marks)  # FIG. 2 "transformed points"
    # FIG. 3: B8 (X2, observed) as a function of the grid-system marks (X1, control)
    f3 = t2.fit_affine(marks_grid, b8_read)
    out, d3 = _recovered(cfg, f2, f3)
    if return_all:
        out.update(
            {
                "marks_grid": marks_grid,
                "b8_read": b8_read,
                "res3": f3.residuals,
                "grid": G,
                "comp_grid": comp_grid,
                "res2": f2.residuals,
                "p3": d3["params"],
            }
        )
    return out


def chain_chunk(cfg: dict, k_marks, sigma_b8_um, rng: np.random.Generator, n: int) -> dict:
    return simulate_chain(cfg, rng, n, k_marks, sigma_b8_um)


# ----------------------------------------------------------------------------- z encoder


def simulate_zscale(cfg: dict, rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    """Nine glass-scale elevations H (mm) and z readings (digits) with a setting error."""
    m = cfg["zscale.points"]
    H = np.linspace(0.0, cfg["zscale.range_mm"], m) + 150.0
    S = cfg["zscale.s_mm_per_digit"]
    z0 = -37.0
    z = (H - z0 + rng.normal(0.0, cfg["zscale.sigma_um"] * UM, (n, m))) / S
    f = enc.line_fit(z, np.broadcast_to(H, (n, m)))
    return {"S": f["S"], "se_S": f["se_S"], "z0": f["z0"], "se_z0": f["se_z0"], "s0_mm": f["s0"]}


# ----------------------------------------------------------------------------- vertical


def simulate_vertical(
    cfg: dict, rng: np.random.Generator, n: int, relief_mm: float | None = None
) -> dict[str, np.ndarray]:
    """Stereomodels fitted to control by a 3-D conformal transformation.

    True model points: ``vertical.control`` points spread over the model area, heights = a
    random plane plus relief of rms ``relief_mm``. The B8 digitises x, y at SX, SY with the
    non-perpendicularity E and z at ``zscale.s_mm_per_digit``; the digitiser converts all
    three with one factor (the x scale), so z is stretched by SX/Sz. Control = a random
    similarity of the true model (scale 10, i.e. ground metres for a 1:10 000 model) with
    errors. Vertical residual rms before and after multiplying z by Sz/SX (12.500/12.700).
    """
    relief = cfg["vertical.relief_mm"] if relief_mm is None else relief_mm
    m = cfg["vertical.control"]
    h = cfg["vertical.extent_mm"] / 2
    xy = rng.uniform(-h, h, (n, m, 2))
    plane = rng.normal(0.0, 0.02, (n, 2))
    zr = rng.normal(0.0, 1.0, (n, m))
    zr -= zr.mean(1, keepdims=True)
    zr *= relief / np.sqrt(np.maximum((zr**2).mean(1, keepdims=True), 1e-300))
    z = 200.0 + np.einsum("tmk,tk->tm", xy, plane) + zr
    true = np.concatenate([xy, z[..., None]], -1)  # model mm
    sxy, sz = cfg["vertical.sigma_xy_um"] * UM, cfg["vertical.sigma_z_um"] * UM
    meas = true + rng.normal(0.0, 1.0, true.shape) * np.array([sxy, sxy, sz])
    # digitise: x, y through the B8 affine, z through the z encoder
    b8_inv = t2.invert_affine(b8_truth(cfg))
    dig_xy = t2.apply_affine(np.broadcast_to(b8_inv, (n, 6)), meas[..., :2])
    dig_z = meas[..., 2] / cfg["zscale.s_mm_per_digit"]
    fac = cfg["b8.sx_mm_per_digit"]
    before = np.concatenate([dig_xy * fac, (dig_z * fac)[..., None]], -1)
    after = before.copy()
    after[..., 2] *= cfg["zscale.s_mm_per_digit"] / fac
    # ground control: similarity of the truth (scale 10 m per model mm) -- errors are in meas
    lam = 10.0
    R = enc.rotation_matrix(
        rng.normal(0, 0.02, n), rng.normal(0, 0.02, n), rng.uniform(-np.pi, np.pi, n)
    )
    ground = lam * np.einsum("tij,tnj->tni", R, true) + rng.uniform(-1e3, 1e3, (n, 1, 3))
    out = {}
    for tag, X in (("before", before), ("after", after)):
        f = enc.conformal3d_fit(X, ground)
        out[f"rms_z_{tag}_um"] = np.sqrt((f["residuals"][..., 2] ** 2).mean(1)) / lam / UM
        out[f"rms_xy_{tag}_um"] = np.sqrt((f["residuals"][..., :2] ** 2).mean((1, 2))) / lam / UM
    out["ratio"] = out["rms_z_after_um"] / out["rms_z_before_um"]
    return out


def vertical_chunk(cfg: dict, relief_mm, rng: np.random.Generator, n: int) -> dict:
    return simulate_vertical(cfg, rng, n, relief_mm)


def decompositions() -> dict:
    """The printed FIG. 2 / FIG. 3 parameters decomposed, with the range the 9-decimal
    rounding of A-F allows (interval arithmetic by corner enumeration)."""
    rows = {"figure": [], "quantity": [], "value": [], "lo": [], "hi": [], "printed": []}
    for fig, params, printed in (("FIG. 2", FIG2, FIG2_PRINTED), ("FIG. 3", FIG3, FIG3_PRINTED)):
        p = np.asarray(params)
        corners = np.array(np.meshgrid(*([[-0.5e-9, 0.5e-9]] * 4), indexing="ij")).reshape(4, -1).T
        P = np.broadcast_to(p, (corners.shape[0], 6)).copy()
        P[:, [0, 1, 3, 4]] += corners
        d0, dc = t2.decompose_columns(p), t2.decompose_columns(P)
        for q, conv, pr in (
            ("SX", 1.0, printed[0]),
            ("SY", 1.0, printed[1]),
            ("E_arcsec", 1 / t2.ARCSEC, printed[2]),
        ):
            key = "E" if q == "E_arcsec" else q
            rows["figure"].append(fig)
            rows["quantity"].append(q)
            rows["value"].append(float(d0[key] * conv))
            rows["lo"].append(float(dc[key].min() * conv))
            rows["hi"].append(float(dc[key].max() * conv))
            rows["printed"].append(pr)
    return rows
