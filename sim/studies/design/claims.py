"""Scoring of study ``brown_design``: what the simulation produced, per claim of the claim book
``claims.toml`` (seed ``004``). The verdicts follow from :mod:`sim.claims.book`'s rules; nothing
here knows a paper number except through the book.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.intervals import binomial_ci
from sim.claims.rules import MIN_CHAIN_TAU
from sim.claims.table import Sim, claim_rows, exact, mc, plates
from sim.instruments.ranges import multilateration as ml
from sim.mc.config import StudyError
from sim.studies.design.errbudget import BUDGET_ROWS

__all__ = ["BOOK", "load_book", "EXTERNAL", "score_external", "score_all"]

BOOK = Path(__file__).with_name("claims.toml")


def load_book() -> ClaimBook:
    return ClaimBook.load(BOOK)


def _central_half(x):
    q25, med, q75 = np.percentile(x, [25, 50, 75])
    return {"value": float(med), "elems": (np.array([q25]), np.array([q75]))}


#: claims computed from :func:`.external.external_at` (decided over the region, :mod:`.region`):
#: id -> (function of the external values giving the score's keyword arguments, note)
EXTERNAL = {
    "brown.operation.lateral_offset_error_um": (
        lambda e: {"value": e["lateral_error_um"], "interval": "exact"},
        lambda e: f"d^2 / (2 r_min) at the plate's shortest range r_min = {e['r_min_mm']:.1f} mm",
    ),
    "brown.calibration.linearity_tolerance_um": (
        lambda e: {"value": e["linearity_tol_um"], "interval": "exact"},
        lambda e: (
            f"lateral offset d with d^2 / (2 r_min) = the accuracy, at r_min = "
            f"{e['r_min_mm']:.1f} mm"
        ),
    ),
    "brown.calibration.drum_graduation_um": (
        lambda e: {"value": e["drum_graduation_um"], "interval": "exact"},
        lambda e: "the dividing error as a fraction of one turn of the screw (pitch not printed)",
    ),
    "brown.results.two_screw_agreement_um": (
        lambda e: _central_half(e["two_screw_rms"]),
        lambda e: (
            "one plate's rms discrepancy with a two-screw comparator (its error not printed: "
            "explored over the region; the labelled example takes the paper's equal "
            "attribution, sqrt(2) x the plate's rms), Table 1's plate and error model, "
            "linearised; the interval is the central half of the plates ('usually')"
        ),
    ),
    "brown.results.zeiss_discrepancy_um": (
        lambda e: {"samples": e["zeiss_rms"]},
        lambda e: (
            "stand-in layout of zeiss.points 1 cm intersections (drawn from zeiss.layout_seed), Table 1's "
            "error model plus the grid's stated error, linearised"
        ),
    ),
    "brown.results.zeiss_comparator_um": (
        lambda e: {"samples": e["zeiss_comparator_rms"]},
        lambda e: "the comparator's part of the Zeiss comparison alone (no grid error)",
    ),
}


def score_external(book: ClaimBook, cid: str, e: dict) -> dict:
    kw, note = EXTERNAL[cid]
    return book.score(cid, note=note(e), **kw(e))


def verdict_of(book: ClaimBook, cid: str, e: dict) -> dict:
    """The row of one external claim on a throwaway copy of its spec (at one input vector)."""
    return score_external(ClaimBook([book.spec(cid)], [], book.path), cid, e)


#: the error-budget sources scored as claims ``brown.budget.<source>_um``
BUDGET_CLAIMS = (
    "scale",
    "scale_spec",
    "screw",
    "drum_periodic",
    "wobble_3kg",
    "wobble_3kg_h1",
    "sphericity",
)

#: the design rows (:mod:`.cells`), each an exact value with its note in ``R["design"]``
DESIGN_CLAIMS = (
    "brown.design.paper_on_pareto_front",
    "brown.design.paper_on_front_same_setting_sigma",
    "brown.design.paper_on_front_same_points",
    "brown.design.paper_worst_sigma_um",
    "brown.design.max_offset_paper_grid_mm",
    "brown.design.max_offset_dilution_grid_mm",
)


def scored_ids(cfg: dict, book: ClaimBook) -> list[str]:
    """The ids :func:`score_all` builds: the budget's sources (:func:`_budget`), the datum
    rows (:func:`_design`), the coverages (:func:`_coverage`) and the posterior's parameters
    (:func:`_bayes`, :data:`sim.instruments.ranges.multilateration.PARAM_NAMES`)."""
    return [
        *(f"brown.budget.{name}_um" for name in BUDGET_CLAIMS),
        *(
            f"brown.datum.{lab}.{m}_pct"
            for m in ("stations", "pivot")
            for lab in ("brown", "invariant", "corners")
        ),
        *(
            f"coverage.{m}.{key}"
            for m in ("pivot", "affine")
            for key in ("coverage_known", "coverage_f", "false_alarm", "sigma0_over_c4")
        ),
        *(f"bayes.brown_agreement.{nm.rsplit('_', 1)[0]}" for nm in ml.PARAM_NAMES),
    ]


def _operation(cfg: dict, R: dict) -> dict[str, Sim]:
    """Calibration and operation: the axis tilt, the paper's arithmetic, the time model."""
    return {
        "brown.calibration.axis_tilt_deg": exact(
            R["external"]["axis_tilt_deg"],
            f"atan(accuracy / gap) at {cfg['calibration.accuracy_um']:g} um over the gap "
            f"operation.gap_um = {cfg['operation.gap_um']:g} um (the paper's larger printed gap "
            "is 100 um, the worst case)",
        ),
        "brown.calibration.scale_combined_um": exact(
            math.hypot(0.5, 0.2), "recomputed from the paper's 0.5 and 0.2 micron"
        ),
        "brown.results.accuracy_range_um": Sim(
            elems=(np.array([2, 3]) / math.sqrt(2),) * 2,
            interval="exact",
            note=(
                "the paper's own arithmetic on its two-screw agreement (+-2 to +-3 um) under "
                "its stated equal attribution: 2 / sqrt 2 = 1.41 and 3 / sqrt 2 = 2.12 um; "
                "what the simulation predicts of it is the two-screw row (one printed "
                "statement, one prediction)"
            ),
        ),
        "brown.operation.measurements_per_point": exact(
            cfg["paper.positions"] * 2, "positions x 2 settings"
        ),
        "brown.operation.single_settings_min": exact(
            R["time"][0],
            f"the time model at {cfg['time.images']} images, 4 positions, single settings",
        ),
        "brown.operation.double_settings_min": exact(
            R["time"][1],
            f"the time model at {cfg['time.images']} images, 4 positions, double settings",
        ),
    }


def _budget(R: dict) -> dict[str, Sim]:
    """The error budget (adaptive Monte Carlo, :mod:`.errbudget`): each source alone, the
    Table-1 model against its linearisation, the closure of the named elements."""
    b = R["budget"]
    B = {s: (r, se, n) for s, r, se, n in zip(b["source"], b["rms_um"], b["se_um"], b["trials"])}
    desc = {n: d for n, _, _, d in BUDGET_ROWS}
    table = {}
    for name in BUDGET_CLAIMS:
        r, se, n = B[name]
        table[f"brown.budget.{name}_um"] = mc(
            r,
            se,
            f"rms coordinate error after a rigid fit, this source alone "
            f"({desc[name]}); {n} trials (adaptive) to a standard error of "
            f"{se:.2g} um; setting error alone: {B['setting'][0]:.3f} um",
        )
    r, se, n = B["table1_model"]
    lin = float(np.sqrt(np.mean(R["external"]["table1_rms"] ** 2)))
    table["brown.budget.table1_model_mc_vs_linear"] = Sim(
        r / lin,
        ((r - 1.96 * se) / lin, (r + 1.96 * se) / lin),
        note=f"rms of the Monte Carlo (Table 1's model, pivot solver) over "
        f"the linearised plate model's {lin:.3f} um",
    )
    prod = R["budget_sims"]["production"]
    table["brown.budget.closure_named_elements_um"] = plates(
        prod["s0_um"][prod["ok"]],
        "sigma0 of the pivot adjustment with the settings and the "
        "calibrated scale and screw only (no other comparator error)",
    )
    return table


def _design(R: dict) -> dict[str, Sim]:
    """The design trade-off (:mod:`.cells`) and the datum of the dilution (:mod:`.dilution`)."""
    table = {cid: exact(*R["design"][cid]) for cid in DESIGN_CLAIMS}
    v, ci, note = R["mc_ratio"]
    table["brown.design.mc_agreement.pooled_ratio"] = Sim(v, ci, note=note)
    dr = R["datum"]
    ideal = (
        ""
        if dr["feasible"]
        else (
            f" Idealised: the longest range, {dr['max_range_mm']:.1f} "
            "mm, does not fit the scale plus micrometer."
        )
    )
    for m in ("stations", "pivot"):
        for dn, lab in (("brown", "brown"), ("inner", "invariant"), ("corners", "corners")):
            lo, hi = dr[(m, dn)]
            table[f"brown.datum.{lab}.{m}_pct"] = Sim(
                lo,
                (lo, lo),
                "exact",
                value_high=hi,
                note=f"per-point dilution {lo:.1f} to {hi:.1f} % "
                f"(analytic); {dr['geometry']}.{ideal}",
            )
    return table


def _coverage(R: dict) -> dict[str, Sim]:
    """Formal against empirical (:mod:`.formal`), nominal scenario of each model."""
    c = R["coverage"]
    model, scen = np.array(c["model"]), np.array(c["scenario"])
    table = {}
    for m in ("pivot", "affine"):
        i = int(np.flatnonzero((model == m) & (scen == "nominal"))[0])
        N = c["trials"][i]
        if N < 2:  # the load check keeps the noise small (checks.NOISE_SHARE); a guard
            raise StudyError(
                f"brown_design: the nominal {m} coverage has {N} converged trials of "
                f"{N + c['nonconverged'][i]}: nothing to compute it from (lower coverage.sigma_um)"
            )
        for key in ("coverage_known", "coverage_f", "false_alarm"):
            v = c[key][i]
            # a proportion: the Wilson interval over the N trials (the false alarms are
            # counts; a coverage is a per-trial average over points, for which N is
            # conservative), never v +- 1.96 se, which left [0, 1] and shrank to [0, 0]
            # when no trial rejected (docs/verdict-rules.md, "Rules about sizes")
            k = min(max(round(v * N) if key == "false_alarm" else v * N, 0.0), N)
            _, lo, hi = binomial_ci(k, N)
            table[f"coverage.{m}.{key}"] = Sim(
                v,
                (float(lo), float(hi)),
                note=f"empirical rate over {N} trials x {c['grid'][i] ** 2} "
                f"points; Wilson interval over trials",
            )
        table[f"coverage.{m}.sigma0_over_c4"] = mc(
            c["s0_ratio"][i] / c["s0_expected"][i],
            c["s0_ratio_se"][i] / c["s0_expected"][i],
            f"E[s0] / sigma = {c['s0_ratio'][i]:.4f} on {c['dof'][i]} "
            f"degrees of freedom, c4 = {c['s0_expected'][i]:.4f}; E[s0^2] / "
            f"sigma^2 = {c['s0sq_ratio'][i]:.4f}",
        )
    return table


def _bayes(R: dict) -> dict[str, Sim]:
    """The emcee cross-check (:mod:`.posterior`): posterior against least-squares sigmas."""
    by = R["bayes"]
    n_tau = by["chain_tau"]
    length = f"{by['kept']} kept steps = {n_tau:.1f} tau (shortest chain, slowest parameter)"
    if n_tau >= MIN_CHAIN_TAU:
        length += f", at least {MIN_CHAIN_TAU} as emcee's rule asks"
    table = {}
    for nm, (v, se, tau, neff) in by["ratio"].items():
        table[f"bayes.brown_agreement.{nm.rsplit('_', 1)[0]}"] = Sim(
            float(v),
            (float(v - 1.96 * se), float(v + 1.96 * se)),
            note=f"posterior / least-squares sigma, one plate; {by['chains']} "
            f"chains x {by['steps']} steps x {by['walkers']} walkers; tau = "
            f"{tau:.0f} steps, N_eff = {neff:.0f}; {length}; interval +-1.96 MC s.e.",
            chain_tau=n_tau,
        )
    v, se, a, bb = by["max_corr_diff"]
    table["bayes.brown_agreement.max_corr_diff"] = mc(
        v,
        se,
        f"largest at ({a}, {bb}); {length}; interval +-1.96 MC s.e. of that correlation",
        chain_tau=n_tau,
    )
    return table


def _twoplate(tp: dict | None) -> dict[str, Sim | None]:
    """The two-plate variance components (seed 001), or nothing when that part is off."""
    if tp is None:
        return {"bayes.twoplate_ratio": None, "bayes.twoplate_ratio.flat_prior_decades": None}
    j, f = tp["prior"].index("certificate"), tp["prior"].index("flat")
    return {
        "bayes.twoplate_ratio": Sim(
            tp["rho_median"][j],
            (tp["rho_q025"][j], tp["rho_q975"][j]),
            "spread",
            note=f"posterior median and 95 % interval of sigma_c^2 / "
            f"sigma_g^2 with the certificate prior on sigma_g, by quadrature; re-weighting "
            f"{tp['rw_ratio_mean'][j]:.2f}, truth {tp['true_ratio'][j]:.2f}",
        ),
        "bayes.twoplate_ratio.flat_prior_decades": Sim(
            tp["log10_width"][f],
            (tp["log10_width"][f] - tp["quad_err"][f], tp["log10_width"][f] + tp["quad_err"][f]),
            "exact",
            note="width (decades) of the 95 % posterior interval of the ratio with log-uniform "
            "priors on both sigmas, by quadrature (interval: its error): the misclosures fix "
            "only sigma_c^2 + (A^2 + B^2) sigma_g^2, so the ratio's posterior is flat between "
            "the prior's bounds (1e-3 to 1e3 um) and the width is theirs, not the data's; the "
            f"chains give {tp['chain_log10_width'][f]:.2f} decades at "
            f"{tp['chain_tau'][f]:.1f} autocorrelation times",
        ),
    }


def _at_level(book: ClaimBook, alpha: float) -> None:
    """The chi-square test runs at ``coverage.alpha``: its false-alarm rate is checked against
    that level (the book states the default 5 %, tolerance 1 point), not against 5 %."""
    for m in ("pivot", "affine"):
        cid = f"coverage.{m}.false_alarm"
        s = book.spec(cid)
        if s["ref"] != alpha:
            book.specs[cid] = {**s, "ref": alpha, "tol": s["tol"] * alpha / s["ref"]}


def score_all(book: ClaimBook, cfg: dict, R: dict) -> list[dict]:
    """The rows of brown_design not decided over the region (the EXTERNAL rows come from
    :mod:`.region`; ``R["external"]`` is at the labelled example)."""
    _at_level(book, cfg["coverage.alpha"])
    table = {
        **_operation(cfg, R),
        **_budget(R),
        **_design(R),
        **_coverage(R),
        **_bayes(R),
        **_twoplate(R.get("twoplate")),
    }
    return claim_rows(book, table)
