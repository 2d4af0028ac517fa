"""Scoring of ``gridplate_two_plates``: the claim book ``claims.toml`` plus what the run made.

The code supplies the simulated values and computed notes only; each verdict follows from the
claim book's rule (:mod:`sim.claims.book`). Paper-checks recompute the paper's numbers from its
own printed numbers, which are read from the book's references (one source).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy import special

from sim.claims.book import ClaimBook
from sim.claims.intervals import share_ci
from sim.claims.region import REGION_MIN_POINTS, share_bound
from sim.claims.table import Sim, claim_rows, exact, plates
from sim.lsq import distributions as D
from sim.mc.config import StudyError
from sim.studies.gridplate.beyond import beyond_rows, coverage_rows
from sim.studies.gridplate.model import MAX_TRIALS

BOOK = Path(__file__).with_name("claims.toml")


def load_book() -> ClaimBook:
    return ClaimBook.load(BOOK)


def quantile_ci(
    x: np.ndarray, q: float, level: float = 0.95, clip: bool = True
) -> tuple[float, tuple[float, float]]:
    """Quantile ``q`` of ``x`` with its distribution-free (order-statistic) interval. Where
    the sample is too small for an end (the 95th percentile's upper end needs ``0.95^n <=
    0.025``, 72 values), ``clip`` takes the sample's extreme (the spread of a sample), else
    the end is unbounded: 24 re-weighting counts gave the 95th percentile [x(22), max], which
    covers it about 60 % of the time (23 % at 6 values), and a claim held on it."""
    x = np.sort(np.asarray(x, float).ravel())
    n = x.size
    a = (1 - level) / 2
    lo, hi = int(D.binom_ppf(a, n, q)), int(D.binom_ppf(1 - a, n, q))
    low = float(x[min(max(lo, 0), n - 1)]) if clip or 0 <= lo else -math.inf
    high = float(x[min(max(hi, 0), n - 1)]) if clip or hi <= n - 1 else math.inf
    return float(np.quantile(x, q)), (low, high)


def median_ci(x: np.ndarray, level: float = 0.95) -> tuple[float, tuple[float, float]]:
    """The median of ``x`` with its distribution-free interval ``[x(lo), x(n - 1 - lo)]``
    (0-based), ``lo`` the largest index with ``P(B <= lo) <= (1 - level) / 2``, ``B ~
    Binomial(n, 1/2)``: it covers the median at least at ``level``. It needs
    :data:`sim.studies.gridplate.schema.MIN_MEDIAN` values (fewer trials are refused on load): :func:`quantile_ci` clips
    its indices to the sample, so two calibrations took [min, max], which covers the median
    half the time, and the self-check it decided "failed" at ``trials = 2``."""
    x = np.sort(np.asarray(x, float).ravel())
    cdf = special.bdtr(np.arange(x.size), x.size, 0.5)
    below = np.flatnonzero(cdf <= (1 - level) / 2 * (1 + 1e-12))
    if not below.size:
        raise StudyError(f"trials: {x.size} calibrations give the median no {level:.0%} interval")
    lo = int(below[-1])
    return float(np.median(x)), (float(x[lo]), float(x[x.size - 1 - lo]))


def _finite(x, what: str, key: str) -> np.ndarray:
    x = np.asarray(x, float).ravel()
    f = x[np.isfinite(x)]
    if f.size < max(2, x.size // 2):
        raise StudyError(
            f"{key}: {what} has no value in {x.size - f.size} of {x.size} "
            "calibrations (no positive re-weighting fixed point); change this key"
        )
    return f


def _left_out(x) -> str:
    """What a note says of the calibrations :func:`_finite` left out (nothing if none)."""
    n = int(np.sum(~np.isfinite(np.asarray(x, float))))
    return (
        f" {n} of {np.size(x)} calibrations had no positive fixed point and are left out."
        if n
        else ""
    )


def _pooled(cfg: dict) -> str:
    """Which plates a pooled s0 covers (the paper's two, or the configured count)."""
    P = cfg["plate.count"]
    return "both plates" if P == 2 else ("the plate" if P == 1 else f"all {P} plates")


def _count(P: int) -> str:
    return "1 plate" if P == 1 else f"{P} plates"


def _fit_pool(cfg: dict) -> str:
    """What a fit's sigma pools: "two plates pooled" (the paper's), one plate alone, or P."""
    P = cfg["plate.count"]
    return "two plates pooled" if P == 2 else ("one plate" if P == 1 else f"{P} plates pooled")


def _readings(cfg: dict, res: dict) -> dict[str, Sim]:
    """The precision of one reading (from the repeated readings) and the stated grid sigma."""
    L, N, P = cfg["readings.count"], cfg["plate.grid"] ** 2, cfg["plate.count"]
    return {
        "twoplate.precision.reading_sigma_um": plates(
            res["sigma_obs_um"],
            f"sigma = sqrt(sum sigma_i^2 / {2 * P if P != 2 else 4}N) from {L} readings of {N} "
            f"points on {_count(P)}; the reading sigma is an input "
            f"({cfg['readings.sigma_um']:g} um), so this shows the estimator's spread "
            f"({2 * P * N * (L - 1)} degrees of freedom; "
            + (
                "the paper's '4N' is the divisor)."
                if P == 2
                else "the paper's divisor 4N is for its two plates)."
            ),
        ),
        "twoplate.grid.stated_sigma_um": exact(
            cfg["grid.sigma_stated_um"], "the stated (certificate) grid sigma of the simulation"
        ),
    }


def _weighting(cfg: dict, res: dict) -> dict[str, Sim]:
    """The paper's weightings 1:2 and 1:3 and its re-weighting to a passing chi-square test."""
    N, P = cfg["plate.grid"] ** 2, cfg["plate.count"]
    sx, sgt = cfg["comparator.coord_sigma_um"], cfg["grid.sigma_true_um"]
    table = {  # 1:2 is the paper's arithmetic on the same adjustment (_paper_checks)
        "twoplate.weight_ratio.grid_sigma_1to3_um": plates(
            res["grid_sigma_1to3_um"],
            "grid sigma implied by the weights, s0/sqrt(P_cx), P_x:P_cx = 1:3, "
            f"x' and y' of {_pooled(cfg)} pooled; expectation sqrt((sx'^2 + sg^2)/(1 + "
            f"P_cx)) = {math.sqrt((sx**2 + sgt**2) / 4):.3f} um from the "
            "simulated comparator and grid sigmas.",
        )
    }
    rr = _finite(res["ratio_rw_mean"], "the re-weighted ratio", "grid.sigma_stated_um")
    table["twoplate.weight_ratio.converged_ratio"] = plates(
        rr,
        "P_cx/P_x at the fixed point of the paper's re-weighting (P_x = 1), mean "
        f"of the {2 * P} adjustments of one calibration; "
        f"{int(np.sum(~np.isfinite(res['ratio_rw_mean'])))} of "
        f"{res['ratio_rw_mean'].size} calibrations had no positive fixed point. True "
        f"ratio sx'^2/sg^2 = {sx**2 / max(sgt, 1e-9) ** 2:.2f}.",
    )
    t = res["rw_trials"].ravel()
    v, ci = quantile_ci(t, 0.95, clip=False)
    few = ""
    if not math.isfinite(ci[1]):  # no order statistic bounds it: the most a count can be
        ci = (ci[0], float(MAX_TRIALS))
        few = (
            f"; {t.size} adjustments bound the 95th percentile from above by no order "
            f"statistic (72 needed), so the interval reaches {MAX_TRIALS}, the most counted"
        )
    table["twoplate.weight_ratio.reweight_trials"] = Sim(
        v,
        ci,
        note=f"re-weightings P_cx <- s0^2/sg^2 until the chi-square test "
        f"({N - 3} degrees of freedom) of s0^2/P_cx against the stated sigma passes, "
        f"starting at 1:{cfg['analysis.ratio_start']:g}: 95th percentile over "
        f"{t.size} adjustments (order-statistic interval); shares 0/1/2/more: "
        + "/".join(f"{np.mean(t == k):.3f}" for k in (0, 1, 2))
        + f"/{np.mean(t > 2):.3f}{few}.",
    )
    pr = res["passes_rw"]
    m, ci = share_ci(pr)
    table["twoplate.weight_ratio.pass_after_reweighting"] = Sim(
        m,
        ci,
        note=f"share of {pr.size} iterated re-weightings (sim.instruments.gridplate.reweight) whose "
        "chi-square test passes: the re-weighting forces s0^2/P_cx to the stated "
        "value, so the test passes by construction and cannot check the stated grid "
        "sigma (only sx'^2 + sg^2 is estimable from one plate).",
    )
    return table


def _comparator(book: ClaimBook, cfg: dict, res: dict) -> dict[str, Sim]:
    """The combined adjustment's iterations, the comparator sigma after the re-weighting, and
    the paper's explanation of it (the mean of L readings, recomputed)."""
    it = res["gn_iterations"]
    lo = quantile_ci(it, 0.025)[1][0]
    hi = quantile_ci(it, 0.975)[1][1]
    sx, L = cfg["comparator.coord_sigma_um"], cfg["readings.count"]
    comp = _finite(res["comp_sigma_um"], "the comparator sigma", "grid.sigma_stated_um")
    r1p5 = book.spec("twoplate.precision.reading_sigma_um")["ref"]
    r1p2 = book.spec("twoplate.comparator_sigma.sigma_um")["ref"]
    h15 = 0.5 * 10.0 ** -book.spec("twoplate.precision.reading_sigma_um")["decimals"]
    best = r1p5 / math.sqrt(2)
    return {
        "twoplate.combined.iterations": Sim(
            elems=(np.array([lo]), np.array([hi])),
            note=f"Gauss-Newton solves of the combined adjustment until the largest "
            f"correction is below {cfg['analysis.iter_tol_um']:g} um (the converging "
            f"solve counts), {it.size} adjustments; interval: the central 95 % of "
            "adjustments with order-statistic bounds; counts "
            + ", ".join(f"{k}: {int(np.sum(it == k))}" for k in np.unique(it))
            + ".",
        ),
        "twoplate.comparator_sigma.sigma_um": plates(
            comp,
            f"s0 (P_x = 1) of the re-weighted combined adjustment, x' and y' on "
            f"{_pooled(cfg)} pooled; the truth is an input ({sx:g} um)."
            + _left_out(res["comp_sigma_um"]),
        ),
        "twoplate.comparator_sigma.mean_of_L": exact(
            best,
            f"recomputed: the precision of a mean of L >= 2 readings, {r1p5:g}/sqrt(L), is "
            f"at most {best:.3f} um ({(r1p5 - h15) / math.sqrt(2):.3f}-"
            f"{(r1p5 + h15) / math.sqrt(2):.3f} over the rounding of {r1p5:g}), below the "
            f"comparator sigma {r1p2:g} um of the means, as the paper's explanation needs; "
            f"the simulation adds a per-point comparator error of "
            f"{math.sqrt(max(sx**2 - cfg['readings.sigma_um'] ** 2 / L, 0)):.2f} um to make up "
            f"its comparator sigma {sx:g} um (comparator.coord_sigma_um) from "
            f"{cfg['readings.sigma_um']:g}/sqrt({L}).",
            ci=((r1p5 - h15) / math.sqrt(2), (r1p5 + h15) / math.sqrt(2)),
        ),
    }


def _fits(book: ClaimBook, cfg: dict, res: dict) -> dict[str, Sim]:
    """The similarity and affine fits with the grid fixed (the paper's 1.65 and 1.5)."""
    r1p2 = book.spec("twoplate.comparator_sigma.sigma_um")["ref"]
    r0p7 = book.spec("twoplate.grid.stated_sigma_um")["ref"]
    return {
        "twoplate.similarity_vs_affine.similarity_sigma_um": plates(
            res["sim_sigma_um"],
            f"sqrt(sum(vx^2+vy^2)/(2N-4)) of a similarity fit, grid fixed, {_fit_pool(cfg)}; "
            f"the comparator's scale difference ({cfg['comparator.scale_diff_ppm']:g}"
            f' ppm) and non-orthogonality ({cfg["comparator.nonorth_arcsec"]:g}") are not '
            "printed: an example; the region (consistent_region.parquet) decides this row.",
        ),
        "twoplate.similarity_vs_affine.affine_sigma_um": plates(
            res["aff_sigma_um"],
            f"sqrt(sum(vx^2+vy^2)/(2N-6)) of the affine fit, grid fixed, {_fit_pool(cfg)}, "
            "against the printed 1.5 (the paper's 1.2 and 0.7 support "
            f"{math.hypot(r1p2, r0p7):.2f}: "
            "paper_check.affine_from_comparator_and_grid).",
        ),
    }


def _paper_checks(book: ClaimBook) -> dict[str, Sim]:
    """The paper's arithmetic recomputed from its own printed numbers (the book's refs)."""

    def ref(cid):
        return book.spec(cid)["ref"]

    r1p5 = ref("twoplate.precision.reading_sigma_um")
    r1p2 = ref("twoplate.comparator_sigma.sigma_um")
    r0p7 = ref("twoplate.grid.stated_sigma_um")
    r12 = ref("twoplate.weight_ratio.grid_sigma_1to2_um")
    r13 = ref("twoplate.weight_ratio.grid_sigma_1to3_um")
    r165 = ref("twoplate.similarity_vs_affine.similarity_sigma_um")
    sup = math.hypot(r1p2, r0p7)
    h1 = 0.5 * 10.0 ** -book.spec("twoplate.comparator_sigma.sigma_um")["decimals"]
    h2 = 0.5 * 10.0 ** -book.spec("twoplate.grid.stated_sigma_um")["decimals"]
    corner = (math.hypot(r1p2 - h1, r0p7 - h2), math.hypot(r1p2 + h1, r0p7 + h2))
    h13 = 0.5 * 10.0 ** -book.spec("twoplate.weight_ratio.grid_sigma_1to3_um")["decimals"]
    f12 = math.sqrt(4 / 3)  # sigma_x(1:2) / sigma_x(1:3) = sqrt((3 + k) / (2 + k)), k = 1
    return {
        "twoplate.weight_ratio.grid_sigma_1to2_um": exact(
            r13 * f12,
            f"recomputed: sigma_x at 1:2 = sigma_x at 1:3 x sqrt((3 + k)/(2 + k)) = {r13:g} x "
            f"{f12:.4f} = {r13 * f12:.3f} um (one adjustment's s_w^2 / (P_cx + k), k = A^2 + "
            f"B^2 = 1), {(r13 - h13) * f12:.3f}-{(r13 + h13) * f12:.3f} over the rounding of "
            f"{r13:g}; the paper's two weightings are one measurement, its 1:3 value an input.",
            ci=((r13 - h13) * f12, (r13 + h13) * f12),
        ),
        "twoplate.paper_check.affine_from_comparator_and_grid": exact(
            sup,
            f"recomputed: sqrt({r1p2:g}^2 + {r0p7:g}^2) = {sup:.3f} um (independent "
            f"comparator and grid errors), {corner[0]:.3f}-{corner[1]:.3f} over the printed "
            f"rounding of {r1p2:g} and {r0p7:g}; the weightings give the same: sqrt(3 x "
            f"{r12:g}^2) = {math.sqrt(3) * r12:.3f} (1:2) and sqrt(4 x {r13:g}^2) = "
            f"{2 * r13:.3f} um (1:3). The interval reaches the printed 1.5's zone "
            "(1.45-1.55) only at its top corner: by the rule not an erratum, a tension.",
            ci=corner,
        ),
        "twoplate.paper_check.scale_share_arithmetic": exact(
            r165 - r1p5,
            f"recomputed {r165:g} - {r1p5:g} = {r165 - r1p5:.3f} um (a linear "
            f"subtraction of sigmas; in quadrature sqrt({r165:g}^2 - {r1p5:g}^2) = "
            f"{math.sqrt(r165**2 - r1p5**2):.3f} um).",
        ),
        "twoplate.paper_check.grid_share_arithmetic": exact(
            r1p5 - r1p2,
            f"recomputed {r1p5:g} - {r1p2:g} = {r1p5 - r1p2:.3f} um (linear; in "
            f"quadrature sqrt({r1p5:g}^2 - {r1p2:g}^2) = {math.sqrt(r1p5**2 - r1p2**2):.3f}"
            f" um, against the given grid sigma {r0p7:g}).",
        ),
    }


def _shares(res: dict) -> dict[str, Sim]:
    """The paper's linear subtractions of sigmas, per simulated calibration."""
    aff = res["aff_sigma_um"]
    return {
        "twoplate.similarity_vs_affine.scale_share_linear_um": plates(
            res["sim_sigma_um"] - aff,
            "similarity minus affine sigma per calibration (the paper's linear "
            "subtraction), against the printed value.",
        ),
        "twoplate.similarity_vs_affine.grid_share_linear_um": plates(
            _finite(aff - res["comp_sigma_um"], "the grid share", "grid.sigma_stated_um"),
            "affine sigma (grid fixed) minus the re-weighted comparator sigma per "
            "calibration (linear), against the printed value." + _left_out(res["comp_sigma_um"]),
        ),
    }


def _closed_form(res: dict) -> Sim:
    """The closed-form re-weighting fixed point against the iterated one, over the sampled
    adjustments: the largest relative difference of the ratios where both found a positive
    fixed point, 1 where only one of them found one (a ratio against none). An identity
    checked on k adjustments bounds the share where it fails only by ``1 - 0.05^(1/k)``
    (:func:`sim.claims.region.share_bound`): with fewer than ``REGION_MIN_POINTS`` (29, under
    10 %) compared and none disagreeing, the interval reaches 1 (an adjustment not compared
    may differ as much as a ratio from none) and the rule gives inconclusive, never holds."""
    ok = np.asarray(res["closed_form_ok"], bool).ravel()
    one = np.asarray(res["closed_form_one"], bool).ravel()
    rel = np.asarray(res["closed_form_rel"], float).ravel()
    k, d = int(ok.sum()), int(one.sum())
    cfmax = float(rel[ok | one].max()) if k + d else 0.0
    note = (
        f"largest relative difference between sim.instruments.gridplate.reweight (iterated) "
        f"and the closed-form fixed point s_w^2/sg^2 - (A^2 + B^2) used for all trials, over "
        f"the {k} of {ok.size} sampled adjustments where both found a positive fixed point"
    )
    if d:
        note += f"; in {d} only one of them found one (counted as a difference of 1)"
    rest = ok.size - k - d
    if rest:
        note += f"; {rest} where neither found one"
    if d or k >= REGION_MIN_POINTS:
        return exact(cfmax, note + ".")
    return Sim(
        cfmax,
        (cfmax, 1.0),
        note=note + f": a self-check needs {REGION_MIN_POINTS} compared (bounding the share where "
        f"it fails under 10 %, 95 %; {k} bound it only under {100 * share_bound(k):.2g} %), so "
        "the interval reaches 1 (an adjustment not compared may differ as much as a ratio from "
        "none) and it is undecided; raise analysis.iter_sample or trials.",
    )


def _self_checks(cfg: dict, res: dict) -> dict[str, Sim]:
    """The closed-form re-weighting against the iterated one, and the affine sigma's Monte
    Carlo against its chi-square distribution."""
    N, P = cfg["plate.grid"] ** 2, cfg["plate.count"]
    sx, sgt = cfg["comparator.coord_sigma_um"], cfg["grid.sigma_true_um"]
    nu = P * (2 * N - 6)
    sw = math.sqrt(sx**2 + sgt**2)
    a_med = sw * math.sqrt(D.chi2_ppf(0.5, nu) / nu)
    med, (lo, hi) = median_ci(res["aff_sigma_um"])
    return {
        "twoplate.self_check.closed_form": _closed_form(res),
        "twoplate.self_check.affine_sigma_analytic": Sim(
            med / a_med - 1,
            (lo / a_med - 1, hi / a_med - 1),
            note=f"Monte-Carlo median of the affine sigma {med:.4f} um against the analytic "
            f"{a_med:.4f} um (chi-square, {nu} degrees of freedom), relative; the sweep "
            "(consistent_region.parquet) uses these chi-square distributions.",
        ),
    }


def score(cfg: dict, res: dict, beyond: dict, cov: dict) -> tuple[list[dict], ClaimBook]:
    """The claims rows of the run (``res``: the per-trial arrays; ``beyond``: the rows of
    ``beyond.parquet``; ``cov["j_true"]``: the swept ratio nearest the true one), in the
    order of the paper's reduction, then the self-checks and what lies beyond the paper."""
    book = load_book()
    table = {
        **_readings(cfg, res),
        **_weighting(cfg, res),
        **_comparator(book, cfg, res),
        **_fits(book, cfg, res),
        **_paper_checks(book),
        **_shares(res),
        **_self_checks(cfg, res),
        **beyond_rows(beyond),
        **coverage_rows(cfg, res, cov["j_true"]),
    }
    return claim_rows(book, table), book
