"""brown_design's Bayesian self-checks decided on emcee's reliability rule (sweep doors40b).

``bayes.brown_agreement.*`` (posterior against least-squares sigma of Brown's 7 globals, and
the largest correlation difference) were decided on +-1.96 Monte-Carlo standard errors from
``N_eff = kept steps x walkers / tau``, with tau from ``emcee.autocorr.integrated_time(...,
tol=0)``: emcee's own rule (a chain at least 50 tau long, ``tol = 50``) switched off. The
committed run (32 walkers x 500 steps x 4 chains) kept 375 steps, 11.8 tau of its slowest
parameter, and all eight rows held. On such a chain tau itself is underestimated (27 steps on
375 kept, 55 on 1,500, 73 on 6,000), and at 375 the spread of 16 independent chains was up to
1.4 times the error from tau: the intervals were too narrow to decide on, silently.

Now a Monte-Carlo interval from a sampler chain is decided only on chains of at least
``MIN_CHAIN_TAU = 50`` autocorrelation times (``sim.claims.rules``; docs/verdict-rules.md),
otherwise inconclusive, the note saying on how many; brown_design's ``bayes.steps`` is 8,000
(6,000 kept, about 70 tau: the eight rows hold on intervals of +-0.014 instead of +-0.033).
The last test checks the sampler against an analytic posterior at the rule's length, with a
tolerance of 4 of its standard errors, and that those errors are honest there; it imports the
rule's constant, absent before the fix.
"""

from __future__ import annotations

import importlib
import math
from pathlib import Path

import numpy as np

from sim.claims.rules import MIN_CHAIN_TAU, decide
from sim.claims.table import claim_rows
from sim.instruments.ranges import bayes
from sim.mc.runner import chunk_rng
from sim.studies import load_study
from sim.studies.design import claims as dc

post = importlib.import_module("sim.studies.design.posterior")
ROOT = Path(__file__).resolve().parents[1]

#: the committed run's numbers (results/brown_design, 4 chains x 500 steps x 32 walkers)
COMMITTED = {
    "ratio": {
        "y1_mm": (0.9925, 0.0171, 28.7, 1686.0),
        "x2_mm": (0.9924, 0.0169, 27.8, 1729.0),
        "y2_mm": (1.0129, 0.0170, 27.1, 1779.0),
        "y3_mm": (0.9904, 0.0168, 27.8, 1736.0),
        "x4_mm": (1.0144, 0.0172, 27.8, 1730.0),
        "alpha_mm": (0.9939, 0.0165, 26.4, 1824.0),
        "beta2_mm2": (0.9872, 0.0159, 25.1, 1916.0),
    },
    "max_corr_diff": (0.0506, 0.0240, "x4_mm", "y2_mm"),
    "chains": 4,
    "steps": 500,
    "walkers": 32,
    "kept": 375,
}


def _outcomes(vals: dict) -> dict[str, dict]:
    rows = claim_rows(dc.load_book(), dc._bayes({"bayes": vals}))
    return {r["claim"]: r for r in rows}


def test_the_committed_self_checks_on_a_chain_of_12_tau_are_inconclusive_not_held():
    short = _outcomes({**COMMITTED, "chain_tau": 11.8})
    assert len(short) == 8
    for cid, r in short.items():
        assert r["outcome"] == "inconclusive", cid
        assert r["note"].startswith(
            "inconclusive on a chain of 11.8 autocorrelation times: a verdict on a sampler's "
            "chain needs 50 (emcee's rule; raise its steps)"
        ), r["note"]
        assert "375 kept steps = 11.8 tau" in r["note"]
    # the same intervals on a chain long enough hold, and say they met the rule
    long = _outcomes({**COMMITTED, "chain_tau": 69.6})
    assert {r["outcome"] for r in long.values()} == {"holds"}
    assert all("at least 50 as emcee's rule asks" in r["note"] for r in long.values())


def test_the_rule_at_its_threshold_and_a_short_chain_cannot_fail_either():
    inside, outside, z = (0.96, 1.03), (1.2, 1.3), (0.9, 1.1)
    assert decide("value", inside, z, chain_tau=MIN_CHAIN_TAU) == "holds"
    assert decide("value", inside, z, chain_tau=math.nextafter(50.0, 0.0)) == "inconclusive"
    assert decide("value", outside, z, chain_tau=49.0) == "inconclusive"
    assert decide("value", outside, z, chain_tau=50.0) == "fails"
    assert decide("upper", (0.0, 0.05), (-math.inf, 0.1), chain_tau=math.nan) == "inconclusive"
    assert decide("value", inside, z) == "holds"  # no chain: as before


def test_a_real_short_chain_is_measured_in_tau_and_leaves_the_rows_undecided(monkeypatch):
    def serial(fn, n, seed, size, part, label, ctx, units=None):  # the runner's chunks, one by one
        outs = [fn(chunk_rng(seed, part, c), 1) for c in range(n)]
        return {k: np.concatenate([o[k] for o in outs]) for k in outs[0]}

    monkeypatch.setattr(post, "run_chunks", serial)
    run = importlib.import_module("sim.studies.design.run")
    over = ["bayes.steps=200", "bayes.chains=2", "bayes.walkers=16"]
    cfg = load_study(ROOT / "studies" / "brown_design.toml", over)[1]
    pts, _, sr = run._paper_plate(cfg)
    _, vals, _ = post.bayes_analysis(cfg, pts, sr, None)
    assert vals["kept"] == 150
    assert vals["chain_tau"] < MIN_CHAIN_TAU
    rows = _outcomes(vals)
    assert {r["outcome"] for r in rows.values()} == {"inconclusive"}


def test_emcee_against_the_analytic_linear_posterior_at_the_rules_length():
    """y = A x + N(0, 0.2^2): the posterior is N(x_hat, sigma^2 (A^T A)^-1). Six independent
    ensembles of 16 walkers x 4,000 steps (3,000 kept, about 65 tau): each meets the rule; the
    pooled mean and sd agree with the analytic ones within 4 standard errors from tau; the
    chains' own spread of the sd ratio is within 1.5 of that error per chain (honest, as the
    rule presumes); 200 steps decide nothing."""
    rng = np.random.default_rng(40)
    A = np.column_stack([np.ones(12), np.linspace(-1, 1, 12), np.linspace(-1, 1, 12) ** 2])
    sigma, W, steps = 0.2, 16, 4000
    y = A @ np.array([0.3, -1.2, 0.7]) + rng.normal(0, sigma, 12)
    cov = sigma**2 * np.linalg.inv(A.T @ A)
    sd, x_hat = np.sqrt(np.diag(cov)), np.linalg.solve(A.T @ A, A.T @ y)
    lp = bayes.linear_log_posterior(A, y, sigma)
    chs = [
        bayes.run_emcee(
            lp, rng.multivariate_normal(x_hat, cov, W), steps, np.random.SeedSequence([40, c])
        )
        for c in range(6)
    ]
    kept = steps - steps // 4
    assert min(kept / c.tau.max() for c in chs) >= MIN_CHAIN_TAU
    X = np.concatenate([c.samples for c in chs])
    n_eff = sum(kept * W / c.tau for c in chs)
    ratio = X.std(0, ddof=1) / sd
    assert np.all(np.abs(ratio - 1) <= 4 * ratio / np.sqrt(2 * n_eff))
    assert np.all(np.abs(X.mean(0) - x_hat) <= 4 * sd / np.sqrt(n_eff))
    per_chain = np.array([c.samples.std(0, ddof=1) / sd for c in chs])
    se_chain = per_chain / np.sqrt(2 * kept * W / np.array([c.tau for c in chs]))
    assert np.all(per_chain.std(0, ddof=1) <= 1.5 * se_chain.mean(0))
    short = bayes.run_emcee(lp, chs[0].samples[:W], 200, np.random.SeedSequence([40, 99]))
    # emcee's per-walker estimate gave half the long chains' tau here; about the ensemble's
    # mean (sim.instruments.ranges.autocorr, doors44v) it is not underestimated so
    assert short.tau.max() > 0.5 * np.mean([c.tau.max() for c in chs])
    assert (200 - 50) / short.tau.max() < MIN_CHAIN_TAU
