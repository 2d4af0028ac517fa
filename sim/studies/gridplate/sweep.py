"""Unprinted inputs of ``gridplate_two_plates`` swept: where each claim of seed 001 holds.

The paper prints neither its grid (points per side, spacing), nor the readings per point,
nor the comparator's scale difference and non-orthogonality, nor the true sigma of its grid
coordinates (only the stated one). For each such input, with the others at their configured
values, the paper's one-calibration numbers are evaluated over simulated calibrations drawn
from their exact sampling distributions (cheap: no adjustment is run):

* each row's affine misclosure variance ``s_w^2 ~ sigma_w^2 chi2(N-3)/(N-3)`` with
  ``sigma_w^2 = sigma_x'^2 + sigma_g,true^2`` (the comparator's scale ~ 1);
* the similarity fit adds, per plate, ``sigma_w^2 chi2'(2, SSR_sys/sigma_w^2)`` where
  ``SSR_sys`` is the similarity residual of the noise-free affine comparator on the grid;
* the paper's statistics follow in closed form (see :mod:`.model`).

Each claim is decided by the claim book's own rule (:func:`sim.claims.book.ClaimBook.score`). A
sweep value is in a claim's set when the outcome is not ``fails`` (the paper's number is
not contradicted: ``holds`` or ``inconclusive``); the *consistent set* of an input is where
every claim of the sweep (paper-checks excepted: they do not depend on the simulation) is.
"""

from __future__ import annotations

import math

import numpy as np

from sim.claims.book import ClaimBook
from sim.instruments import transforms2d as t2
from sim.instruments.plates import grid_points
from sim.studies.gridplate.model import reweight_trials, truth_rows
from sim.studies.gridplate.schema import UM

#: input key -> config list of swept values
INPUTS = {
    "plate.grid": "consistency.grid",
    "plate.spacing_mm": "consistency.spacing_mm",
    "readings.count": "consistency.readings",
    "comparator.scale_diff_ppm": "consistency.scale_diff_ppm",
    "grid.sigma_true_um": "consistency.grid_sigma_true_um",
}
#: claims evaluated in the sweep
CLAIMS = (
    "twoplate.weight_ratio.grid_sigma_1to2_um",
    "twoplate.weight_ratio.grid_sigma_1to3_um",
    "twoplate.weight_ratio.converged_ratio",
    "twoplate.weight_ratio.reweight_trials",
    "twoplate.comparator_sigma.sigma_um",
    "twoplate.comparator_sigma.mean_of_L",
    "twoplate.similarity_vs_affine.similarity_sigma_um",
    "twoplate.similarity_vs_affine.affine_sigma_um",
    "twoplate.similarity_vs_affine.scale_share_linear_um",
    "twoplate.similarity_vs_affine.grid_share_linear_um",
)


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
        "twoplate.weight_ratio.grid_sigma_1to2_um": np.sqrt((sw2 / 3).mean(1)),
        "twoplate.weight_ratio.grid_sigma_1to3_um": np.sqrt((sw2 / 4).mean(1)),
        "twoplate.weight_ratio.converged_ratio": np.where(ok, (sw2 / st**2 - 1).mean(1), np.nan),
        "rw_trials": reweight_trials(
            sw2, np.ones_like(sw2), st, dof, cfg["analysis.ratio_start"], cfg["analysis.alpha"]
        ),
        "twoplate.comparator_sigma.sigma_um": comp,
        "twoplate.similarity_vs_affine.similarity_sigma_um": sim,
        "twoplate.similarity_vs_affine.affine_sigma_um": aff,
        "twoplate.similarity_vs_affine.scale_share_linear_um": sim - aff,
        "twoplate.similarity_vs_affine.grid_share_linear_um": aff - comp,
    }


def _outcome(spec: dict, **kw) -> dict:
    return ClaimBook([spec], [], "<sweep>").score(spec["id"], **kw)


def evaluate(book: ClaimBook, cfg: dict, rng: np.random.Generator) -> dict[str, dict]:
    """Rows (outcome, value, p_plate) of every sweep claim at one configuration."""
    d = draws(cfg, rng, cfg["consistency.draws"])
    out = {}
    for cid in CLAIMS:
        spec = book.spec(cid)
        if cid == "twoplate.weight_ratio.reweight_trials":
            x = d["rw_trials"].ravel()
            row = _outcome(spec, value=float(np.percentile(x, 95)), interval="exact")
        elif cid == "twoplate.comparator_sigma.mean_of_L":
            row = _outcome(
                spec,
                value=cfg["readings.sigma_um"] / math.sqrt(cfg["readings.count"]),
                interval="exact",
            )
        else:
            x = d[cid]
            x = x[np.isfinite(x)]
            if x.size < 0.5 * d[CLAIMS[0]].size:  # most plates have no fixed point: fails
                row = {"outcome": "fails", "value": math.nan, "p_plate": math.nan}
            else:
                row = _outcome(spec, samples=x)
        out[cid] = {"outcome": row["outcome"], "value": row["value"], "p_plate": row["p_plate"]}
    return out


def run_sweep(book: ClaimBook, cfg: dict) -> tuple[dict, dict]:
    """Sweep every unprinted input; returns the detail table and the consistent-set table."""
    det = {k: [] for k in ("input", "input_value", "claim", "kind", "outcome", "value", "p_plate")}
    cons = {
        k: []
        for k in (
            "input",
            "claim",
            "kind",
            "holds_low",
            "holds_high",
            "n_values",
            "n_holds",
            "default",
        )
    }
    for i, (key, listkey) in enumerate(INPUTS.items()):
        vals = sorted(cfg[listkey])
        ok_all = np.ones(len(vals), bool)
        per_claim = {c: np.zeros(len(vals), bool) for c in CLAIMS}
        for j, v in enumerate(vals):
            c = dict(cfg)
            c[key] = v
            if key == "comparator.scale_diff_ppm":  # eps in the configured proportion
                base = cfg["comparator.scale_diff_ppm"]
                c["comparator.nonorth_arcsec"] = (
                    cfg["comparator.nonorth_arcsec"] * v / base
                    if base
                    else cfg["comparator.nonorth_arcsec"]
                )
            rng = np.random.default_rng(np.random.SeedSequence(cfg["seed"], spawn_key=(900, i, j)))
            rows = evaluate(book, c, rng)
            for cid, r in rows.items():
                kind = book.spec(cid)["kind"]
                good = r["outcome"] != "fails"
                per_claim[cid][j] = good
                if kind != "paper-check":
                    ok_all[j] &= good
                for col, val in (
                    ("input", key),
                    ("input_value", float(v)),
                    ("claim", cid),
                    ("kind", kind),
                    ("outcome", r["outcome"]),
                    ("value", r["value"]),
                    ("p_plate", r["p_plate"]),
                ):
                    det[col].append(val)
        for cid, good in list(per_claim.items()) + [("ALL", ok_all)]:
            hv = np.asarray(vals, float)[good]
            cons["input"].append(key)
            cons["claim"].append(cid)
            cons["kind"].append("all" if cid == "ALL" else book.spec(cid)["kind"])
            cons["holds_low"].append(float(hv.min()) if hv.size else math.nan)
            cons["holds_high"].append(float(hv.max()) if hv.size else math.nan)
            cons["n_values"].append(len(vals))
            cons["n_holds"].append(int(good.sum()))
            cons["default"].append(float(cfg[key]))
    return det, cons
