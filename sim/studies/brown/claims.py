"""Scoring of the Brown claims (the claim book ``claims.toml``) from what the runs produced.

The book holds the paper's words, forms, references and deciding tolerances; this module
only supplies values: analytic predictions for the nominal geometry (the same functions as
the sweep, :mod:`.values`), Monte-Carlo distributions of one-plate statistics, and the
self-checks of Monte Carlo against the analytic covariance. Seed paper 004 (Brown 1968).
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np
from scipy import optimize

from sim.claims.book import ClaimBook
from sim.claims.declaration import read_toml
from sim.claims.intervals import std_rel_se
from sim.claims.table import Sim, claim_rows, exact, plates
from sim.instruments.ranges import brown as B
from sim.instruments.ranges import multilateration as ml
from sim.mc.config import ConfigError
from sim.mc.runner import chunk_rng
from sim.studies.brown import values as V
from sim.studies.brown.core import BIAS_TOL_MM, spread_sigma
from sim.studies.brown.schema import MODEL_NAMES, TABLE1, range_sigma_um

BOOK = Path(__file__).with_name("claims.toml")


#: the keys of a Table 1 row that its one declaration gives (the printed number and its zone)
PRINTED_KEYS = ("form", "ref", "decimals", "tol")


def full_book() -> ClaimBook:
    """The whole claim book. The rows of Table 1's printed statements take their printed
    number and zone (:data:`PRINTED_KEYS`) from their one declaration,
    :data:`sim.instruments.ranges.brown.TABLE1`, which brown_design's region uses too; a row
    that states one of them again is refused, naming it."""
    data = read_toml(BOOK, "claim book")
    bad = set(data) - {"claim", "not_reproduced"}
    if bad:
        raise ConfigError(sorted(bad)[0], f"{BOOK}: unknown table")
    printed = B.TABLE1["statements"]
    specs = []
    claims = data.get("claim", [])
    if not isinstance(claims, list) or not all(isinstance(s, dict) for s in claims):
        raise ConfigError("claim", f"{BOOK}: [[claim]] must be a list of tables")
    for s in claims:
        decl = printed.get(s.get("id"), {})
        again = [k for k in PRINTED_KEYS if k in decl and k in s]
        if again:
            raise ConfigError(
                f"claim.{again[0]}",
                f"{BOOK} ({s['id']}): declared once, in sim.instruments.ranges.brown.TABLE1",
            )
        specs.append({**s, **{k: decl[k] for k in PRINTED_KEYS if k in decl}})
    return ClaimBook(specs, data.get("not_reproduced", []), str(BOOK))


def load_book(study: str) -> ClaimBook:
    """The part of the claim book that ``study`` scores: ids ``brown.table1*`` and the
    *Results* section for ``brown_table1``, the rest for ``brown_dilution``."""
    full = full_book()
    t1 = study == "brown_table1"
    specs = [s for cid, s in full.specs.items() if scored_by(study)(cid)]
    nr = [n for n in full.not_reproduced if ("Results" in n["source"]) == t1]
    return ClaimBook(specs, nr, str(BOOK))


def scored_by(study: str) -> Callable[[str], bool]:
    """Whether ``study`` scores the claim id (the book's split of :func:`load_book`)."""
    t1 = study == "brown_table1"
    return lambda cid: cid.startswith("brown.table1") == t1


def _pt(pts, j) -> str:
    return f"point {j + 1} ({pts[j, 0]:g}, {pts[j, 1]:g}) mm"


def mc_agreement(mc, i, a, trials, why: str = "") -> Sim:
    """Mean over coordinates of MC sigma / reference sigma ``a`` (jackknife CI over chunks);
    ``why``: what the reference is, when it is not the analytic covariance at the truth."""
    band = 1.96 * std_rel_se(mc.N)
    v, *ci = mc.jack(lambda sd: (sd[i] / a).mean())
    r = mc.sd[i] / a
    return Sim(
        v,
        tuple(ci),
        note=(
            f"{int((np.abs(r - 1) < band).sum())} of {r.size} coordinates inside the 95 % sampling "
            f"band +-{band:.3f}; {mc.N} of {trials} trials converged in all models"
            + (f"; {why}" if why else "")
        ),
    )


def biased_reference(cfg, pts, theta, mc, i, m, a) -> tuple[np.ndarray, str]:
    """The reference of model ``m``'s self-check (``a``: its analytic sigmas, um) and what
    the note says of it: the analytic covariance on unbiased ranges; with ``errors.bias_um``
    the first-order spread at the biased ranges (:func:`.core.spread_sigma`), which is the
    analytic one for a model that absorbs the bias and wider for one that cannot."""
    b = cfg["errors.bias_um"]
    if b == 0:
        return a, ""
    ref = spread_sigma(pts, theta, m, range_sigma_um(cfg), b)
    how = "absorbs in alpha" if m == "pivot" else "cannot absorb (its residuals widen the spread)"
    return ref, (
        f"reference: the first-order spread of this model's coordinates at ranges carrying "
        f"errors.bias_um = {b:g} um, which it {how}; against the analytic covariance at "
        f"the true values the ratio is {(mc.sd[i] / a).mean():.4f}"
    )


def min_points_stations(cfg: dict, theta: np.ndarray) -> tuple[int, str]:
    """Smallest n for which the ``stations`` normal equations are regular (n generic points
    inside the format, drawn once from stream part 98)."""
    half = cfg["plate.format_mm"] / 2
    g = chunk_rng(cfg["seed"], 98, 0).uniform(-0.8 * half, 0.8 * half, (8, 2))
    reg = []
    for n in range(1, 9):
        Qgg = ml.covariance(g[None, :n], theta[None], "stations")[1]
        reg.append(bool(np.all(np.isfinite(Qgg))))
    n_min = 1 + reg.index(True) if any(reg) else 0
    return n_min, (
        "regular normal equations for n = "
        + ", ".join(str(n + 1) for n, r in enumerate(reg) if r)
        + " of 1-8 generic points; 4n equations, "
        "2n + 5 unknowns"
    )


def idealised_offset(cfg: dict, pts: np.ndarray) -> tuple[float, float]:
    """Offset (mm) at which the largest known-station ratio of the plate's pattern, scaled to
    ``idealised.half_extent_mm``, is 0.85, and its longest range (mm); NaN if none in
    0.5-300 mm."""
    e = cfg["idealised.half_extent_mm"]
    P = pts * (e / np.abs(pts).max())
    f = lambda o: (
        V.sigmas(
            P[None],
            V.thetas(cfg["plate.format_mm"], [o], 0.0, 0.0),  # noqa: E731
            "known",
        ).max()
        - 0.85
    )
    if not f(0.5) > 0 > f(300.0):
        return float("nan"), float("nan")
    o = optimize.brentq(f, 0.5, 300.0, xtol=1e-4)
    th = V.thetas(
        cfg["plate.format_mm"], [o], cfg["comparator.alpha_mm"], cfg["comparator.beta_mm"]
    )
    return float(o), float(ml.ranges(P[None], th).max())


def _idealised(cfg: dict, pts: np.ndarray) -> Sim:
    """The offset of the idealised four-station system (Figure 1) at the 0.85 ratio."""
    o, rmax = idealised_offset(cfg, pts)
    lim = cfg["comparator.scale_length_mm"] + cfg["comparator.micrometer_mm"]
    if not np.isfinite(o):
        return exact(-1.0, "no offset in 0.5-300 mm gives 0.85 (value -1: none)")
    return exact(
        o,
        f"idealised four-station system (Figure 1), not the built comparator: the offset at "
        f"which the largest known-station ratio of the pattern scaled to +-"
        f"{cfg['idealised.half_extent_mm']:g} mm is 0.85; its longest range is {rmax:.1f} mm "
        f"against {lim:g} mm of scale plus micrometer",
    )


def score_dilution(book, cfg, pts, theta, an, mc, sim, curve, extra, mono) -> list[dict]:
    """The rows of brown_dilution not decided over the region (:mod:`.region`): structure,
    bias invariance, findings and self-checks (an: model -> (n, 2) unit analytic sigmas)."""
    ex = (V.pooled(an["pivot"]) / V.pooled(an["stations"]) - 1) * 100
    k_last = max(curve)
    alpha = V.pooled(V.sigmas(pts[None], theta[None], "alpha")[0])
    a_only = float(((alpha / V.pooled(an["stations"]) - 1) * 100).max())
    n_min, n_note = min_points_stations(cfg, theta)
    nb = int(sim["bias.n"].sum())
    table = {
        "brown.dilution_falls_with_points.max_pct_largest_grid": exact(
            float(curve[k_last].max()),
            f"largest per-point dilution (%) of a {k_last} x {k_last} grid, same extent; "
            + ", ".join(f"{k * k} points: {curve[k].max():.1f} %" for k in curve),
        ),
        "brown.pivot_extra_dilution.alpha_only_max_pct": exact(
            a_only,
            "largest extra dilution (%) from freeing alpha "
            f"alone (beta^2 known); with beta^2 too: {ex.max():.2f} %",
        ),
        "brown.structure.min_points_stations": exact(n_min, n_note),
        "brown.bias_invariance.max_point_shift_mm": exact(
            sim["bias.max_point_shift_mm"].max(),
            f"largest coordinate change over {nb} Monte-Carlo plates when "
            f"{cfg['checks.bias_shift_um']:g} um is added to every range (pivot "
            "model); zero to rounding"
            + (
                f" (both adjustments converged to {BIAS_TOL_MM:g} mm, not the run's "
                f"solver.tol_mm = {cfg['solver.tol_mm']:g} mm)"
                if cfg["solver.tol_mm"] > BIAS_TOL_MM
                else ""
            ),
        ),
        "brown.bias_invariance.alpha_shift_error_mm": exact(
            sim["bias.alpha_err_mm"].max(),
            "largest |change of alpha + constant| over the same plates",
        ),
        "brown.idealised.offset_for_085_mm": _idealised(cfg, pts),
    }
    sr = range_sigma_um(cfg)  # an is per unit range sigma; the Monte Carlo is in um
    for i, m in enumerate(MODEL_NAMES):
        ref, why = biased_reference(cfg, pts, theta, mc, i, m, an[m] * sr)
        table[f"brown.mc_agreement.{m}.mean_ratio"] = mc_agreement(mc, i, ref, cfg["trials"], why)
    return claim_rows(book, table)


def _closure(cfg, s0, sr) -> dict[str, Sim]:
    """The closure rows of Table 1: sigma0 over plates, its typical range, the setting sigma."""
    q25, q75 = np.percentile(s0, [25, 75])
    inside = float(np.mean((s0 >= 1.45) & (s0 < 2.05)))
    n = cfg["errors.settings"]  # the inputs as configured (the paper's: 1.7 um, double, 1.1 um)
    word = {1: "single", 2: "double"}.get(n, f"{n} settings")
    return {
        "brown.table1_closure.rms_um": plates(
            s0,
            f"a-posteriori sigma0 of one plate over {len(s0)} simulated plates; its expectation is "
            f"the range sigma {sr:.2f} um built from {cfg['errors.setting_sigma_um']:g} um per "
            f"setting ({word}) and the comparator's {cfg['errors.comparator_sigma_um']:g} um, "
            "which the paper derived from this 1.6: agreement by construction",
        ),
        "brown.table1_closure.typical_range_um": Sim(
            float(q25),
            value_high=float(q75),
            interval="spread",
            elems=(np.array([q25]), np.array([q75])),
            note=(
                f"'typically': the middle half (25-75 %) of simulated plates' sigma0 ({q25:.2f}-"
                f"{q75:.2f} um) must lie in 1.5-2.0 um; {inside:.0%} of plates print inside. One "
                "comparator calibrated on Table 1; other production models may differ"
            ),
        ),
    }


def _setting(cfg, t1) -> Sim:
    if cfg["errors.settings"] > 1:
        run, paper = cfg["errors.setting_sigma_um"], TABLE1["errors.setting_sigma_um"].default
        whose = "the paper's" if run == paper else f"this run's, not the paper's {paper:g} um"
        return plates(
            t1["setting_sigma_um"],
            "recovered per plate from the differences of the repeated "
            f"settings; the simulated setting sigma is {run:g} um, {whose}",
        )
    return exact(
        cfg["errors.setting_sigma_um"],
        "single settings: the setting sigma cannot be recovered from the plate; the value is the input",
    )


#: the paper's own arithmetic (paper checks): claim id -> (value, how it is recomputed)
TABLE1_ARITHMETIC = {
    "brown.table1_setting.pair_mean_um": (1.7 / np.sqrt(2), "recomputed: 1.7 / sqrt(2)"),
    "brown.table1_closure.comparator_um": (
        float(np.sqrt(1.6**2 - 1.2**2)),
        "recomputed: sqrt(1.6^2 - 1.2^2)",
    ),
    "brown.table1_external.equal_share_low_um": (2 / np.sqrt(2), "recomputed: 2 / sqrt(2)"),
    "brown.table1_external.equal_share_high_um": (3 / np.sqrt(2), "recomputed: 3 / sqrt(2)"),
    "brown.table1_external.zeiss_comparator_um": (
        float(np.sqrt(1.5**2 - 0.8**2)),
        "recomputed: sqrt(1.50^2 - 0.8^2)",
    ),
}


def score_table1(book, cfg, pts, an_pivot, sr, mc, t1) -> list[dict]:
    """The rows of brown_table1 not decided over the region (:mod:`.region`): the closure,
    the paper's arithmetic, self-checks. ``t1``: per-plate statistics of the converged trials."""
    dof = 4 * len(pts) - (2 * len(pts) + 7)
    table = {
        "brown.table1_closure.dof": exact(dof, "4n ranges - (2n + 7) unknowns of the pivot model"),
        **_closure(cfg, t1["sigma0_um"], sr),
        "brown.table1_setting.sigma_um": _setting(cfg, t1),
        **{cid: exact(v, note) for cid, (v, note) in TABLE1_ARITHMETIC.items()},
        "brown.table1_mc_agreement.pivot.mean_ratio": mc_agreement(mc, 2, an_pivot, cfg["trials"]),
    }
    return claim_rows(book, table)
