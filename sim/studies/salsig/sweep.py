"""Unprinted inputs of ``salsig_encoders`` swept: where each claim of seed 002 holds.

Salsig prints neither the B8 marking error nor the comparator error (only the unit-weight
errors they produce), nor anything about the models of his vertical test (relief of the
control heights, their vertical error, the number of control points). For each such input,
with the others at their configured values, the claims that depend on it are evaluated on
``consistency.trials`` simulated calibrations or models (common random numbers: the same
stream for every value of one input) and decided by the claim book's own rule. A value is in
a claim's set when the claim is not contradicted there (``holds`` or ``inconclusive``); the
*consistent set* of an input is where every claim of its sweep is. The z encoder's span and
setting error and the grid spacing decide no printed number (only the unprinted standard
error of the z scale), so they are not swept.
"""

from __future__ import annotations

import math

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.intervals import spread
from sim.studies.salsig.model import simulate_chain, simulate_vertical

VERTICAL = (
    "salsig.vertical_halved.rms_ratio",
    "salsig.vertical_halved.dramatic_vertical",
    "salsig.vertical_halved.dramatic_horizontal",
)
CHAIN = ("salsig.recovery.s0_fig2_mm", "salsig.recovery.s0_fig3_digits")
#: input key -> (config list of swept values, claims it decides)
INPUTS = {
    "vertical.relief_mm": ("consistency.relief_mm", VERTICAL),
    "vertical.sigma_z_um": ("consistency.sigma_z_um", VERTICAL),
    "vertical.control": ("consistency.control", VERTICAL),
    "b8.sigma_um": ("consistency.b8_sigma_um", CHAIN),
    "comparator.sigma_um": ("consistency.comparator_sigma_um", CHAIN),
}


def _score(spec: dict, x: np.ndarray) -> dict:
    b = ClaimBook([spec], [], "<sweep>")
    if spec["form"] == "one-plate":
        return b.score(spec["id"], samples=x)
    med, ci = spread(x)
    return b.score(spec["id"], med, ci, "spread")


def evaluate(book: ClaimBook, cfg: dict, claims: tuple, rng: np.random.Generator) -> dict:
    n = cfg["consistency.trials"]
    if claims is VERTICAL:
        v = simulate_vertical(cfg, rng, n)
        data = {
            VERTICAL[0]: v["ratio"],
            VERTICAL[1]: v["rms_z_before_um"] / v["rms_z_after_um"],
            VERTICAL[2]: v["rms_xy_before_um"] / v["rms_xy_after_um"],
        }
    else:
        c = simulate_chain(cfg, rng, n)
        data = {CHAIN[0]: c["s0_fig2_mm"], CHAIN[1]: c["s0_fig3_digits"]}
    return {cid: _score(book.spec(cid), data[cid]) for cid in claims}


def run_sweep(book: ClaimBook, cfg: dict) -> tuple[dict, dict]:
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
    for i, (key, (listkey, claims)) in enumerate(INPUTS.items()):
        vals = sorted(cfg[listkey])
        per = {c: np.zeros(len(vals), bool) for c in claims}
        for j, v in enumerate(vals):
            c = dict(cfg)
            c[key] = v
            rng = np.random.default_rng(np.random.SeedSequence(cfg["seed"], spawn_key=(900, i)))
            for cid, r in evaluate(book, c, claims, rng).items():
                per[cid][j] = r["outcome"] != "fails"
                for col, val in (
                    ("input", key),
                    ("input_value", float(v)),
                    ("claim", cid),
                    ("kind", r["kind"]),
                    ("outcome", r["outcome"]),
                    ("value", r["value"]),
                    ("p_plate", r["p_plate"]),
                ):
                    det[col].append(val)
        allg = np.logical_and.reduce([per[c] for c in claims])
        for cid, good in list(per.items()) + [("ALL", allg)]:
            hv = np.asarray(vals, float)[good]
            for col, val in (
                ("input", key),
                ("claim", cid),
                ("kind", "all" if cid == "ALL" else book.spec(cid)["kind"]),
                ("holds_low", float(hv.min()) if hv.size else math.nan),
                ("holds_high", float(hv.max()) if hv.size else math.nan),
                ("n_values", len(vals)),
                ("n_holds", int(good.sum())),
                ("default", float(cfg[key])),
            ):
                cons[col].append(val)
    return det, cons
