"""Unprinted inputs swept, not tuned (issue 11.3): for every input of study ``brown_design``
that the paper does not print, each claim that depends on it is evaluated at every swept value
(linearised, :mod:`.external`) with the claim book's rule, on feasible designs only (every
range on the 261 mm scale plus the 1 mm micrometer). ``consistent_set.parquet`` gives, per
input and claim, the smallest and largest swept value at which the claim holds, and per input
the *consistent set* (claim ``ALL``): ``holds_*`` where every claim holds, ``compatible_*``
where no claim fails (holds or inconclusive: a one-plate statistic of the paper is compatible
with the simulated plates but too spread to "hold"). The pass time and
the screw pitch enter no printed claim but the drum's; the offset, beta and the Zeiss layout
enter the tolerances and the external comparisons.
"""

from __future__ import annotations

import numpy as np

from sim.studies.design.cells import measuring_time, pareto_front
from sim.studies.design.claims import verdict_of
from sim.studies.design.external import external_at

__all__ = ["sweep_unprinted", "INPUTS"]

#: unprinted input -> (config key of its swept values, claims that depend on it)
_OFFSET_CLAIMS = (
    "brown.operation.lateral_offset_error_um",
    "brown.calibration.linearity_tolerance_um",
    "brown.results.two_screw_agreement_um",
    "brown.results.accuracy_range_um",
    "brown.results.zeiss_discrepancy_um",
    "brown.results.zeiss_comparator_um",
)
INPUTS = {
    "paper.offset_mm": ("unprinted.offsets_mm", _OFFSET_CLAIMS),
    "paper.beta_mm": ("unprinted.betas_mm", _OFFSET_CLAIMS),
    "zeiss.half_extent_mm": (
        "unprinted.zeiss_extents_mm",
        ("brown.results.zeiss_discrepancy_um", "brown.results.zeiss_comparator_um"),
    ),
    "budget.pitch_mm": ("unprinted.pitches_mm", ("brown.calibration.drum_graduation_um",)),
    "time.pass_min": ("unprinted.pass_min", ("brown.design.paper_on_front_same_points",)),
}
_ZEISS = ("brown.results.zeiss_discrepancy_um", "brown.results.zeiss_comparator_um")


def _front_same_points(cfg, cols, pass_min):
    c = dict(cfg, **{"time.pass_min": pass_min})
    cost = measuring_time(
        c, np.array(cols["positions"]), np.array(cols["n_points"]), np.array(cols["settings"])
    )
    jp = int(np.flatnonzero(cols["paper_design"])[0])
    sel = (
        np.array(cols["feasible"])
        & np.isclose(np.array(cols["setting_sigma_um"]), cols["setting_sigma_um"][jp])
        & (np.array(cols["n_points"]) == cols["n_points"][jp])
        & np.isclose(np.array(cols["extent_mm"]), cols["extent_mm"][jp])
    )
    return bool(pareto_front(cost, np.array(cols["worst_sigma_um"]), sel)[jp])


def sweep_unprinted(cfg: dict, book, design_cols: dict) -> tuple[dict, dict]:
    """Returns ``(consistent_set columns, per-value columns)``."""
    base = {
        "paper.offset_mm": cfg["paper.offset_mm"],
        "paper.beta_mm": cfg["paper.beta_mm"],
        "zeiss.half_extent_mm": cfg["zeiss.half_extent_mm"],
        "budget.pitch_mm": cfg["budget.pitch_mm"],
    }
    vals = {
        c: []
        for c in (
            "input",
            "value",
            "claim",
            "sim_value",
            "sim_low",
            "sim_high",
            "zone_low",
            "zone_high",
            "verdict",
            "feasible",
        )
    }
    cs = {
        c: []
        for c in (
            "input",
            "claim",
            "holds_low",
            "holds_high",
            "n_holds",
            "compatible_low",
            "compatible_high",
            "n_compatible",
            "n_values",
            "note",
        )
    }
    for inp, (key, claims) in INPUTS.items():
        xs = [float(x) for x in cfg[key]]
        holds = {c: [] for c in claims}
        compat = {c: [] for c in claims}
        for x in xs:
            if inp == "time.pass_min":
                on = _front_same_points(cfg, design_cols, x)
                for c, v in zip(
                    vals,
                    (
                        inp,
                        x,
                        claims[0],
                        float(on),
                        float(on),
                        float(on),
                        np.nan,
                        np.nan,
                        "finding",
                        True,
                    ),
                ):
                    vals[c].append(v)
                holds[claims[0]].append(on)
                compat[claims[0]].append(on)
                continue
            p = dict(base, **{inp: x})
            e = external_at(
                cfg,
                p["paper.offset_mm"],
                p["paper.beta_mm"],
                p["zeiss.half_extent_mm"],
                p["budget.pitch_mm"],
                plates=inp != "budget.pitch_mm",
            )
            for cid in claims:
                ok = e["feasible"] and (e["zeiss_feasible"] if cid in _ZEISS else True)
                row = verdict_of(book, cid, e)
                for c, v in zip(
                    vals,
                    (
                        inp,
                        x,
                        cid,
                        row["value"],
                        row["ci_low"],
                        row["ci_high"],
                        _finite_or_nan(row["zone_low"]),
                        _finite_or_nan(row["zone_high"]),
                        row["verdict"] if ok else "infeasible",
                        bool(ok),
                    ),
                ):
                    vals[c].append(v)
                holds[cid].append(ok and row["verdict"] == "holds")
                compat[cid].append(ok and row["verdict"] in ("holds", "inconclusive"))
        allh = np.ones(len(xs), bool)
        allc = np.ones(len(xs), bool)
        printed = [c for c in claims if book.spec(c)["kind"] != "finding"]
        for cid in claims:
            h, cp = np.array(holds[cid]), np.array(compat[cid])
            if cid in printed:
                allh &= h
                allc &= cp
            _append(
                cs, inp, cid, xs, h, cp, "" if cid in printed else "a finding (no paper number)"
            )
        note = "" if printed else "no printed claim depends on this input"
        if printed and not allc.any():
            fail = [c for c in printed if not all(compat[c])]
            note = "no swept value where no claim fails; failing somewhere: " + ", ".join(fail)
        _append(cs, inp, "ALL", xs, allh, allc, note)
    return cs, vals


def _finite_or_nan(x):
    return float(x) if np.isfinite(x) else float("nan")


def _append(cs, inp, cid, xs, h, cp, note):
    x = np.array(xs)[h]
    xc = np.array(xs)[cp]
    cs["input"].append(inp)
    cs["claim"].append(cid)
    cs["holds_low"].append(float(x.min()) if len(x) else np.nan)
    cs["holds_high"].append(float(x.max()) if len(x) else np.nan)
    cs["n_holds"].append(int(h.sum()))
    cs["compatible_low"].append(float(xc.min()) if len(xc) else np.nan)
    cs["compatible_high"].append(float(xc.max()) if len(xc) else np.nan)
    cs["n_compatible"].append(int(cp.sum()))
    cs["n_values"].append(len(xs))
    contiguous = len(x) == 0 or np.all(h[np.flatnonzero(h)[0] : np.flatnonzero(h)[-1] + 1])
    cs["note"].append(
        note
        or ("" if contiguous else "holds at the values in the range only in part (not contiguous)")
    )
