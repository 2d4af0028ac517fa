"""The comparator's error budget (seed ``004``, *Calibration*): each error source of
:mod:`sim.instruments.ranges.budget` alone, and in combinations, on the Table-1 plate of the paper's design
(pivot model), as the rms coordinate error after a rigid fit over all points (um) and the
closure sigma0 (um). Trial counts are adaptive (:mod:`.adaptive`, through the runner); the
rows run side by side (:mod:`.parts`).
"""

from __future__ import annotations

from functools import partial

import numpy as np

from sim.mc.workunits import DESIGN_UNITS
from sim.studies.design.adaptive import run_adaptive
from sim.studies.design.chunks import budget_chunk
from sim.studies.design.parts import side_by_side

__all__ = ["BUDGET_ROWS", "budget_analysis", "rms_stat", "PART0"]

PART0 = 10
BUDGET_ROWS = (  # (name, sources, settings on?, description)
    ("setting", (), True, "setting error only (the paper's settings)"),
    ("scale", ("scale",), False, "scale graduations, calibrated residual"),
    ("scale_spec", ("scale_spec",), False, "scale graduations, uncalibrated (specification)"),
    ("screw", ("screw",), False, "micrometer screw, calibrated residual"),
    ("drum_periodic", ("drum_periodic",), False, "drum eccentricity, uncorrected"),
    ("wobble_3kg", ("wobble",), False, "pivot wobble at 3 kg thrust"),
    ("wobble_3kg_h1", ("wobble_h1",), False, "the same wobble as a first harmonic"),
    ("sphericity", ("sphericity",), False, "sphericity of the pivot ball"),
    ("production", ("scale", "screw"), True, "settings + calibrated scale and screw, 10 kg thrust"),
    ("production_3kg", ("scale", "screw", "wobble"), True, "production with 3 kg thrust"),
    ("table1_model", ("comparator",), True, "settings + random comparator error (Table 1)"),
)


def rms_stat(res: dict) -> dict:
    """rms coordinate error and its standard error (delta method on the mean square)."""
    ms = res["ms_um2"][res["ok"]]
    if len(ms) < 2:
        return {"rms": (float("nan"), float("inf"))}
    v = float(np.sqrt(ms.mean()))
    se = float(ms.std(ddof=1) / np.sqrt(len(ms)) / (2 * v)) if v > 0 else 0.0
    return {"rms": (v, se)}


def budget_analysis(cfg: dict, pts: np.ndarray, th: np.ndarray, ctx) -> tuple[dict, dict]:
    """Returns the budget table and the per-trial results of each row."""
    bcfg = {k: v for k, v in cfg.items() if k.startswith("budget.")}
    bcfg["comparator.sigma_um"] = cfg["comparator.sigma_um"]
    cols = {
        k: [] for k in ("source", "description", "rms_um", "se_um", "trials", "s0_um", "settings")
    }

    def row(i, srcs, sett, name):
        fn = partial(
            budget_chunk,
            bcfg,
            pts,
            th,
            srcs,
            cfg["paper.setting_sigma_um"] if sett else 0.0,
            cfg["paper.settings"],
        )
        return run_adaptive(
            fn,
            rms_stat,
            cfg["budget.target_se_um"],
            cfg["seed"],
            cfg["chunk"],
            part=PART0 + i,
            min_trials=2 * cfg["chunk"],
            max_trials=cfg["budget.max_trials"],
            label=f"budget {name}",
            ctx=ctx,
            units=DESIGN_UNITS["budget"],
        )

    done = side_by_side(
        {
            name: partial(row, i, srcs, sett, name)
            for i, (name, srcs, sett, _) in enumerate(BUDGET_ROWS)
        },
        ctx,
    )
    sims = {}
    for name, srcs, sett, desc in BUDGET_ROWS:
        res, st = done[name]
        sims[name] = res
        ok = res["ok"]
        cols["source"].append(name)
        cols["description"].append(desc)
        cols["rms_um"].append(st["rms"][0])
        cols["se_um"].append(st["rms"][1])
        cols["trials"].append(len(ok))
        cols["s0_um"].append(
            float(np.sqrt(np.mean(res["s0_um"][ok] ** 2))) if ok.any() else float("nan")
        )
        cols["settings"].append(bool(sett))
    return cols, sims
