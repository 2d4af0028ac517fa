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

from pathlib import Path

from sim.mc.config import StudyError
from sim.mc.progress import phase
from sim.mc.runner import run_chunks
from sim.mc.storage import provenance
from sim.report.plotting import draw
from sim.studies.network.analysis import ellipse, estimated_points
from sim.studies.network.bias_checks import bias_effect
from sim.studies.network.claims import design_figures, network_claims
from sim.studies.network.compare import dilution
from sim.studies.network.definition import build
from sim.studies.network.estimates import TOO_FEW, mc_estimates
from sim.studies.network.figures import network_figure, reliability_figure
from sim.studies.network.gama import export, import_note, merge_gama
from sim.studies.network.model import datum
from sim.studies.network.probe import chunk_fn, not_converged
from sim.studies.network.rounding import check_rounding
from sim.studies.network.sparse_analysis import (
    pre_analysis,
    shows_phases,
    shows_phases_of,
)
from sim.studies.network.tables import (
    K95,
    write_datums,
    write_observations,
    write_parameters,
    write_points,
    write_summary,
)

__all__ = ["run"]


def _mc(net, an, C, pts, cfg, ctx):
    fn = chunk_fn(net, an, C, pts, cfg)
    return run_chunks(
        fn, cfg["trials"], cfg["seed"], cfg["chunk"], part=0, label=cfg["study"], ctx=ctx
    )


def run(cfg: dict, out: Path, ctx) -> None:
    """Pre-analysis in the configured datum, the Monte Carlo, then the tables, the claims,
    the gama-local export and the figures."""
    out = Path(out)
    full = merge_gama(cfg)
    quiet = True if getattr(ctx, "quiet", False) else None  # else --quiet as the command set it
    with phase("network: building", shows_phases_of(cfg), quiet):
        net = build(full)
    show = shows_phases(net.q)
    dt = datum(net, full)
    an = pre_analysis(net, dt, cfg["reliability.alpha0"], cfg["reliability.power"])
    if not an.ok:
        raise StudyError("datum.kind: the normal equations are singular in this datum")
    prov = provenance(cfg)
    pts = estimated_points(net, an)
    check_rounding(net, an.cov, pts)
    held = [net.names[a] for a in range(net.n) if net.role[a] != 1 and a not in pts]
    C = dt.constraint_matrix(net.theta_true()[None])
    sim = _mc(net, an, C, pts, cfg, ctx)
    try:
        est = mc_estimates(an, pts, sim)
    except StudyError:
        key, msg = not_converged(net, an, C, pts, cfg, TOO_FEW)
        raise StudyError(f"{key}: {msg}") from None
    with phase("network: tables and figures", show, quiet):
        _outputs(out, cfg, full, net, an, dt, C, pts, held, sim, est, prov)


def _outputs(out, cfg, full, net, an, dt, C, pts, held, sim, est, prov) -> None:
    """The compared parameterisation, the tables, the claims, the export and the figures."""
    dil = dilution(net, an, full, cfg, pts)
    write_points(out, net, an, pts, est, dil, prov)
    write_parameters(out, net, an, sim, est.n_ok, prov)
    write_datums(out, net, an, cfg, prov)
    write_observations(out, net, an, prov)
    facts = {
        "datum_constraints": 0 if C is None else C.shape[-1],
        "held_by_datum": ", ".join(held),
        "gama_xml": export(net, full, out / "network.xml"),
        "gama_input": import_note(cfg),
    }
    write_summary(out, net, an, full, facts, est, prov)  # full: the datum as read
    a95 = K95 * ellipse(an.cov[pts])[0]
    biased = bias_effect(net, an, C, pts, cfg)
    network_claims(out, prov, an, est, cfg, design_figures(net, an, a95, dil, est), biased)
    draw(
        [
            (network_figure, (net, an, pts, out / "network.png")),
            (reliability_figure, (net, an, out / "reliability.png")),
        ]
    )
