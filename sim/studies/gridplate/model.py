"""Simulation and per-chunk reduction of ``gridplate_two_plates`` (seed 001).

A PSK-like comparator with a small difference of its x and y scales and a small
non-orthogonality measures ``P`` grid plates (k x k points, a slight kappa rotation each),
``L`` readings per point. Each trial reproduces the paper's reduction: precision from the
repeated readings, similarity and affine fits with the grid taken as error-free, the combined
adjustment with the grid coordinates as weighted observations (x' and y' apart), the
chi-square test of the grid variance implied by the weights and the re-weighting of
``P_x : P_cx``. Coordinates in mm, errors reported in um.

Speed: the combined adjustment of one comparator row with ``P_x = 1`` and ``P_cx = r`` on
equally weighted points is, to first order, the affine least-squares fit with the misclosure
cofactor ``(1 + k/r)``, ``k = A^2 + B^2`` (Gauss-Helmert form): ``s0^2 = s_w^2 / (1 + k/r)``,
``Q_r = (1 + k/r) Q_affine``, where ``s_w^2`` is the affine fit's residual variance of the row.
So the weight-ratio and stated-sigma sweeps are evaluated from ONE affine fit per plate; the
iterated combined adjustment (:func:`sim.instruments.gridplate.reweight`) runs once per plate (the paper's
procedure, and the check of the closed form: ``closed_form_rel``), and its Gauss-Newton
iterations are counted on ``analysis.iter_sample`` adjustments per chunk.
"""

from __future__ import annotations

import numpy as np

from sim.instruments import gridplate as gp
from sim.instruments import transforms2d as t2
from sim.lsq import distributions as D
from sim.studies.gridplate.schema import UM

PARAMS = ("S", "S2", "eps")
PARAM_LABEL = {"S": "S", "S2": "S'", "eps": "eps"}
MAX_TRIALS = 10  # re-weighting trials counted at most


def truth_rows(cfg: dict):
    """The comparator's true ``S, S', eps`` (seed 001 convention, grid -> comparator)."""
    d = cfg["comparator.scale_diff_ppm"] * 1e-6
    return 1.0 - d / 2, 1.0 + d / 2, cfg["comparator.nonorth_arcsec"] * t2.ARCSEC


def simulate(cfg: dict, rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    """Readings and grid certificates of ``n`` calibrations
    (:func:`sim.instruments.gridplate.simulate_calibrations` with this study's config).

    Returns ``readings`` (n, P, N, L, 2) mm, ``cert`` (n, P, N, 2) mm (the grid coordinates
    as given), ``true`` (n, P, 6) the true affine grid -> comparator of each plate.
    """
    return gp.simulate_calibrations(rng, n, **calibration_args(cfg))


def calibration_args(cfg: dict) -> dict:
    """The keyword arguments of :func:`sim.instruments.gridplate.simulate_calibrations`."""
    return dict(
        grid=cfg["plate.grid"],
        spacing_mm=cfg["plate.spacing_mm"],
        plates=cfg["plate.count"],
        readings=cfg["readings.count"],
        scale_diff_ppm=cfg["comparator.scale_diff_ppm"],
        nonorth_arcsec=cfg["comparator.nonorth_arcsec"],
        kappa_deg=cfg["plate.kappa_deg"],
        reading_sigma_um=cfg["readings.sigma_um"],
        coord_sigma_um=cfg["comparator.coord_sigma_um"],
        grid_sigma_um=cfg["grid.sigma_true_um"],
    )


def _decomp_errors(p, cov, S, S2, eps):
    d = t2.decompose_rows(p, cov)
    err = np.stack([d["S"] - S, d["S2"] - S2, t2._wrap(d["eps"] - eps)], -1)
    sd = np.sqrt(np.einsum("tii->ti", d["cov"]))
    return err, sd


def reweight_trials(
    sw2: np.ndarray, k: np.ndarray, stated: float, dof: int, start: float, alpha: float
) -> np.ndarray:
    """The paper's re-weighting, literally: adjust at ``P_cx = start`` (``P_x = 1``); while the
    chi-square test of the implied grid variance ``s0^2 / P_cx`` against ``stated^2`` rejects,
    set ``P_cx <- s0^2 / stated^2`` and adjust again. Returns the number of re-weightings
    (0: the first adjustment passed; ``MAX_TRIALS``: never passed). Closed form per
    adjustment: ``s0^2 = s_w^2 / (1 + k / P_cx)``."""
    lo, hi = D.chi2_ppf(alpha / 2, dof), D.chi2_ppf(1 - alpha / 2, dof)
    r = np.full(sw2.shape, float(start))
    count = np.zeros(sw2.shape, int)
    done = np.zeros(sw2.shape, bool)
    for _ in range(MAX_TRIALS):
        s02 = sw2 / (1.0 + k / r)
        x = dof * (s02 / r) / stated**2
        done |= (x >= lo) & (x <= hi)
        r = np.where(done, r, s02 / stated**2)
        count += ~done
    return count


def iterations(comp: np.ndarray, g: np.ndarray, ratio: np.ndarray, tol_mm: float) -> np.ndarray:
    """Gauss-Newton iterations of the combined adjustment until the correction is negligible.

    The adjustment starts, as :func:`sim.instruments.gridplate.combined_adjustment` does, from the affine
    fit with the grid fixed; iteration ``j`` is the ``j``-th solve of the combined normals.
    Counted: the first ``j`` whose largest correction (parameters mapped to the grid's
    coordinates, and adjusted grid coordinates) is below ``tol_mm``; the iteration that shows
    the convergence counts, as in the paper's program. At most 6."""
    ext = np.abs(g).max(axis=(1, 2)) + 1.0
    prev_p = prev_u = None
    count = np.full(comp.shape[0], 6)
    for j in range(1, 7):
        r = gp.combined_adjustment(comp, g, 1.0, ratio, max_iter=j, tol=0.0)
        if prev_p is not None:
            dp = np.abs(r.params - prev_p)
            corr = np.maximum(
                (dp[:, :2].max(1)) * ext + dp[:, 2], np.abs(r.grid - prev_u).max((1, 2))
            )
            count = np.where((count == 6) & (corr < tol_mm), j, count)
        prev_p, prev_u = r.params, r.grid
        if np.all(count < 6):
            break
    return count


def row_misclosure(fa, N: int) -> tuple[np.ndarray, np.ndarray]:
    """Per row (x', y') of each plate of the affine fit ``fa`` with the grid fixed: the
    misclosure variance ``s_w^2`` (mm^2) and ``k = A^2 + B^2``, both ``(nP, 2)``."""
    sw2 = np.stack([(fa.residuals[..., c] ** 2).sum(1) / (N - 3) for c in (0, 1)], 1)
    kk = np.stack(
        [fa.params[:, 0] ** 2 + fa.params[:, 1] ** 2, fa.params[:, 3] ** 2 + fa.params[:, 4] ** 2],
        1,
    )
    return sw2, kk


def _rowscale(x: np.ndarray) -> np.ndarray:
    """A per-row factor ``(nP, 2)`` as the ``(nP, 6, 6)`` block scaling of an affine
    cofactor matrix (rows x' and y' of the affine, three parameters each)."""
    f = np.repeat(x, 3, axis=1)
    return np.sqrt(f[:, :, None] * f[:, None, :]) * (
        np.arange(6)[:, None] // 3 == np.arange(6) // 3
    )


def _fixed_grid(cfg: dict, fa, n: int, P: int) -> dict[str, np.ndarray]:
    """The affine fit with the grid fixed: errors of S, S', eps, coverage and stated sd with
    the a-priori comparator sigma (``fixed_pri``) and the a-posteriori s0 (``fixed_post``)."""
    sx = cfg["comparator.coord_sigma_um"] * UM  # a-priori comparator sigma
    z = D.norm_ppf(0.975)
    out: dict[str, np.ndarray] = {}
    for tag, cov in (("fixed_pri", fa.cofactor * sx**2), ("fixed_post", fa.cov)):
        err, sd = _decomp_errors(fa.params, cov, *truth_rows(cfg))
        for i, k in enumerate(PARAMS):
            out[f"{k}_err_{tag}"] = err[:, i].reshape(n, P)
            out[f"{k}_cov_{tag}"] = (np.abs(err[:, i]) <= z * sd[:, i]).reshape(n, P)
            out[f"{k}_sd_{tag}"] = sd[:, i].reshape(n, P)
    return out


def _weight_ratios(cfg: dict, fa, sw2: np.ndarray, kk: np.ndarray, n: int, P: int) -> dict:
    """The weightings in closed form: the grid sigma implied by the paper's 1:2 and 1:3 and
    by every swept ratio (um), and the coverage of S, S', eps at each swept ratio (a-priori
    and a-posteriori sigma; the a-priori stated sd)."""
    sx = cfg["comparator.coord_sigma_um"] * UM
    z = D.norm_ppf(0.975)
    out: dict[str, np.ndarray] = {}
    for r in (2, 3):  # the paper's two printed weightings
        out[f"grid_sigma_1to{r}_um"] = np.sqrt((sw2 / (r + kk)).reshape(n, 2 * P).mean(1)) / UM
    for j, r in enumerate(cfg["analysis.ratios"]):
        f = 1.0 + kk / r
        out[f"implied_grid_um_r{j}"] = np.sqrt((sw2 / (r + kk)).reshape(n, 2 * P).mean(1)) / UM
        for tag, scale in (("pri", sx**2 * f), ("post", sw2)):
            err, sd = _decomp_errors(fa.params, fa.cofactor * _rowscale(scale), *truth_rows(cfg))
            for i, k in enumerate(PARAMS):
                out[f"{k}_cov_w{tag}_r{j}"] = (np.abs(err[:, i]) <= z * sd[:, i]).reshape(n, P)
                if tag == "pri":
                    out[f"{k}_sd_w_r{j}"] = sd[:, i].reshape(n, P)
    return out


def _chi2_rejections(cfg: dict, sw2: np.ndarray, kk: np.ndarray, N: int, n: int, P: int) -> dict:
    """The chi-square test with a-priori weights ``P_x = 1/sx^2``, ``P_cx = 1/stated^2``
    (closed form), per stated grid sigma: rejected or not, per row and plate."""
    sx = cfg["comparator.coord_sigma_um"] * UM
    alpha, dof = cfg["analysis.alpha"], N - 3
    lo, hi = D.chi2_ppf(alpha / 2, dof), D.chi2_ppf(1 - alpha / 2, dof)
    out = {}
    for j, st in enumerate(cfg["analysis.stated_sigmas_um"]):
        s02 = sw2 / (sx**2 + kk * (st * UM) ** 2)
        x = dof * s02
        out[f"reject_s{j}"] = ((x < lo) | (x > hi)).reshape(n, 2 * P)
    return out


def _reweighting(cfg: dict, sw2: np.ndarray, kk: np.ndarray, N: int, n: int, P: int):
    """The paper's re-weighting at its fixed point (closed form): ``P_cx = s_w^2/sg^2 - k``,
    ``s0^2 = s_w^2 - k sg^2`` (the comparator variance), NaN where no positive fixed point;
    and the number of re-weightings of the literal procedure. Returns the arrays and the
    closed-form ratio per row (for the check against the iterated adjustment)."""
    sg = cfg["grid.sigma_stated_um"] * UM
    closed = sw2 / sg**2 - kk
    ok = closed > 0
    ratio = np.where(ok, closed, np.nan)
    okn = ok.reshape(n, 2 * P).all(1)
    s0sq = np.where(ok, sw2 - kk * sg**2, np.nan).reshape(n, 2 * P)
    out = {
        "ratio_rw": ratio.reshape(n, 2 * P),
        "comp_sigma_um": (
            np.where(okn, np.sqrt(np.where(okn[:, None], s0sq, 1.0).mean(1)), np.nan) / UM
        ),
        "ratio_rw_mean": np.where(
            okn, np.where(okn[:, None], ratio.reshape(n, 2 * P), 1.0).mean(1), np.nan
        ),
        "rw_trials": reweight_trials(
            sw2, kk, sg, N - 3, cfg["analysis.ratio_start"], cfg["analysis.alpha"]
        ).reshape(n, 2 * P),
    }
    return out, closed


def _iterated(cfg: dict, mean: np.ndarray, g: np.ndarray, closed: np.ndarray) -> dict:
    """The iterated combined adjustment (:func:`sim.instruments.gridplate.reweight`) on a
    sample of adjustments: check of the closed form (``closed_form_ok``: both methods found a
    positive fixed point and their ratios are compared; ``closed_form_one``: only one of them
    found one), pass rate after re-weighting, Gauss-Newton iterations."""
    sg = cfg["grid.sigma_stated_um"] * UM
    comp2 = np.concatenate([mean[..., 0], mean[..., 1]], 0)[: cfg["analysis.iter_sample"]]
    g2 = np.concatenate([g, g], 0)[: cfg["analysis.iter_sample"]]
    m = comp2.shape[0]
    start = cfg["analysis.ratio_start"]
    rw = gp.reweight(comp2, g2, sg, ratio0=float(start), alpha=cfg["analysis.alpha"])
    cf = np.concatenate([closed[:, 0], closed[:, 1]])[:m]
    found = np.isfinite(rw["ratio"])
    good = found & (cf > 0)  # both found a positive fixed point: their ratios compared
    one = found != (cf > 0)  # one method found a fixed point, the other none: they disagree
    r_it = np.where(found, rw["ratio"], start)
    rel = np.abs(np.where(good, rw["ratio"] / np.where(good, cf, 1.0) - 1, 0.0))
    return {  # a disagreement is a relative difference of 1 (a ratio against none)
        "closed_form_rel": np.where(one, 1.0, rel),
        "closed_form_ok": good,
        "closed_form_one": one,
        "passes_rw": rw["passes"],
        "gn_iterations": iterations(comp2, g2, r_it, cfg["analysis.iter_tol_um"] * UM),
    }


def reduce_chunk(cfg: dict, sim: dict) -> dict[str, np.ndarray]:
    """The paper's reduction (and the coverage sweep) for the simulated calibrations: the
    precision of the readings, similarity and affine fits with the grid fixed, the weightings
    and the chi-square test in closed form, the re-weighting and the iterated adjustment."""
    readings, cert = sim["readings"], sim["cert"]
    n, P, N, L, _ = readings.shape
    _, sigma_obs = gp.repeat_precision(readings)
    mean = readings.mean(axis=3).reshape(n * P, N, 2)
    g = cert.reshape(n * P, N, 2)
    out: dict[str, np.ndarray] = {"sigma_obs_um": sigma_obs / UM}
    fs = t2.fit_similarity(g, mean)
    fa = t2.fit_affine(g, mean)
    out["sim_sigma_um"] = np.sqrt((fs.s0**2).reshape(n, P).mean(1)) / UM
    out["aff_sigma_um"] = np.sqrt((fa.s0**2).reshape(n, P).mean(1)) / UM
    sw2, kk = row_misclosure(fa, N)
    out |= _fixed_grid(cfg, fa, n, P)
    out |= _weight_ratios(cfg, fa, sw2, kk, n, P)
    out |= _chi2_rejections(cfg, sw2, kk, N, n, P)
    rw, closed = _reweighting(cfg, sw2, kk, N, n, P)
    out |= rw
    out |= _iterated(cfg, mean, g, closed)
    return out


def chunk(cfg: dict, rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    """The chunk function (module level; bind ``cfg`` with functools.partial to pickle)."""
    return reduce_chunk(cfg, simulate(cfg, rng, n))
