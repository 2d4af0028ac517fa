"""What ``gridplate_two_plates`` finds beyond the paper: bias, spread and coverage of the
comparator's S, S', eps (``beyond.parquet``, the ``twoplate.beyond.*`` findings of the claim
book), scored by :func:`sim.studies.gridplate.claims.score`."""

from __future__ import annotations

import numpy as np

from sim.claims.book import ClaimBook
from sim.claims.intervals import mean_ci, share_ci, std_ci
from sim.claims.table import Sim
from sim.instruments import transforms2d as t2
from sim.studies.gridplate.model import PARAM_LABEL, PARAMS


def scored_ids(cfg: dict, book: ClaimBook) -> list[str]:
    """The ids :func:`sim.studies.gridplate.claims.score` builds from this module's rows: bias
    and spread of S, S', eps with the grid fixed (:func:`beyond_rows`: one ``grid fixed`` row
    of ``beyond.parquet`` each) and their coverages (:func:`coverage_rows`)."""
    return [
        *(f"twoplate.beyond.fixed.{w}_{k}" for k in PARAMS for w in ("bias", "sd")),
        *(
            f"twoplate.beyond.coverage_{k}_{tag}"
            for k in PARAMS
            for tag in ("fixed_pri", "fixed_post", "wpri", "wpost")
        ),
    ]


def beyond_rows(beyond: dict) -> dict[str, Sim]:
    """Bias and spread of S, S', eps with the grid fixed (rows of ``beyond.parquet``)."""
    table = {}
    for i in range(len(beyond["param"])):
        if not beyond["method"][i].startswith("grid fixed"):
            continue
        k = {"S": "S", "S'": "S2", "eps": "eps"}[beyond["param"][i]]
        u = beyond["unit"][i]
        table[f"twoplate.beyond.fixed.bias_{k}"] = Sim(
            beyond["bias"][i],
            (beyond["bias_lo"][i], beyond["bias_hi"][i]),
            note=f"mean error of {beyond['param'][i]} ({u}), grid fixed (the weighted "
            "adjustment gives the same estimates to first order)",
        )
        table[f"twoplate.beyond.fixed.sd_{k}"] = Sim(
            beyond["sd"][i],
            (beyond["sd_lo"][i], beyond["sd_hi"][i]),
            note=f"standard deviation of {beyond['param'][i]} over plates ({u}), "
            "chi-square interval",
        )
    return table


def coverage_rows(cfg: dict, res: dict, j_true: int) -> dict[str, Sim]:
    """Coverage of the nominal 95 % intervals of S, S', eps: grid fixed (a-priori and
    a-posteriori sigma) and weighted at the ratio nearest the true one."""
    table = {}
    for k in PARAMS:
        for tag, key, lab in (
            ("fixed_pri", f"{k}_cov_fixed_pri", "grid fixed, a-priori comparator sigma"),
            ("fixed_post", f"{k}_cov_fixed_post", "grid fixed, a-posteriori s0"),
            (
                "wpri",
                f"{k}_cov_wpri_r{j_true}",
                "weighted at the ratio nearest the true one, a-priori sigma",
            ),
            ("wpost", f"{k}_cov_wpost_r{j_true}", "weighted, a-posteriori s0"),
        ):
            m, ci = share_ci(res[key])
            table[f"twoplate.beyond.coverage_{k}_{tag}"] = Sim(
                m,
                ci,
                note=f"share of plates whose interval {PARAM_LABEL[k]} +- 1.96 sd "
                f"contains the truth; {lab}"
                + (f" (1:{cfg['analysis.ratios'][j_true]:g})" if tag.startswith("w") else "")
                + ".",
            )
    return table


def beyond_table(res: dict, ratios: list, j_true: int) -> dict:
    """Bias and spread of S, S', eps (grid fixed and weighted at the ratio nearest the truth)."""
    conv = {"S": 1e6, "S2": 1e6, "eps": 1 / t2.ARCSEC}
    b = {
        k: []
        for k in (
            "param",
            "method",
            "bias",
            "bias_lo",
            "bias_hi",
            "sd",
            "sd_lo",
            "sd_hi",
            "stated_sd_rms",
            "unit",
        )
    }
    for k in PARAMS:
        for meth, key, sdkey in (
            ("grid fixed (affine)", f"{k}_err_fixed_pri", f"{k}_sd_fixed_post"),
            (f"grid weighted 1:{ratios[j_true]:g}", f"{k}_err_fixed_pri", f"{k}_sd_w_r{j_true}"),
        ):
            e = np.asarray(res[key], float).ravel() * conv[k]
            m, (lo, hi) = mean_ci(e)
            s, slo, shi = std_ci(e)
            for col, v in (
                ("param", PARAM_LABEL[k]),
                ("method", meth),
                ("bias", m),
                ("bias_lo", lo),
                ("bias_hi", hi),
                ("sd", float(s)),
                ("sd_lo", float(slo)),
                ("sd_hi", float(shi)),
                ("stated_sd_rms", float(np.sqrt(np.mean(np.asarray(res[sdkey]) ** 2)) * conv[k])),
                ("unit", "arcsec" if k == "eps" else "ppm"),
            ):
                b[col].append(v)
    return b
