"""Simulation core of the Brown studies: analytic cofactor sigmas, the Monte-Carlo chunk
(all three adjustment models on the same simulated ranges) and streamed statistics.

Coordinates in mm, standard deviations in um. Seed paper 004 (Brown 1968).
"""

from __future__ import annotations

from functools import partial

import numpy as np

from sim.instruments.ranges import multilateration as ml
from sim.mc.config import StudyError
from sim.mc.runner import jackknife, run_chunks
from sim.studies import RunContext
from sim.studies.brown.schema import MODEL_NAMES
from sim.studies.brown.values import start_theta


def analytic_sigma(pts: np.ndarray, theta: np.ndarray, model: str, sigma_um: float = 1.0):
    """Per-point sigma_x, sigma_y (um) at the true values, shape (n, 2)."""
    Q = ml.covariance(pts[None], theta[None], model)[0][0]
    return sigma_um * np.sqrt(np.stack([Q[:, 0, 0], Q[:, 1, 1]], axis=1))


#: the step (mm) of the central differences of :func:`spread_sigma` and the convergence
#: tolerance (mm) of its noise-free adjustments (the difference quotient is good to about
#: tol / step = 1e-10, its truncation error to step^2 / range^2, below 1e-10 as well)
SPREAD_STEP_MM, SPREAD_TOL_MM = 1e-3, 1e-13
#: the ranges (a plate's points x 4 of each perturbed copy) adjusted at once by
#: :func:`spread_sigma`: its 2 x 4n copies of an n-point plate in one batch held 32 n^2
#: values besides the ``np.eye(4n)`` of its steps (11.6 GB at 3,600 points, where the run's
#: estimate said 0.333 GiB; 100,000 random points are allowed), so they go in blocks
SPREAD_BLOCK_RANGES = 2**20


def spread_sigma(pts, theta, model: str, sigma_um: float, bias_um: float) -> np.ndarray:
    """The first-order standard deviations (um, (n, 2)) of ``model``'s adjusted coordinates
    when every range carries ``bias_um`` and independent errors of ``sigma_um``: the spread
    that the Monte Carlo measures, and what its self-check compares it with.

    With no bias (or a model that absorbs a constant, ``pivot``'s alpha) the adjustment fits
    the noise-free ranges exactly and this is the analytic covariance :func:`analytic_sigma`.
    A model that cannot absorb the bias (``known``, ``stations``) leaves residuals of the
    bias's size, and the curvature of the ranges times those residuals changes the
    estimate's covariance (the sandwich ``A^-1 J^T J A^-1``, ``A = J^T J + sum r_i H_i``, of a
    misspecified least-squares fit): 10 mm of bias widened ``known``'s spread by 9.6 %
    (``stations``' by 1.7 %). It is taken here as the derivative of the adjusted coordinates
    with respect to each range (central differences of noise-free adjustments, a block of
    ranges at a time: :data:`SPREAD_BLOCK_RANGES`) at the biased ranges, times ``sigma_um``."""
    if bias_um == 0:
        return analytic_sigma(pts, theta, model, sigma_um)
    r0 = ml.ranges(pts[None], theta[None]) + bias_um * 1e-3  # (1, n, 4) mm
    m = r0[0].size
    block = max(1, SPREAD_BLOCK_RANGES // (2 * m))  # ranges perturbed in one batch
    g2 = np.zeros(pts.shape)
    for lo in range(0, m, block):
        k = min(block, m - lo)
        step = np.zeros((k, m))
        step[np.arange(k), lo + np.arange(k)] = SPREAD_STEP_MM
        step = step.reshape((k,) + r0.shape[1:])
        res = ml.adjust(
            np.concatenate([r0 + step, r0 - step]),
            model,
            start_theta(theta, model),
            tol_mm=SPREAD_TOL_MM,
            max_iter=100,
        )
        if not res.converged.all():  # no derivative: the self-check has no reference
            return np.full(pts.shape, np.nan)
        G = (res.points[:k] - res.points[k:]) / (2 * SPREAD_STEP_MM)  # (k, n, 2) d point / d r
        g2 += (G * G).sum(0)
    return sigma_um * np.sqrt(g2)


SIM_KEYS = (
    "errors.setting_sigma_um",
    "errors.settings",
    "errors.comparator_sigma_um",
    "errors.bias_um",
    "solver.tol_mm",
    "solver.max_iter",
)


def _adjust_all(obs, pts, theta, sim) -> tuple[dict, dict]:
    """All three models on the same ranges: per-trial rows and the chunk's error sums (um)."""
    n = obs.shape[0]
    out: dict[str, np.ndarray] = {}
    errs, ok_all = [], np.ones(n, bool)
    res_by = {}
    for m in MODEL_NAMES:
        res = ml.adjust(
            obs,
            m,
            start_theta(theta, m),
            tol_mm=sim["solver.tol_mm"],
            max_iter=sim["solver.max_iter"],
        )
        res_by[m] = res
        out[f"rows.{m}_converged"] = res.converged
        out[f"rows.{m}_status"] = res.status
        out[f"rows.{m}_iterations"] = res.iterations
        out[f"rows.{m}_sigma0_um"] = res.sigma0 * 1e3
        for i, name in enumerate(ml.PARAM_NAMES[: ml.MODELS[m]]):
            out[f"rows.{m}_{name}"] = res.theta[:, i]
        errs.append((res.points - pts) * 1e3)  # um
        ok_all &= res.converged
    e = np.stack(errs, 1)[ok_all]  # (n_ok, 3, n_pts, 2)
    out["sum.n"] = np.array([ok_all.sum()], float)
    out["sum.e1"] = e.sum(0)[None]
    out["sum.e2"] = (e * e).sum(0)[None]
    out["sum.nfail"] = np.array([[(~res_by[m].converged).sum() for m in MODEL_NAMES]], float)
    return out, res_by


#: the convergence tolerance (mm) and the least iteration limit of the bias-invariance check's
#: two pivot adjustments: its claims' zone is +-1e-9 mm ("zero to rounding"), and at a looser
#: ``solver.tol_mm`` (1e-3 mm) each adjustment stopped that far from its solution, so the two
#: differed by 1e-8 mm and the paper's "precisely the same" failed on the solver's limit
BIAS_TOL_MM, BIAS_MAX_ITER = 1e-10, 30


#: restarts of each of the bias check's adjustments from its own solution (:func:`_polished`)
BIAS_RESTARTS = 2


def _polished(r, obs, tol: float, it: int):
    """``(result, converged)``: the pivot adjustment ``r`` of ``obs`` restarted from its own
    solution :data:`BIAS_RESTARTS` times. The engine stops where the remaining error it
    estimates from the contraction of the last two corrections is below ``tol``; at range
    errors of 0.1-3 mm (brown_dilution's range sigma at 100-3000 um) that estimate fell 100
    times short on some plates, which stopped up to 3e-8 mm from the solution, and the bias
    check failed on the paper's exact "precisely the same x_j, y_j" (zone 1e-9 mm). A restart
    takes a full first step (no estimate yet): after one, up to 6e-10 mm apart at 3 mm over
    2,000 plates; after two, 1e-11 mm (at 1 um: 1e-13 mm, as before)."""
    ok = r.converged.copy()
    for _ in range(BIAS_RESTARTS):
        r = ml.adjust(obs, "pivot", r.theta, r.points, tol_mm=tol, max_iter=it)
        ok &= r.converged
    return r, ok


def _bias_rows(obs, theta, sim, r0, shift_um: float) -> dict[str, np.ndarray]:
    """The pivot adjustment again with ``shift_um`` added to every range: the largest point
    change (mm) and the error of alpha's change against the shift, over both converged; both
    adjustments held to :data:`BIAS_TOL_MM` (``r0``, the run's, redone when its tolerance
    was looser) and restarted once from their solutions (:func:`_polished`)."""
    tol = min(sim["solver.tol_mm"], BIAS_TOL_MM)
    it = (
        sim["solver.max_iter"]
        if tol == sim["solver.tol_mm"]
        else max(sim["solver.max_iter"], BIAS_MAX_ITER)
    )

    def fit(o):
        return ml.adjust(o, "pivot", start_theta(theta, "pivot"), tol_mm=tol, max_iter=it)

    r0 = r0 if tol == sim["solver.tol_mm"] else fit(obs)
    r0, ok0 = _polished(r0, obs, tol, it)
    o2 = obs + shift_um * 1e-3
    r2, ok2 = _polished(fit(o2), o2, tol, it)
    both = ok0 & ok2
    return {
        "bias.max_point_shift_mm": np.array([np.abs(r2.points - r0.points)[both].max(initial=0.0)]),
        "bias.alpha_err_mm": np.array(
            [np.abs(r2.theta[both, 5] - r0.theta[both, 5] + shift_um * 1e-3).max(initial=0.0)]
        ),
        "bias.n": np.array([both.sum()]),
    }


def _table1_rows(r, sett) -> dict[str, np.ndarray]:
    """Per-plate statistics of the a-posteriori point sigmas (um) of the pivot adjustment ``r``
    (NaN where it did not converge); ``sett``: the individual settings."""
    n = r.sigma0.shape[0]
    out = {}
    Qpp = ml.covariance(r.points, r.theta, "pivot")[0]
    ap = r.sigma0[:, None, None] * 1e3 * np.sqrt(np.stack([Qpp[..., 0, 0], Qpp[..., 1, 1]], -1))
    nan = np.where(r.converged, 1.0, np.nan)
    out["t1.sigma0_um"] = r.sigma0 * 1e3 * nan
    out["t1.share_1p1_1p3"] = ((ap >= 1.05) & (ap < 1.35)).mean(axis=(1, 2)) * nan
    out["t1.max_sigma_um"] = ap.max(axis=(1, 2)) * nan
    out["t1.points_ge_1p45"] = (ap.max(axis=2) >= 1.45).sum(axis=1) * nan
    L = sett.shape[-1]  # the setting sigma needs repeated settings
    out["t1.setting_sigma_um"] = (
        np.sqrt(sett.var(axis=-1, ddof=1).mean(axis=(1, 2))) * nan if L > 1 else np.full(n, np.nan)
    )
    for k in ("share_1p1_1p3", "max_sigma_um", "points_ge_1p45"):
        out[f"rows.pivot_{k}"] = out[f"t1.{k}"]
    return out


def chunk(
    rng: np.random.Generator,
    n: int,
    *,
    sim: dict,
    pts: np.ndarray,
    theta: np.ndarray,
    shift_um: float | None = None,
    table1: bool = False,
) -> dict[str, np.ndarray]:
    """One chunk of ``n`` simulated plates, adjusted with all three models.

    Returns per-trial rows (``rows.*``: sigma0, iterations, status and globals per model),
    per-chunk sums of the coordinate errors over the trials where all models converged
    (``sum.n`` (1,), ``sum.e1``/``sum.e2`` (1, 3, n_pts, 2) in um and um^2) from which the
    Monte-Carlo sigmas and their jackknife intervals follow, and, for the production test,
    per-plate statistics of the a-posteriori sigmas. Module level, so it can be sent to
    worker processes (bind the keywords with functools.partial).
    """
    P = np.broadcast_to(pts, (n,) + pts.shape)
    TH = np.broadcast_to(theta, (n, 7))
    obs, sett = ml.simulate_ranges(
        P,
        TH,
        rng,
        setting_sigma_um=sim["errors.setting_sigma_um"],
        settings=sim["errors.settings"],
        comparator_sigma_um=sim["errors.comparator_sigma_um"],
        bias_um=sim["errors.bias_um"],
        return_settings=True,
    )
    out, res_by = _adjust_all(obs, pts, theta, sim)
    if shift_um is not None:
        out.update(_bias_rows(obs, theta, sim, res_by["pivot"], shift_um))
    if table1:
        out.update(_table1_rows(res_by["pivot"], sett))
    return out


def run_mc(cfg: dict, pts, theta, ctx: RunContext, shift_um=None, table1=False) -> dict:
    fn = partial(
        chunk,
        sim={k: cfg[k] for k in SIM_KEYS},
        pts=pts,
        theta=theta,
        shift_um=shift_um,
        table1=table1,
    )
    return run_chunks(
        fn, cfg["trials"], cfg["seed"], cfg["chunk"], part=0, label=cfg["study"], ctx=ctx
    )


class MC:
    """Monte-Carlo statistics from per-chunk sums (streamed; memory independent of trials).

    ``sums`` (C, 3, n, 2, 2) holds per chunk the first and second moments of the errors of
    each model; ``cnt`` (C,) the trials they cover. Intervals are delete-one-chunk jackknife
    intervals (:func:`sim.mc.runner.jackknife`) or chi-square intervals for single sigmas.
    """

    def __init__(self, sim: dict):
        self.cnt = sim["sum.n"]
        self.sums = np.stack([sim["sum.e1"], sim["sum.e2"]], -1)
        self.packed = np.concatenate([self.cnt[:, None], self.sums.reshape(len(self.cnt), -1)], 1)
        self.shape = self.sums.shape[1:]
        self.N = int(self.cnt.sum())
        self.nfail = sim["sum.nfail"].sum(0)
        if self.N < 2:
            raise StudyError(
                f"only {self.N} trials converged in all models (non-converged: "
                + ", ".join(f"{m} {int(f)}" for m, f in zip(MODEL_NAMES, self.nfail))
                + "): a singular reduced normal matrix (a degenerate geometry), or the "
                "solver stopped before converging (solver.max_iter, solver.tol_mm)"
            )

    def sd_from(self, total: np.ndarray) -> np.ndarray:
        """(3, n, 2) standard deviations from a packed total [N, sums...]."""
        N = total[0]
        s = total[1:].reshape(self.shape)
        return np.sqrt(np.maximum(s[..., 1] - s[..., 0] ** 2 / N, 0) / (N - 1))

    @property
    def sd(self) -> np.ndarray:
        return self.sd_from(self.packed.sum(0))

    def jack(self, f):
        """Estimate and 95 % jackknife interval of ``f(sd (3, n, 2))``."""
        return jackknife(lambda t: f(self.sd_from(t)), self.packed)


def points_table(pts, an: dict, mc: MC, sr: float) -> dict:
    """Rows of points.parquet: one per model and point (sigmas in um)."""
    n = len(pts)
    k_pt = pooled_sigma(an["known"])
    cols: dict[str, list] = {
        k: []
        for k in (
            "model",
            "point",
            "x_mm",
            "y_mm",
            "sigma_x_um",
            "sigma_y_um",
            "mc_sigma_x_um",
            "mc_sigma_y_um",
            "mc_trials",
            "ratio_x",
            "ratio_y",
            "dilution_pct",
        )
    }
    sd = mc.sd
    for i, m in enumerate(MODEL_NAMES):
        a = an[m]
        cols["model"] += [m] * n
        cols["point"] += list(range(1, n + 1))
        cols["x_mm"] += list(pts[:, 0])
        cols["y_mm"] += list(pts[:, 1])
        cols["sigma_x_um"] += list(a[:, 0])
        cols["sigma_y_um"] += list(a[:, 1])
        cols["mc_sigma_x_um"] += list(sd[i, :, 0])
        cols["mc_sigma_y_um"] += list(sd[i, :, 1])
        cols["mc_trials"] += [mc.N] * n
        cols["ratio_x"] += list(a[:, 0] / sr)
        cols["ratio_y"] += list(a[:, 1] / sr)
        cols["dilution_pct"] += list((pooled_sigma(a) / k_pt - 1) * 100)
    return cols


def pooled_sigma(a: np.ndarray) -> np.ndarray:
    """sigma of a point: rms of its sigma_x and sigma_y, (n,)."""
    return np.sqrt((a**2).mean(axis=-1))
