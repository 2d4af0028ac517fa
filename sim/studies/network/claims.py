"""The claims of a network study: self-checks with decision zones stated a priori, and the
design figures as findings. The book is built in code (a network study has no paper): Monte
Carlo within 5 % of analytic, coverage and false-alarm rate within 2 points of their nominal
values (the false-alarm rate within 40 % of ``test.alpha`` below 5 %, see :func:`alarm_tol`),
redundancy numbers summing to the degrees of freedom to 1e-6. The findings (exact,
analytic) let a ``[sweep]`` over any key tabulate them per cell: the largest and the rms point
sigma, the largest 95 % semi-axis, the smallest redundancy number, the largest MDB of a length
observation and the largest dilution against ``compare.fix``. Lengths in mm."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.claims.book import ClaimBook, write_claims
from sim.claims.rules import NOT_APPLICABLE
from sim.claims.table import Sim, claim_rows, exact
from sim.studies.network.bias_checks import BIASED_CHECKS
from sim.studies.network.estimates import McEstimates

__all__ = ["alarm_tol", "design_figures", "network_claims"]

SOURCE = "this project (analytic pre-analysis)"


def design_figures(net, an, a95_mm: np.ndarray, dil: np.ndarray, est: McEstimates) -> dict:
    """The design figures the findings report: largest point sigma (analytic, Monte Carlo),
    largest 95 % semi-axis ``a95_mm``, smallest redundancy number, the MDBs of the length
    observations, the dilutions ``dil`` (%), the rms point sigma."""
    an_sig = est.an_sig
    # the Monte Carlo of the coordinate with the largest analytic sigma, with its interval:
    # the largest of the Monte-Carlo sigmas (0.00119 mm of a 5 x 5 plate at 0.00104 mm
    # analytic, 200 trials) is raised by their noise, read as the Monte Carlo 15 % worse
    worst = int(np.argmax(an_sig))
    return {
        "sigma_max": tuple(float(a[worst]) for a in (an_sig, est.s_mc, est.s_lo, est.s_hi)),
        "a95_max": float(np.max(a95_mm)),
        "dilution_max": dil,
        "r_min": float(an.redundancy.min()),
        "mdb_mm": an.mdb[~np.isin(net.kind, (1, 2))],
        "sigma_rms": float(np.sqrt(np.mean(an_sig**2))),
    }


def alarm_tol(alpha: float) -> float:
    """Tolerance of the false-alarm self-check: 2 points, and at most 40 % of the level (the
    2 points at the default 5 %). A fixed 2 points at ``test.alpha = 1e-6`` made the zone
    [-0.02, 0.02], a probability below zero, and the check "held" on a rejection rate of up
    to 2 % (20,000 times the level): it could not tell a test that works from one that
    rejects far too often. The zone stays within (0, 1) at every level."""
    return min(0.02, 0.4 * alpha)


def _self_checks(alpha: float, dof: int) -> list[tuple[str, str, float, float]]:
    """``(id, what, reference, tolerance)`` of the four self-checks."""
    return [
        (
            "network.mc_agreement.mean_ratio",
            "Monte-Carlo sigma / analytic sigma (root of the mean variance ratio over coordinates)",
            1.0,
            0.05,
        ),
        (
            "network.coverage95.mean",
            "share of adjusted points inside their analytic 95 % ellipse",
            0.95,
            0.02,
        ),
        (
            "network.global_test.false_alarm",
            f"rejection rate of the global test at alpha {alpha:g} (no blunders)",
            alpha,
            alarm_tol(alpha),
        ),
        (
            "network.redundancy.sum",
            "redundancy numbers sum to the degrees of freedom",
            float(dof),
            1e-6,
        ),
    ]


def _findings(design: dict) -> list[tuple[str, str, float, str]]:
    """``(id, what, value, note)`` of the design findings this network has."""
    mdb = design["mdb_mm"][np.isfinite(design["mdb_mm"])]
    dil = design["dilution_max"][np.isfinite(design["dilution_max"])]
    finds = [
        (
            "network.design.sigma_max_mm",
            "largest point sigma (x or y), mm",
            design["sigma_max"][0],
            "analytic; Monte Carlo of that coordinate {1:.4g} mm [{2:.4g}, {3:.4g}]".format(
                *design["sigma_max"]
            ),
        ),
        (
            "network.design.sigma_rms_mm",
            "rms of the point sigmas (x and y), mm",
            design["sigma_rms"],
            "analytic",
        ),
        (
            "network.design.ellipse95_max_mm",
            "largest semi-axis of a 95 % ellipse, mm",
            design["a95_max"],
            "analytic",
        ),
        (
            "network.design.redundancy_min",
            "smallest redundancy number",
            design["r_min"],
            "analytic",
        ),
    ]
    if mdb.size:  # a network of directions and angles only has no length MDB
        finds.append(
            (
                "network.design.mdb_max_mm",
                "largest minimal detectable bias of a "
                "distance or coordinate observation (controlled ones), mm",
                float(mdb.max()),
                "analytic",
            )
        )
    if dil.size:  # only with compare.fix
        finds.append(
            (
                "network.design.dilution_max_pct",
                "largest dilution against compare.fix known, %",
                float(dil.max()),
                "analytic",
            )
        )
    return finds


def _book(checks: list[tuple], finds: list[tuple]) -> ClaimBook:
    return ClaimBook(
        [
            {
                "id": i,
                "source": SOURCE,
                "paper": p,
                "kind": "self-check",
                "form": "value",
                "ref": r,
                "tol": t,
            }
            for i, p, r, t in checks
        ]
        + [{"id": f[0], "source": SOURCE, "paper": f[1], "kind": "finding"} for f in finds],
        [],
        "<network self-checks>",
    )


def _ci(est: tuple, note: str) -> Sim:
    """A ``(value, lo, hi)`` estimate (arrays of one) as a claim's value and 95 % interval."""
    return Sim(est[0][0], (est[1][0], est[2][0]), note=note)


def _over_all(est: tuple, ok: int, trials: int) -> tuple:
    """A share's ``(value, lo, hi)`` of the ``ok`` converged trials as bounds of the share over
    all ``trials``: the others' outcomes are unknown, each may be either, so the interval is
    ``[lo ok / T, (hi ok + T - ok) / T]`` (the value stays the converged trials'). A run of
    which 1,830 of 2,000 trials did not converge held its coverage and false-alarm self-checks
    on the 170 that did (0.952 in [0.945, 0.958]); over every trial the share is anywhere in
    [0.08, 0.99] and decides nothing."""
    if ok >= trials:
        return est
    v, lo, hi = (np.asarray(x, float) for x in est)
    return v, lo * ok / trials, (hi * ok + trials - ok) / trials


def _not_applicable(rows: list[dict], biased: str | None) -> list[dict]:
    """The rows with the :data:`~sim.studies.network.bias_checks.BIASED_CHECKS` **not
    applicable** when ``biased`` says why (a bias the adjustment does not absorb), their
    value and outcome kept and the outcome named in the note."""
    if biased is None:
        return rows
    return [
        {
            **r,
            "verdict": NOT_APPLICABLE,
            "holds": None,
            "note": f"{biased}{r['outcome']}; {r['note']}",
        }
        if r["claim"] in BIASED_CHECKS
        else r
        for r in rows
    ]


def network_claims(
    out: Path, prov: dict, an, est: McEstimates, cfg: dict, design: dict, biased=None
) -> None:
    """Score the self-checks and findings of a network study into ``claims.parquet``;
    ``biased``: why the checks of unbiased readings are not applicable
    (:func:`sim.studies.network.bias_checks.bias_effect`), None when they are."""
    checks = _self_checks(cfg["test.alpha"], an.dof)
    finds = _findings(design)
    book = _book(checks, finds)
    ok, trials = int(float(est.n_ok.sum())), int(cfg["trials"])
    note = (
        f"{ok} converged of {trials} trials; sigma ratio: "
        "jackknife CI over chunks, shares: Wilson interval from the counts"
    )
    if ok < trials:
        note += (
            f"; the {trials - ok} trials that did not converge are left out of the sigma ratio "
            "(it is of the converged trials alone) and taken as either outcome by the shares' "
            "intervals"
        )
    table = {
        checks[0][0]: _ci(est.ratio, note),
        checks[1][0]: _ci(_over_all(est.cover_mean, ok, trials), note),
        checks[2][0]: _ci(_over_all(est.alarm, ok, trials), note),
        checks[3][0]: exact(
            float(an.redundancy.sum()), note=f"{len(an.redundancy)} observations, dof {an.dof}"
        ),
        **{i: exact(v, note=nt) for i, _, v, nt in finds},
    }
    rows = _not_applicable(claim_rows(book, table), biased)
    write_claims(out / "claims.parquet", rows, prov, book)
