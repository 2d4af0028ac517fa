"""The tables a network study writes, one writer each: ``points.parquet`` (analytic sigma and
95 % ellipse, Monte-Carlo sigma with its interval, ellipse coverage, dilution),
``parameters.parquet`` (orientations in arcsec, additive constant in mm, scale in ppm),
``datums.parquet`` (point sigmas in other datums), ``observations.parquet`` (redundancy, MDB,
external reliability) and ``summary.parquet`` (one row). Coordinates and sigmas in mm."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.mc import tolerance as tol
from sim.mc.runner import jackknife
from sim.mc.storage import write_table
from sim.studies.network.analysis import (
    CHI2_2_95,
    bearing_deg,
    ellipse,
    in_datum,
    inner_over_defect,
    match_points,
)
from sim.studies.network.definition import KINDS, Network
from sim.studies.network.estimates import McEstimates, sample_sd
from sim.studies.network.sparse_analysis import in_datum_sparse, variances

__all__ = [
    "K95",
    "POINT_TOLERANCES",
    "parameter_indices",
    "write_datums",
    "write_observations",
    "write_parameters",
    "write_points",
    "write_summary",
]

#: the 95 % semi-axis factor of a 2-D error ellipse
K95 = float(np.sqrt(CHI2_2_95))
#: arcsec per radian
ARCSEC = 1 / (np.pi / 648000)

_A = tol.arithmetic(analytic=True)
#: how ``make verify`` compares ``points.parquet`` (:mod:`sim.mc.tolerance`): the analytic
#: columns by their arithmetic, also against a run with fewer trials; the bearing as an axis
#: (null, with its reason, for a circle); the Monte-Carlo columns at their intervals
POINT_TOLERANCES = {
    **{c: _A for c in ("x_mm", "y_mm", "sigma_x_mm", "sigma_y_mm", "dilution_pct")},
    **{c: _A for c in ("ellipse95_a_mm", "ellipse95_b_mm")},
    "ellipse_bearing_deg": tol.axial(180.0, null_reason="ellipse_bearing_null", analytic=True),
    **{
        f"mc_sigma_{a}{s}_mm": tol.mc(ci=(f"mc_sigma_{a}_lo_mm", f"mc_sigma_{a}_hi_mm"))
        for a in "xy"
        for s in ("", "_lo", "_hi")
    },
    **{c: tol.mc(ci=("coverage95_lo", "coverage95_hi")) for c in ("coverage95", "coverage95_lo")},
    "coverage95_hi": tol.mc(ci=("coverage95_lo", "coverage95_hi")),
}


def write_points(
    out: Path, net: Network, an, pts: list[int], est: McEstimates, dil: np.ndarray, prov: dict
) -> None:
    """``points.parquet``: per estimated point, the analytic and Monte-Carlo sigmas, the 95 %
    ellipse, its coverage and the dilution ``dil`` (%)."""
    a95, b95, _ = ellipse(an.cov[pts])
    bearing, bearing_why = bearing_deg(an.cov[pts])
    s_mc, s_lo, s_hi, cover = est.s_mc, est.s_lo, est.s_hi, est.cover
    write_table(
        out / "points.parquet",
        {
            "point": [net.names[a] for a in pts],
            "x_mm": net.xy_mm[pts, 0],
            "y_mm": net.xy_mm[pts, 1],
            "role": [("free", "fixed", "observed")[net.role[a]] for a in pts],
            "sigma_x_mm": est.an_sig[0::2],
            "sigma_y_mm": est.an_sig[1::2],
            "ellipse95_a_mm": K95 * a95,
            "ellipse95_b_mm": K95 * b95,
            "ellipse_bearing_deg": bearing,
            "ellipse_bearing_null": bearing_why,
            "mc_sigma_x_mm": s_mc[0::2],
            "mc_sigma_x_lo_mm": s_lo[0::2],
            "mc_sigma_x_hi_mm": s_hi[0::2],
            "mc_sigma_y_mm": s_mc[1::2],
            "mc_sigma_y_lo_mm": s_lo[1::2],
            "mc_sigma_y_hi_mm": s_hi[1::2],
            "coverage95": cover[0],
            "coverage95_lo": cover[1],
            "coverage95_hi": cover[2],
            "dilution_pct": dil,
        },
        prov,
        tolerances=POINT_TOLERANCES,
    )


def parameter_indices(net: Network, an) -> np.ndarray:
    """Indices of the estimated globals that are not coordinates (orientations, constant,
    scale)."""
    return np.array([g for g in an.free if g >= 2 * net.n], int)


_MC_PARAMETER_COLUMNS = (
    "mc_mean_error",
    "mc_mean_error_lo",
    "mc_mean_error_hi",
    "mc_sigma",
    "mc_sigma_lo",
    "mc_sigma_hi",
)


def _mc_parameters(sim: dict, n_ok: np.ndarray, kp: int) -> tuple[np.ndarray, ...]:
    """Mean error and sigma of the ``kp`` parameters with their jackknife intervals, in the
    order of :data:`_MC_PARAMETER_COLUMNS` (internal units: rad, mm, ppm)."""
    sums = np.concatenate([n_ok[:, None], sim["sum.pe"], sim["sum.pee"]], axis=1)

    def mean(t):
        return t[1 : 1 + kp] / t[0]

    def sd(t):
        return sample_sd(t[0], t[1 : 1 + kp], t[1 + kp :])

    return (*jackknife(mean, sums), *jackknife(sd, sums))


def write_parameters(out: Path, net: Network, an, sim: dict, n_ok: np.ndarray, prov: dict) -> None:
    """``parameters.parquet``: the estimated globals that are not coordinates (orientation of
    each direction set in arcsec, additive constant in mm, scale in ppm) with their true value,
    analytic sigma and Monte-Carlo mean error and sigma with intervals."""
    par = parameter_indices(net, an)
    names = net.parameter_names()
    units = ["arcsec"] * len(net.stations) + ["mm", "ppm"]
    f = np.array([ARCSEC] * len(net.stations) + [1.0, 1.0])
    rel = par - 2 * net.n
    pos = {g: a for a, g in enumerate(an.free)}
    an_sig = (
        np.sqrt(np.maximum(variances(an, [pos[g] for g in par]), 0.0)) if len(par) else np.zeros(0)
    )
    cols = {
        "parameter": [names[r] for r in rel],
        "unit": [units[r] for r in rel],
        "true": net.theta_true()[par] * f[rel],
        "sigma": an_sig * f[rel],
    }
    if len(par):
        mc = _mc_parameters(sim, n_ok, len(par))
        cols.update({k: v * f[rel] for k, v in zip(_MC_PARAMETER_COLUMNS, mc)})
    else:
        cols.update({k: np.zeros(0) for k in _MC_PARAMETER_COLUMNS})
    write_table(out / "parameters.parquet", cols, prov)


def write_datums(out: Path, net: Network, an, cfg: dict, prov: dict) -> None:
    """``datums.parquet``: the point sigmas in the inner datum over ``output.inner_over`` (the
    patterns form one set of datum points; empty without it), removing every defect of the
    network adjusted free, or, where the points cannot hold those but hold the ones the fixed
    points leave, these (the datum named "... (about the fixed points)":
    :func:`~sim.studies.network.analysis.inner_over_defect`)."""
    drows = {"datum": [], "point": [], "sigma_x_mm": [], "sigma_y_mm": []}
    if cfg["output.inner_over"]:
        sel = match_points(net, "output.inner_over", cfg["output.inner_over"])
        H, held = inner_over_defect(net, an.free, sel, "output.inner_over")
        cov = in_datum_sparse(net, an, sel, H) if an.Q is None else in_datum(net, an, sel, H)
        name = f"inner over {', '.join(cfg['output.inner_over'])}"
        for a in range(net.n):
            drows["datum"].append(name + " (about the fixed points)" * held)
            drows["point"].append(net.names[a])
            drows["sigma_x_mm"].append(float(np.sqrt(max(cov[a, 0, 0], 0))))
            drows["sigma_y_mm"].append(float(np.sqrt(max(cov[a, 1, 1], 0))))
    write_table(out / "datums.parquet", drows, prov)


def write_observations(out: Path, net: Network, an, prov: dict) -> None:
    """``observations.parquet``: per observation, its points, sigma (mm or arcsec), redundancy
    number, MDB, external reliability and bias-to-noise ratio."""
    ang = np.isin(net.kind, (1, 2))
    to = np.where(net.kind == 2, net.k, net.j)
    write_table(
        out / "observations.parquet",
        {
            "kind": [KINDS[c] for c in net.kind],
            "from": [
                net.names[net.j[r]] if net.kind[r] == 2 else net.names[net.i[r]]
                for r in range(net.m)
            ],
            "to": [net.names[t] if t >= 0 else "" for t in to],
            "at": [net.names[net.i[r]] if net.kind[r] == 2 else "" for r in range(net.m)],
            "sigma_mm": np.where(ang, np.nan, net.sigma),
            "sigma_arcsec": np.where(ang, net.sigma / (np.pi / 648000), np.nan),
            "redundancy": an.redundancy,
            "mdb_mm": np.where(ang | ~np.isfinite(an.mdb), np.nan, an.mdb),
            "mdb_arcsec": np.where(ang & np.isfinite(an.mdb), an.mdb / (np.pi / 648000), np.nan),
            "external_max_mm": np.where(np.isfinite(an.ext_max_mm), an.ext_max_mm, np.nan),
            "bias_noise_ratio": np.where(np.isfinite(an.bnr), an.bnr, np.nan),
            "controlled": np.isfinite(an.mdb),
        },
        prov,
    )


def write_summary(
    out: Path, net: Network, an, cfg: dict, facts: dict, est: McEstimates, prov: dict
) -> None:
    """``summary.parquet``, one row: the network's size, datum and degrees of freedom, the
    converged trials, the false-alarm rate, the mean coverage, the MC / analytic ratio, and
    ``facts`` (``datum_constraints``, ``held_by_datum``, ``gama_xml``, ``gama_input``)."""
    row = {
        "network": net.name,
        "points": net.n,
        "observations": net.m,
        "unknowns": len(an.free),
        "datum": cfg["datum.kind"],
        "datum_constraints": facts["datum_constraints"],
        "dof": an.dof,
        "redundancy_sum": float(an.redundancy.sum()),
        "trials": cfg["trials"],
        "converged": int(float(est.n_ok.sum())),
        "false_alarm": float(est.alarm[0][0]),
        "test_alpha": cfg["test.alpha"],
        "coverage95_mean": float(est.cover_mean[0][0]),
        "mc_over_analytic": float(est.ratio[0][0]),
        "compare_fix": ", ".join(cfg["compare.fix"]),
        "held_by_datum": facts["held_by_datum"],
        "gama_xml": facts["gama_xml"],
        "gama_input": facts["gama_input"],
    }
    write_table(out / "summary.parquet", {k: [v] for k, v in row.items()}, prov)
