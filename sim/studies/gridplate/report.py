"""Report section of ``gridplate_two_plates`` (seed 001): built from the study's Parquet files
and its claim book only (no model code), on the shared skeleton :mod:`sim.report.section`.
Sigmas in um, scale in ppm, angles in arcsec."""

from __future__ import annotations

from pathlib import Path

from sim.report.section import config, errata, figure, region_lead, rows, section, table
from sim.report.tables import fmt, md_table
from sim.studies.gridplate.schema import SCHEMA

PARAM_LABEL = {"S": "S", "S2": "S'", "eps": "eps"}

_MODEL = (
    "**Model.** Grid -> comparator affine `x' = A1 x + B1 y + c1`, `y' = A2 x + B2 y + c2` "
    "(the paper's equation 2), decomposed by rows: `S = 1/sqrt(A1^2+B1^2)`, "
    "`S' = 1/sqrt(A2^2+B2^2)`, `phi' - phi = pi/2 - eps`. The combined adjustment carries "
    "`(A, B, C)` and the adjusted grid coordinates as unknowns, x' and y' apart. With "
    "`P_x = 1` and equal weights it is, to first order, the affine fit with the misclosure "
    "cofactor `1 + (A^2+B^2)/P_cx`: the weight-ratio sweeps use that closed form, checked "
    "against the iterated adjustment (`twoplate.self_check.closed_form`). The paper's "
    "re-weighting has the fixed point `P_cx = s_w^2/sg^2 - (A^2+B^2)`: after it the "
    "chi-square test passes by construction (only `sx'^2 + sg^2` is estimable from one "
    "plate), so the test cannot confirm the stated grid sigma."
)


def _intro(cfg: dict) -> str:
    k, n = cfg["plate.grid"], cfg["plate.count"]
    return (  # plate.count = 1: "1 grid plates" (doors25a)
        f"Simulated calibrations of a comparator with {n} grid plate{'s' * (n != 1)} of "
        f"{k} x {k} points at {cfg['plate.spacing_mm']:g} mm, each on its carrier with "
        f"|kappa| <= {cfg['plate.kappa_deg']:g} deg, {cfg['readings.count']} readings per point "
        f"of {cfg['readings.sigma_um']:g} um, a mean comparator coordinate of "
        f"{cfg['comparator.coord_sigma_um']:g} um, grid coordinates of "
        f"{cfg['grid.sigma_true_um']:g} um (stated {cfg['grid.sigma_stated_um']:g} um), "
        f"{cfg['trials']} calibrations (seed {cfg['seed']}). The paper's numbers describe one "
        "calibration, so they are scored as one-plate statistics: where the paper's value "
        "falls among simulated calibrations (`p`), and whether the simulation is sharp enough "
        "to decide. The configured grid, scale difference and true grid sigma are one example "
        "point: the predictions above are decided over the whole region."
    )


def _implied(out: Path) -> list[str]:
    imp = table(out, "implied_grid.parquet")
    return [
        "**Grid sigma implied by the weight ratio** (`s0/sqrt(P_cx)`, median and 95 % range):",
        md_table(
            ["P_cx : P_x", "median (um)", "95 % range (um)"],
            [
                [fmt(r), fmt(m), f"{fmt(lo)}-{fmt(hi)}"]
                for r, m, lo, hi in zip(imp["ratio"], imp["median"], imp["lo"], imp["hi"])
            ],
        ),
        figure(out, "implied_grid.png", "implied grid sigma"),
    ]


def _beyond(out: Path) -> list[str]:
    cols = ("param", "method", "bias", "bias_lo", "bias_hi", "sd", "stated_sd_rms", "unit")
    be = table(out, "beyond.parquet")
    return [
        "**Beyond the paper: grid fixed versus weighted.** Errors of the recovered parameters "
        "over all simulated plates; `stated sd` is the rms of the stated standard deviations "
        "(grid fixed: a-posteriori s0; weighted: a-priori weights).",
        md_table(
            ["parameter", "method", "bias", "95 % CI", "sd", "stated sd", "unit"],
            [
                [p, m, fmt(b), f"[{fmt(lo)}, {fmt(hi)}]", fmt(s), fmt(st), u]
                for p, m, b, lo, hi, s, st, u in zip(*(be[c] for c in cols))
            ],
        ),
    ]


def _coverage(out: Path) -> list[str]:
    cov = table(out, "coverage.parquet")
    header = (
        ["P_cx : P_x"]
        + [f"{PARAM_LABEL[p]} a-priori" for p in PARAM_LABEL]
        + [f"{PARAM_LABEL[p]} a-post." for p in PARAM_LABEL]
    )
    body = [
        [fmt(r)]
        + [fmt(cov[f"{p}_pri"][i]) for p in PARAM_LABEL]
        + [fmt(cov[f"{p}_post"][i]) for p in PARAM_LABEL]
        for i, r in enumerate(cov["ratio"])
    ]
    fixed = (
        ["grid fixed"]
        + [fmt(cov[f"{p}_fixed_pri"][0]) for p in PARAM_LABEL]
        + [fmt(cov[f"{p}_fixed_post"][0]) for p in PARAM_LABEL]
    )
    return [
        "Coverage of the nominal 95 % intervals:",
        md_table(header, [*body, fixed]),
        figure(out, "coverage.png", "coverage")
        + "\n"
        + figure(out, "parameters.png", "parameters"),
    ]


def _chi2(out: Path, cfg: dict) -> list[str]:
    ch = table(out, "chi2_power.parquet")
    cols = ("stated_um", "reject", "lo", "hi", "analytic")
    return [
        "**Chi-square test with a wrong stated grid sigma** (fixed a-priori weights "
        f"`P_x = 1/sx'^2`, `P_cx = 1/sg_stated^2`, two-sided at {cfg['analysis.alpha']:g}, "
        "one test per coordinate and plate):",
        md_table(
            ["stated sigma (um)", "rejection rate", "95 % CI", "analytic"],
            [
                [fmt(s), fmt(r), f"[{fmt(lo)}, {fmt(hi)}]", fmt(a)]
                for s, r, lo, hi, a in zip(*(ch[c] for c in cols))
            ],
        ),
        figure(out, "chi2_power.png", "chi-square"),
    ]


def _closing(out: Path, claims: list[dict]) -> list[str]:
    c = {r["claim"]: r for r in claims}

    def v(k, f="value"):
        r = c.get(k)
        return fmt(r[f]) if r is not None and r[f] is not None else "n/a"

    return [
        "Residual vectors of one simulated calibration (plate 1): "
        + figure(out, "residuals.png", "residuals"),
        f"Re-weighted ratio (median {v('twoplate.weight_ratio.converged_ratio')}), comparator "
        f"sigma (median {v('twoplate.comparator_sigma.sigma_um')} um).",
    ]


def report(out: Path) -> str:
    """The section of ``gridplate_two_plates``: the predictions over the region, the paper's
    reduction, then the weightings, the fixed-versus-weighted comparison and the test."""
    out = Path(out)
    cfg = config(out)["config"]
    claims = rows(out, "claims.parquet")
    adj = 2 * cfg["plate.count"] * cfg.get("region.iter_calibrations", 1)  # results before it: 1
    return section(
        out,
        lead=[
            region_lead(
                out,
                "The paper's weighting, iteration and similarity-versus-affine predictions",
                values=f"each input vector's statistics drawn from their exact sampling "
                f"distributions, {cfg['region.draws']} simulated calibrations per vector, whose "
                "noise enters the decision; the combined adjustment's Gauss-Newton iterations "
                f"counted by running it on {adj} adjustments per vector",
            ),
            figure(out, "consistent_region.png", "consistent region"),
        ],
        intro=[_intro(cfg), _MODEL, errata(claims)],
        schema=SCHEMA,
        body=[
            *_implied(out),
            *_beyond(out),
            *_coverage(out),
            *_chi2(out, cfg),
            *_closing(out, claims),
        ],
    )
