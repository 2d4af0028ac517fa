"""Run a network study: pre-analysis, Monte Carlo through the runner, tables, figures.

Writes ``summary.parquet`` (one row), ``points.parquet`` (per point: analytic sigma and 95 %
ellipse, Monte-Carlo sigma with its interval, ellipse coverage, dilution against the compared
parameterisation), ``parameters.parquet`` (orientations, additive constant and scale: analytic
and Monte-Carlo sigma), ``datums.parquet`` (point sigmas in other datums), ``observations.parquet``
(redundancy, MDB, external reliability), ``claims.parquet`` (self-checks: Monte Carlo against
analytic, coverage, false-alarm rate of the global test, redundancy sum), ``network.xml`` (the
network in ``gama-local`` XML when it has that form) and the figures.
"""

from __future__ import annotations

import fnmatch
from functools import partial
from pathlib import Path

import numpy as np

from sim.claims.book import ClaimBook, write_claims
from sim.lsq import distributions as D
from sim.mc.config import ConfigError, StudyError
from sim.mc.runner import jackknife, run_chunks
from sim.mc.storage import provenance, write_table
from sim.report.figure_jobs import draw_figures
from sim.studies.network.analysis import (
    CHI2_2_95,
    analyse,
    ellipse,
    estimated_points,
    in_datum,
    match_points,
    mc_chunk,
)
from sim.studies.network.definition import KINDS, Network, build
from sim.studies.network.figures import network_figure, reliability_figure
from sim.studies.network.gama import export, import_note, merge_gama
from sim.studies.network.model import datum

__all__ = ["run", "compare_points"]

K95 = float(np.sqrt(CHI2_2_95))


def compare_points(net: Network, cfg: dict) -> list[int]:
    out: list[int] = []
    for p in cfg["compare.fix"]:
        hit = [a for a, nm in enumerate(net.names) if fnmatch.fnmatchcase(nm, p)]
        if not hit:
            raise ConfigError("compare.fix", f"no point named {p!r}")
        out += [h for h in hit if h not in out]
    return out


def _rms_sigma(cov: np.ndarray) -> np.ndarray:
    return np.sqrt((cov[:, 0, 0] + cov[:, 1, 1]) / 2)


def _params(net: Network, an) -> np.ndarray:
    """Indices of the estimated globals that are not coordinates (orientations, constant,
    scale)."""
    return np.array([g for g in an.free if g >= 2 * net.n], int)


def _mc(net, an, C, pts, cfg, ctx):
    crit = float(D.chi2_ppf(1 - cfg["test.alpha"], an.dof))
    cov_inv = np.linalg.inv(an.cov[pts])
    fn = partial(
        mc_chunk,
        net=net,
        free=an.free,
        C=None if C is None else C[0],
        cov_inv=cov_inv,
        pts=np.asarray(pts),
        crit=crit,
        tol=cfg["solver.tol_mm"],
        max_iter=cfg["solver.max_iter"],
        par=_params(net, an),
    )
    return run_chunks(
        fn, cfg["trials"], cfg["seed"], cfg["chunk"], part=0, label=cfg["study"], ctx=ctx
    )


def run(cfg: dict, out: Path, ctx) -> None:
    out = Path(out)
    full = merge_gama(cfg)
    net = build(full)
    dt = datum(net, full)
    an = analyse(net, dt, cfg["reliability.alpha0"], cfg["reliability.power"])
    if not an.ok:
        raise StudyError("datum.kind: the normal equations are singular in this datum")
    prov = provenance(cfg)
    pts = estimated_points(net, an)
    held = [net.names[a] for a in range(net.n) if net.role[a] != 1 and a not in pts]
    C = dt.constraint_matrix(net.theta_true()[None])
    sim = _mc(net, an, C, pts, cfg, ctx)
    n_ok = sim["sum.n"][:, 0]
    if n_ok.sum() < 2 or np.count_nonzero(n_ok) < 2:
        raise StudyError(
            "solver.max_iter: fewer than two chunks have converged trials; the "
            "network does not converge from its true coordinates"
        )
    sums = np.concatenate(
        [
            sim["sum.n"],
            sim["sum.e"].reshape(len(n_ok), -1),
            np.einsum("ckii->cki", sim["sum.ee"]).reshape(len(n_ok), -1),
            sim["sum.inside"],
            sim["sum.reject"],
        ],
        axis=1,
    )
    k = len(pts)

    def sig(t):
        n, e, ee = t[0], t[1 : 1 + 2 * k], t[1 + 2 * k : 1 + 4 * k]
        return np.sqrt(np.maximum(ee / n - (e / n) ** 2, 0) * n / (n - 1))

    an_sig = np.sqrt(np.stack([an.cov[pts, 0, 0], an.cov[pts, 1, 1]], 1)).reshape(-1)
    s_mc, s_lo, s_hi = jackknife(sig, sums)
    ratio = jackknife(lambda t: np.atleast_1d(np.mean(sig(t) / an_sig)), sums)
    cover = jackknife(lambda t: t[1 + 4 * k : 1 + 5 * k] / t[0], sums)
    cover_mean = jackknife(lambda t: np.atleast_1d(np.mean(t[1 + 4 * k : 1 + 5 * k] / t[0])), sums)
    alarm = jackknife(lambda t: np.atleast_1d(t[-1] / t[0]), sums)

    a95, b95, th = ellipse(an.cov[pts])
    extra = compare_points(net, cfg)
    dil = np.full(k, np.nan)
    if extra:
        an2 = analyse(net, datum(net, full, tuple(extra)), 0.001, 0.8)
        if not an2.ok:
            raise StudyError("compare.fix: the compared parameterisation is singular")
        s1, s2 = _rms_sigma(an.cov[pts]), _rms_sigma(an2.cov[pts])
        with np.errstate(divide="ignore", invalid="ignore"):
            dil = np.where(s2 > 0, 100 * (s1 / s2 - 1), np.nan)
    write_table(
        out / "points.parquet",
        {
            "point": [net.names[a] for a in pts],
            "x_mm": net.xy[pts, 0],
            "y_mm": net.xy[pts, 1],
            "role": [("free", "fixed", "observed")[net.role[a]] for a in pts],
            "sigma_x_mm": an_sig[0::2],
            "sigma_y_mm": an_sig[1::2],
            "ellipse95_a_mm": K95 * a95,
            "ellipse95_b_mm": K95 * b95,
            "ellipse_bearing_deg": np.degrees(th),
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
    )
    _parameters(net, an, sim, n_ok, out, prov)
    drows = {"datum": [], "point": [], "sigma_x_mm": [], "sigma_y_mm": []}
    if cfg["output.inner_over"]:  # the patterns form one set of datum points
        sel = match_points(net, "output.inner_over", cfg["output.inner_over"])
        cov = in_datum(net, an, sel)
        for a in range(net.n):
            drows["datum"].append(f"inner over {', '.join(cfg['output.inner_over'])}")
            drows["point"].append(net.names[a])
            drows["sigma_x_mm"].append(float(np.sqrt(max(cov[a, 0, 0], 0))))
            drows["sigma_y_mm"].append(float(np.sqrt(max(cov[a, 1, 1], 0))))
    write_table(out / "datums.parquet", drows, prov)
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
    gama = export(net, full, out / "network.xml")
    n_tot = float(n_ok.sum())
    write_table(
        out / "summary.parquet",
        {
            "network": [net.name],
            "points": [net.n],
            "observations": [net.m],
            "unknowns": [len(an.free)],
            "datum": [cfg["datum.kind"]],
            "datum_constraints": [0 if C is None else C.shape[-1]],
            "dof": [an.dof],
            "redundancy_sum": [float(an.redundancy.sum())],
            "trials": [cfg["trials"]],
            "converged": [int(n_tot)],
            "false_alarm": [float(alarm[0][0])],
            "test_alpha": [cfg["test.alpha"]],
            "coverage95_mean": [float(cover_mean[0][0])],
            "mc_over_analytic": [float(ratio[0][0])],
            "compare_fix": [", ".join(cfg["compare.fix"])],
            "held_by_datum": [", ".join(held)],
            "gama_xml": [gama],
            "gama_input": [import_note(cfg)],
        },
        prov,
    )
    design = {
        "sigma_max": (
            float(np.max(np.maximum(an_sig[0::2], an_sig[1::2]))),
            float(np.max(np.maximum(s_mc[0::2], s_mc[1::2]))),
        ),
        "a95_max": float(np.max(K95 * a95)),
        "dilution_max": dil,
        "r_min": float(an.redundancy.min()),
        "mdb_mm": an.mdb[~np.isin(net.kind, (1, 2))],
        "sigma_rms": float(np.sqrt(np.mean(an_sig**2))),
    }
    _claims(out, prov, an, ratio, cover_mean, alarm, cfg, n_tot, design)
    draw_figures(
        [
            (network_figure, (net, an, pts, out / "network.png")),
            (reliability_figure, (net, an, out / "reliability.png")),
        ],
        ctx.executor,
    )


def _parameters(net: Network, an, sim: dict, n_ok: np.ndarray, out: Path, prov: dict) -> None:
    """``parameters.parquet``: the estimated globals that are not coordinates (orientation of
    each direction set in arcsec, additive constant in mm, scale in ppm) with their true value,
    analytic sigma and Monte-Carlo mean error and sigma with intervals."""
    par = _params(net, an)
    names = net.parameter_names()
    units = ["arcsec"] * len(net.stations) + ["mm", "ppm"]
    f = np.array([1 / (np.pi / 648000)] * len(net.stations) + [1.0, 1.0])
    rel = par - 2 * net.n
    pos = {g: a for a, g in enumerate(an.free)}
    an_sig = (
        np.sqrt(np.maximum([an.Q[pos[g], pos[g]] for g in par], 0.0)) if len(par) else np.zeros(0)
    )
    cols = {
        "parameter": [names[r] for r in rel],
        "unit": [units[r] for r in rel],
        "true": net.theta_true()[par] * f[rel],
        "sigma": an_sig * f[rel],
    }
    if len(par):
        kp = len(par)
        sums = np.concatenate([n_ok[:, None], sim["sum.pe"], sim["sum.pee"]], axis=1)

        def mean(t):
            return t[1 : 1 + kp] / t[0]

        def sd(t):
            n, e, ee = t[0], t[1 : 1 + kp], t[1 + kp :]
            return np.sqrt(np.maximum(ee / n - (e / n) ** 2, 0) * n / (n - 1))

        (m, m_lo, m_hi), (s_, s_lo, s_hi) = jackknife(mean, sums), jackknife(sd, sums)
        cols.update(
            {
                "mc_mean_error": m * f[rel],
                "mc_mean_error_lo": m_lo * f[rel],
                "mc_mean_error_hi": m_hi * f[rel],
                "mc_sigma": s_ * f[rel],
                "mc_sigma_lo": s_lo * f[rel],
                "mc_sigma_hi": s_hi * f[rel],
            }
        )
    else:
        cols.update(
            {
                k: np.zeros(0)
                for k in (
                    "mc_mean_error",
                    "mc_mean_error_lo",
                    "mc_mean_error_hi",
                    "mc_sigma",
                    "mc_sigma_lo",
                    "mc_sigma_hi",
                )
            }
        )
    write_table(out / "parameters.parquet", cols, prov)


def _claims(out, prov, an, ratio, cover, alarm, cfg, n_tot, design) -> None:
    """Self-checks, with decision zones stated a priori: Monte Carlo within 5 % of analytic,
    coverage and false-alarm rate within 2 points of their nominal values, redundancy numbers
    summing to the degrees of freedom to 1e-6. Then the design figures as findings (exact,
    analytic), so that a ``[sweep]`` over any key tabulates them per cell: the largest and
    the rms point sigma, the largest 95 % semi-axis, the smallest redundancy number, the
    largest MDB of a length observation and the largest dilution against ``compare.fix``."""
    a = cfg["test.alpha"]
    spec = [
        (
            "network.mc_agreement.mean_ratio",
            "Monte-Carlo sigma / analytic sigma (mean over coordinates)",
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
            f"rejection rate of the global test at alpha {a:g} (no blunders)",
            a,
            0.02,
        ),
        (
            "network.redundancy.sum",
            "redundancy numbers sum to the degrees of freedom",
            float(an.dof),
            1e-6,
        ),
    ]
    src = "this project (analytic pre-analysis)"
    mdb = design["mdb_mm"][np.isfinite(design["mdb_mm"])]
    dil = design["dilution_max"][np.isfinite(design["dilution_max"])]
    finds = [
        (
            "network.design.sigma_max_mm",
            "largest point sigma (x or y), mm",
            design["sigma_max"][0],
            f"analytic; Monte Carlo {design['sigma_max'][1]:.4g} mm",
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
    book = ClaimBook(
        [
            {
                "id": i,
                "source": src,
                "paper": p,
                "kind": "self-check",
                "form": "value",
                "ref": r,
                "tol": t,
            }
            for i, p, r, t in spec
        ]
        + [{"id": f[0], "source": src, "paper": f[1], "kind": "finding"} for f in finds],
        [],
        "<network self-checks>",
    )
    note = f"{int(n_tot)} converged of {cfg['trials']} trials; jackknife CI over chunks"
    rows = [
        book.score(spec[0][0], ratio[0][0], (ratio[1][0], ratio[2][0]), note=note),
        book.score(spec[1][0], cover[0][0], (cover[1][0], cover[2][0]), note=note),
        book.score(spec[2][0], alarm[0][0], (alarm[1][0], alarm[2][0]), note=note),
        book.score(
            spec[3][0],
            float(an.redundancy.sum()),
            interval="exact",
            note=f"{len(an.redundancy)} observations, dof {an.dof}",
        ),
    ]
    rows += [book.score(i, v, interval="exact", note=nt) for i, _, v, nt in finds]
    write_claims(out / "claims.parquet", rows, prov, book)
