"""Formal against empirical precision (seed ``004``; the affine case after seed ``001``).

Coverage of the 95 % point ellipses (known sigma; s0 with the F distribution), the false-alarm
rate of the global chi-square test and E[s0] / sigma, for Brown's pivot model (Brown's datum)
over noise, point count and beta, and for an affine calibration (a linear model). Every case
is one :func:`sim.studies.run_steps.run_part` call of a picklable chunk function, so its chunks run on
the run's executor; the cases run side by side (:mod:`.parts`).
"""

from __future__ import annotations

from functools import partial

import numpy as np

from sim.instruments.plates import grid_points
from sim.instruments.ranges import coverage as cv
from sim.instruments.ranges import multilateration as ml
from sim.lsq.result import STATUS
from sim.mc.workunits import DESIGN_UNITS, affine_units
from sim.studies.design.chunks import affine_chunk, coverage_chunk
from sim.studies.design.parts import side_by_side
from sim.studies.run_steps import run_part

__all__ = ["coverage_analysis", "summarize_cov", "COLUMNS", "PART0"]

PART0 = 30
COLUMNS = (
    "model",
    "scenario",
    "grid",
    "sigma_um",
    "beta_mm",
    "trials",
    "nonconverged",
    "dof",
    "coverage_known",
    "coverage_f",
    "false_alarm",
    "s0_ratio",
    "s0_ratio_se",
    "s0sq_ratio",
    "s0_expected",
    "b_coverage",
    "beta_coverage",
    "note",
)
_AFFINE = np.array([[1.00002, 3e-5, 0.01], [-2e-5, 0.99997, -0.02]])


def why_not(sim: dict) -> str:
    """What a case's ``note`` says of its trials that did not converge (``""``: none), by
    the engine's status (:data:`sim.lsq.result.STATUS`); with fewer than 2 converged its
    statistics are NaN, and the note says so: a row of NaN says why it has no numbers."""
    ok, status = sim["ok"], np.asarray(sim["status"])
    bad = int((~ok).sum())
    if not bad:
        return ""
    N, T = int(ok.sum()), ok.size
    codes, counts = np.unique(status[~ok], return_counts=True)
    why = ", ".join(f"{c} {STATUS.get(int(s), f'status {int(s)}')}" for s, c in zip(codes, counts))
    if N < 2:
        return f"no statistics: {N} of {T} trials converged ({why})"
    return f"{bad} of {T} trials did not converge ({why}): the statistics are over the other {N}"


def summarize_cov(sim: dict, sigma_um: float, dof: int) -> dict:
    ok = sim["ok"]
    N = int(ok.sum())
    base = {
        "trials": N,
        "nonconverged": int((~ok).sum()),
        "dof": dof,
        "s0_expected": cv.c4(dof + 1) if dof > 0 else np.nan,
        "note": why_not(sim),
    }
    if N < 2:  # every trial singular or diverged: recorded, not skipped, the note says why
        return base
    s0 = sim["s0_um"][ok] / sigma_um
    return {
        **base,
        "coverage_known": float(sim["cov_known"][ok].mean()),
        "coverage_f": float(np.nanmean(sim["cov_f"][ok])) if dof > 0 else np.nan,
        "false_alarm": float(sim["reject"][ok].mean()) if dof > 0 else np.nan,
        "s0_ratio": float(s0.mean()) if dof > 0 else np.nan,
        "s0_ratio_se": float(s0.std(ddof=1) / np.sqrt(N)) if dof > 0 else np.nan,
        "s0sq_ratio": float((s0**2).mean()) if dof > 0 else np.nan,
        "b_coverage": float(np.mean(sim["b_in"][ok])),
        "beta_coverage": float(np.mean(sim["beta_in"][ok])),
    }


def _cases(cfg):
    sig0, k0, b0 = cfg["coverage.sigma_um"], cfg["datum.grid"], cfg["datum.beta_mm"]
    T, Ts = cfg["coverage.trials"], cfg["coverage.sweep_trials"]
    cases = [("nominal", k0, sig0, b0, T)]
    cases += [("noise", k0, s, b0, Ts) for s in cfg["coverage.noise_um"]]
    cases += [("points", g, sig0, b0, Ts) for g in cfg["coverage.grids"]]
    cases += [("beta", k0, sig0, b, Ts) for b in cfg["coverage.betas_mm"]]
    return cases


def coverage_analysis(cfg: dict, ctx) -> dict:
    cols = {c: [] for c in COLUMNS}

    def add(model, scen, k, sig, beta, summ):
        for c, v in zip(COLUMNS[:5], (model, scen, k, sig, beta)):
            cols[c].append(v)
        for c in COLUMNS[5:]:
            cols[c].append(summ.get(c, "" if c == "note" else np.nan))

    h = cfg["plate.format_mm"] / 2 + cfg["datum.offset_mm"]
    ext = (cfg["datum.grid"] - 1) * cfg["datum.spacing_mm"] / 2
    sig0 = cfg["coverage.sigma_um"]
    tasks = {}
    for part, (scen, k, sig, beta, T) in enumerate(_cases(cfg), PART0):
        pts = grid_points(k, 2 * ext / (k - 1))
        th = ml.design_theta(h, cfg["comparator.alpha_mm"], beta)
        fn = partial(coverage_chunk, pts, th, sig, cfg["coverage.alpha"])
        units = DESIGN_UNITS["coverage"]
        tasks[part] = partial(run_part, cfg, ctx, fn, part, f"coverage {scen}", T, units=units)
    affine = ((cfg["datum.grid"], cfg["coverage.trials"]), (2, cfg["coverage.sweep_trials"]))
    for part, (k, T) in enumerate(affine, PART0 + len(tasks)):
        grid = grid_points(k, 2 * 110.0 / (k - 1))
        fn = partial(affine_chunk, grid, sig0, _AFFINE, cfg["coverage.alpha"])
        units = affine_units(min(cfg["chunk"], T))
        tasks[part] = partial(run_part, cfg, ctx, fn, part, "coverage affine", T, units=units)
    sims = side_by_side(tasks, ctx)
    part = PART0
    for scen, k, sig, beta, T in _cases(cfg):
        dof = 4 * k * k - (2 * k * k + 7)
        add("pivot", scen, k, sig, beta, summarize_cov(sims[part], sig, dof))
        part += 1
    for k, T in affine:
        summ = summarize_cov(sims[part], sig0, 2 * k * k - 6)
        part += 1
        summ["b_coverage"] = summ["beta_coverage"] = np.nan
        add("affine", "nominal" if k == cfg["datum.grid"] else "points", k, sig0, np.nan, summ)
    return cols
