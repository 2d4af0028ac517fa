"""The Monte Carlo's chunk function of a network, and the solver probe ``sim check`` runs
with it: a few trials from a fixed stream of their own (not the run's), refused when none
converges within ``solver.max_iter`` (status 1, the iteration limit). ``solver.max_iter = 1``
was accepted, every chunk computed, and the run then refused ("fewer than two chunks have
converged trials"): the first correction from the true coordinates is the noise itself, so
a trial converges at the earliest in the second iteration."""

from __future__ import annotations

from dataclasses import replace
from functools import partial

import numpy as np

from sim.lsq import distributions as D
from sim.mc.config import ConfigError
from sim.mc.runner import PROBE_SEED, PROBE_TRIALS, probe_limit
from sim.studies.network.analysis import mc_chunk
from sim.studies.network.definition import Network
from sim.studies.network.keys import SCHEMA
from sim.studies.network.linearity import biased, why_not_converged
from sim.studies.network.sparse_analysis import SparseAnalytic, mc_chunk_sparse
from sim.studies.network.tables import parameter_indices

#: why a limit of one iteration never converges (said with the refusal, as before it was common)
FIRST = (
    "the first correction from the true coordinates is the noise itself, so a trial converges "
    "in its second iteration at the earliest"
)


def chunk_fn(net: Network, an, C, pts, cfg: dict):
    """The function of one chunk (rng, n) -> outputs that the run's Monte Carlo calls."""
    crit = float(D.chi2_ppf(1 - cfg["test.alpha"], an.dof))
    common = dict(
        net=net,
        free=an.free,
        cov_inv=np.linalg.inv(an.cov[pts]),
        pts=np.asarray(pts),
        crit=crit,
        tol=cfg["solver.tol_mm"],
        max_iter=cfg["solver.max_iter"],
        par=parameter_indices(net, an),
    )
    if isinstance(an, SparseAnalytic):  # one factor for every trial and iteration
        return partial(mc_chunk_sparse, fac=an.factor, dof=an.dof, **common)
    return partial(mc_chunk, C=None if C is None else C[0], **common)


def probe_solver(net: Network, an, C, pts, cfg: dict) -> None:
    """Refuse a solver limit no probe trial meets, naming ``solver.max_iter`` and the network
    (:func:`sim.mc.runner.probe_limit`); and a network none of whose probe trials converges
    at any limit, naming a gross bias or the sight too short for its noise
    (:mod:`sim.studies.network.linearity`): the run computed every chunk, then refused,
    naming ``solver.max_iter``. The probe is 16 trials, a second on a 90,000-point network."""
    seen: dict[int, np.ndarray] = {}

    def statuses(max_iter: int) -> np.ndarray:
        if max_iter not in seen:
            fn = chunk_fn(net, an, C, pts, {**cfg, "solver.max_iter": max_iter})
            seen[max_iter] = fn(np.random.default_rng(PROBE_SEED), PROBE_TRIALS)["rows.status"]
        return seen[max_iter]

    probe_limit(cfg, statuses, SCHEMA["solver.max_iter"].default, f"{net.name!r} network", FIRST)
    limit = cfg["solver.max_iter"]
    if np.any(statuses(limit) == 0):
        return
    what = f"none of {PROBE_TRIALS} probe trials converged within solver.max_iter = {limit}"
    raise ConfigError(*cause(net, an, C, pts, cfg, what))


def cause(net: Network, an, C, pts, cfg: dict, what: str) -> tuple[str, str]:
    """``(key, message)`` of a network whose trials do not converge (``what``: which): its
    bias when more of the same probe trials (one stream, the same noise) converge without it
    than with it, else the weakest sight. A bias of 0.01 sigma was named "a gross error" of a
    network too short for its noise; shared by the probe and the run's own refusal after its
    chunks, which named any bias first (a probe that passed had converged with it)."""
    if np.any(net.bias):
        n_ok = []
        for b in (net, replace(net, bias=np.zeros_like(net.bias))):
            out = chunk_fn(b, an, C, pts, cfg)(np.random.default_rng(PROBE_SEED), PROBE_TRIALS)
            n_ok.append(int(np.sum(out["rows.status"] == 0)))
        if n_ok[1] > n_ok[0]:
            return biased(net, cfg, what)
    return why_not_converged(net, an.cov, cfg, what)
