"""The consistent region of ``gridplate_two_plates``'s unprinted inputs (seed 001) and the
verdicts of its predictions over it (issue 21, :mod:`sim.claims.inference`).

The paper prints neither its grid (points per side, spacing), nor the comparator's scale
difference and non-orthogonality, nor the true sigma of its grid coordinates (only the stated
0.7 um); ``region.toml`` declares them with their physically possible ranges (the PSK's
23 cm plate bounds the grid's extent), the printed numbers that constrain them (the
comparator sigma 1.2 um and the 1:3 weighting's 0.7 um, both inputs of the simulation) and
the predictions decided over the region. The readings per point are not an input here: the
paper's statistics depend on the comparator sigma of the means (printed, 1.2 um), not on how
many readings made it.

The model at each input vector draws ``region.draws`` calibrations from the exact sampling
distributions of the paper's statistics (no adjustment is run; the run's own Monte Carlo
checks them, ``twoplate.self_check.affine_sigma_analytic``):

* each row's affine misclosure variance ``s_w^2 ~ sigma_w^2 chi2(N-3)/(N-3)`` with
  ``sigma_w^2 = sigma_x'^2 + sigma_g,true^2`` (the comparator's scale ~ 1);
* the similarity fit adds, per plate, ``sigma_w^2 chi2'(2, SSR_sys/sigma_w^2)`` where
  ``SSR_sys`` is the similarity residual of the noise-free affine comparator on the grid;
* the paper's statistics follow in closed form (see :mod:`.model`).

Each statistic is evidence with the book's one-plate rule (the 2.5-97.5 % spread of one
calibration and ``p``, a calibration at least as extreme), so the Monte-Carlo noise of the
draws enters the decision (:func:`sim.claims.book_region.sample_evidence`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.book_region import Declaration, load_declaration, plate_ref, sample_evidence
from sim.claims.inference import Region, explore
from sim.instruments import transforms2d as t2
from sim.instruments.plates import grid_points
from sim.studies.gridplate.model import reweight_trials, truth_rows
from sim.studies.gridplate.schema import UM

DECLARATION = Path(__file__).with_name("region.toml")
#: the statistic behind each claim id (keys of :func:`draws`)
RW = "twoplate.weight_ratio.reweight_trials"


def declaration(book: ClaimBook) -> Declaration:
    return load_declaration(DECLARATION, book)


def point_cfg(cfg: dict, x: dict, i: int) -> dict:
    """The configuration at input vector ``i`` of ``x``."""
    c = dict(cfg)
    c["plate.grid"] = int(round(x["grid_points_1"][i]))
    c["plate.spacing_mm"] = float(x["spacing_mm"][i])
    ppm = float(x["scale_diff_at_100mm_um"][i]) * 10.0  # 1 um over 100 mm = 10 ppm
    base = cfg["comparator.scale_diff_ppm"]
    c["comparator.scale_diff_ppm"] = ppm
    c["comparator.nonorth_arcsec"] = cfg["comparator.nonorth_arcsec"] * ppm / base if base else 0.0
    c["grid.sigma_true_um"] = float(x["grid_sigma_true_um"][i])
    return c


def nominal(cfg: dict) -> dict[str, float]:
    """The configured inputs in the region's names (drawn as an example in the figure)."""
    return {
        "grid_points_1": float(cfg["plate.grid"]),
        "spacing_mm": float(cfg["plate.spacing_mm"]),
        "scale_diff_at_100mm_um": cfg["comparator.scale_diff_ppm"] / 10.0,
        "grid_sigma_true_um": float(cfg["grid.sigma_true_um"]),
    }


def sys_ssr_um2(cfg: dict) -> float:
    """Similarity residual sum of squares (um^2, one plate) of the noise-free comparator."""
    G = grid_points(cfg["plate.grid"], cfg["plate.spacing_mm"])
    S, S2, eps = truth_rows(cfg)
    ideal = t2.apply_affine(t2.affine_from_rows(S, S2, eps, 0.0, (120.0, 120.0))[None], G[None])
    f = t2.fit_similarity(G[None], ideal)
    return float((f.residuals**2).sum()) / UM**2


def draws(cfg: dict, rng: np.random.Generator, M: int) -> dict[str, np.ndarray]:
    """The paper's statistics of ``M`` simulated calibrations (um, ratios, counts)."""
    N, P = cfg["plate.grid"] ** 2, cfg["plate.count"]
    dof = N - 3
    sx, st = cfg["comparator.coord_sigma_um"], cfg["grid.sigma_stated_um"]
    sw2_true = sx**2 + cfg["grid.sigma_true_um"] ** 2
    sw2 = sw2_true * rng.chisquare(dof, (M, 2 * P)) / dof
    ssr = sys_ssr_um2(cfg)
    # an exact similarity (no scale difference) leaves a residual of rounding size only: a
    # residual rms below 1 pm is zero, so the draws do not hinge on the fit's last bits
    lam = ssr / sw2_true if ssr > 2 * N * 1e-12 else 0.0
    extra = sw2_true * (
        rng.noncentral_chisquare(2, lam, (M, P)) if lam > 0 else rng.chisquare(2, (M, P))
    )
    ssr_aff = sw2.sum(1) * dof
    aff = np.sqrt(ssr_aff / (P * (2 * N - 6)))
    sim = np.sqrt((ssr_aff + extra.sum(1)) / (P * (2 * N - 4)))
    comp2 = sw2 - st**2
    ok = (comp2 > 0).all(1)
    comp = np.sqrt(np.where(ok, comp2.mean(1), np.nan))
    return {
        "twoplate.weight_ratio.grid_sigma_1to3_um": np.sqrt((sw2 / 4).mean(1)),
        "twoplate.weight_ratio.converged_ratio": np.where(ok, (sw2 / st**2 - 1).mean(1), np.nan),
        RW: reweight_trials(
            sw2, np.ones_like(sw2), st, dof, cfg["analysis.ratio_start"], cfg["analysis.alpha"]
        ).ravel(),
        "twoplate.comparator_sigma.sigma_um": comp,
        "twoplate.similarity_vs_affine.similarity_sigma_um": sim,
        "twoplate.similarity_vs_affine.affine_sigma_um": aff,
        "twoplate.similarity_vs_affine.scale_share_linear_um": sim - aff,
        "twoplate.similarity_vs_affine.grid_share_linear_um": aff - comp,
    }


def _evidence(book: ClaimBook, cid: str, x: np.ndarray) -> dict:
    """Per-point evidence of claim ``cid`` from its (N, M) statistic: a statistic without a
    value for most calibrations (no positive fixed point) contradicts the claim."""
    if cid == RW:  # "one or two trials": the 95th percentile of the re-weightings, exact
        v = np.percentile(x, 95, axis=1)
        return {"value": v, "low": v, "high": v}
    ev = sample_evidence(x, *plate_ref(book.spec(cid)))
    bad = np.mean(np.isfinite(x), axis=1) < 0.5
    for k in ("value", "low", "high"):
        ev[k] = np.where(bad, np.inf, ev[k])
    if "p" in ev:
        ev["p"] = np.where(bad, 0.0, ev["p"])
    return ev


def model_fn(cfg: dict, book: ClaimBook, rng: np.random.Generator, ids: list[str]):
    """``x -> evidence`` for :func:`sim.claims.inference.explore`."""
    M = cfg["region.draws"]

    def model(x: dict[str, np.ndarray]) -> dict:
        n = len(x["spacing_mm"])
        stats = {c: np.empty((n, M if c != RW else M * 2 * cfg["plate.count"])) for c in ids}
        extent = np.empty(n)
        for i in range(n):
            c = point_cfg(cfg, x, i)
            extent[i] = (c["plate.grid"] - 1) * c["plate.spacing_mm"]
            d = draws(c, rng, M)
            for cid in ids:
                stats[cid][i] = d[cid]
        out = {cid: _evidence(book, cid, stats[cid]) for cid in ids}
        out["hardware.extent_mm"] = extent
        return out

    return model


def explore_region(cfg: dict, book: ClaimBook, rng: np.random.Generator) -> tuple[Region, list]:
    """The consistent region (every evaluated point, with the predictions' evidence)."""
    dec = declaration(book)
    ids = [s.id for s in dec.statements if s.id in book.specs] + dec.predictions
    region = explore(
        dec.inputs,
        dec.statements,
        model_fn(cfg, book, rng, ids),
        rng,
        n=cfg["region.points"],
        rounds=cfg["region.rounds"],
        max_new=4 * cfg["region.points"],
    )
    return region, dec.predictions
