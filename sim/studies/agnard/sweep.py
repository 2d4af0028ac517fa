"""Consistent set of ``agnard_block``'s unprinted inputs (seed ``003_5ce730a990a7ebc5.txt``).

The paper does not print its five-point control layout (Figure 5 is lost) nor the
re-centring error of mechanical pugging. Both are swept; for each swept value every
affected claim is decided by the claim book's own rule (:mod:`sim.claims.book`), and the report
gives, claim by claim, the values where it holds and where it does not fail, and the
*consistent set*: the values where no claim fails (``ok_*``) and where all hold
(``holds_*``). Ranges are the smallest and largest swept value with that outcome (the
sweep is a grid; a gap inside would show in ``sweep_claims.parquet``).
"""

from __future__ import annotations

import numpy as np

from sim.claims.book import ClaimBook

#: the claims each unprinted input bears on
FIVE_CLAIMS = [
    f"agnard.control_5.{w}_{c}_cm" for w in ("ctrl", "check") for c in ("x", "y", "xy", "z")
] + [f"agnard.max_residual.control_5_{c}_cm" for c in ("xy", "z")]
RECENTRE_CLAIMS = ["agnard.pass_rejections.mechanical_pct"]


def five_samples(sw: dict, i: int) -> dict[str, np.ndarray]:
    """Per-block statistics (cm) of swept layout ``i`` keyed by claim id."""
    out = {}
    for w in ("ctrl", "check"):
        for c in ("x", "y", "xy", "z"):
            out[f"agnard.control_5.{w}_{c}_cm"] = 100 * np.asarray(sw[f"inset{i}.{w}_{c}_m"])
    for c in ("xy", "z"):
        out[f"agnard.max_residual.control_5_{c}_cm"] = 100 * np.asarray(
            sw[f"inset{i}.ctrl_max_{c}_m"]
        )
    return out


def evaluate(book: ClaimBook, sweeps: dict[str, dict[float, dict[str, np.ndarray]]]):
    """``sweeps[input][value][claim] = samples``. Returns (per-value table, consistent set)."""
    long = {
        k: []
        for k in (
            "input",
            "value",
            "claim",
            "median",
            "lo",
            "hi",
            "zone_low",
            "zone_high",
            "outcome",
            "unit",
        )
    }
    cs = {
        k: []
        for k in ("input", "claim", "holds_low", "holds_high", "ok_low", "ok_high", "n_values")
    }
    for inp, by_value in sweeps.items():
        values = sorted(by_value)
        claims = list(dict.fromkeys(c for v in values for c in by_value[v]))
        ok_all = np.ones(len(values), bool)
        hold_all = np.ones(len(values), bool)
        for cid in claims:
            outs = []
            for v in values:
                one = ClaimBook([book.spec(cid)], [], book.path)
                r = one.score(cid, samples=by_value[v][cid])
                outs.append(r["outcome"])
                for k, x in (
                    ("input", inp),
                    ("value", float(v)),
                    ("claim", cid),
                    ("median", r["value"]),
                    ("lo", r["ci_low"]),
                    ("hi", r["ci_high"]),
                    ("zone_low", _nan_inf(r["zone_low"])),
                    ("zone_high", _nan_inf(r["zone_high"])),
                    ("outcome", r["outcome"]),
                    ("unit", cid.rsplit("_", 1)[-1]),
                ):
                    long[k].append(x)
            outs = np.asarray(outs)
            ok_all &= outs != "fails"
            hold_all &= outs == "holds"
            _cs_row(cs, inp, cid, values, outs == "holds", outs != "fails")
        _cs_row(cs, inp, "ALL", values, hold_all, ok_all)
    return long, cs


def _nan_inf(x: float) -> float:
    """An unbounded side of a decision zone is stored as NaN (no bound), not infinity."""
    return float(x) if np.isfinite(x) else np.nan


def _cs_row(cs: dict, inp: str, cid: str, values, holds: np.ndarray, ok: np.ndarray) -> None:
    v = np.asarray(values, float)
    cs["input"].append(inp)
    cs["claim"].append(cid)
    cs["holds_low"].append(float(v[holds].min()) if holds.any() else np.nan)
    cs["holds_high"].append(float(v[holds].max()) if holds.any() else np.nan)
    cs["ok_low"].append(float(v[ok].min()) if ok.any() else np.nan)
    cs["ok_high"].append(float(v[ok].max()) if ok.any() else np.nan)
    cs["n_values"].append(int(v.size))
