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
            seen[max_iter] = _probe(net, an, C, pts, {**cfg, "solver.max_iter": max_iter})
        return seen[max_iter]

    probe_limit(cfg, statuses, SCHEMA["solver.max_iter"].default, f"{net.name!r} network", FIRST)
    limit = cfg["solver.max_iter"]
    if np.any(statuses(limit) == 0):
        return
    what = f"none of {PROBE_TRIALS} probe trials converged within solver.max_iter = {limit}"
    raise ConfigError(*not_converged(net, an, C, pts, cfg, what, statuses(limit)))


def _probe(net: Network, an, C, pts, cfg: dict) -> np.ndarray:
    """The solver statuses of the :data:`PROBE_TRIALS` probe trials of ``net``, adjusted in
    chunks of at most the run's ``chunk`` trials from one stream (the same draws, so the same
    statuses, as one chunk of all of them): the memory estimate counts ``chunk`` trials, and
    a dense network of 39,006 distances at ``chunk = 2`` asked 1.84 GiB for the 16 trials'
    Jacobian in one array, 8 times what the estimate had counted."""
    fn, rng = chunk_fn(net, an, C, pts, cfg), np.random.default_rng(PROBE_SEED)
    step = max(1, min(int(cfg["chunk"]), PROBE_TRIALS))
    return np.concatenate(
        [fn(rng, min(step, PROBE_TRIALS - i))["rows.status"] for i in range(0, PROBE_TRIALS, step)]
    )


def not_converged(
    net: Network, an, C, pts, cfg: dict, what: str, status: np.ndarray | None = None
) -> tuple[str, str]:
    """``(key, message)`` for a network whose trials do not converge (``what``: which), at
    load time (none of the probe trials) or after the run (too few of its trials), by the
    probe trials (``status``: their statuses as declared, probed when not given): a bias
    (:func:`sim.studies.network.linearity.biased`) when they converge more often without the
    biases; ``solver.max_iter`` when it is under the key's default and they converge more
    often within the default; else the sight too short for its noise
    (:func:`sim.studies.network.linearity.why_not_converged`). A bias of 0.01 sigma was
    named "a gross error" of a network too short for its noise (by the probe; after the run,
    any bias, 0.001 mm on a 1 mm distance), and a run at ``solver.max_iter = 10`` of which 11
    of the 16 probe trials converge within 20 was told to place its points further apart."""
    ok = partial(_converged, net, an, C, pts, cfg)
    n = int(np.count_nonzero(status == 0)) if status is not None else ok()
    if np.any(net.bias) and ok(net=replace(net, bias=np.zeros_like(net.bias))) > n:
        return biased(net, cfg, what)
    limit, default = cfg["solver.max_iter"], SCHEMA["solver.max_iter"].default
    if limit < default and (m := ok(max_iter=default)) > n:
        return "solver.max_iter", (
            f"{what}: {n} of {PROBE_TRIALS} probe trials converge within solver.max_iter = "
            f"{limit}, {m} within the key's default {default}: raise solver.max_iter"
        )
    return why_not_converged(net, an.cov, cfg, what)


def _converged(net0: Network, an, C, pts, cfg: dict, net=None, max_iter=None) -> int:
    """How many of the probe trials of ``net`` (else ``net0``) converge within ``max_iter``
    (else ``cfg``'s ``solver.max_iter``)."""
    limit = cfg["solver.max_iter"] if max_iter is None else max_iter
    st = _probe(net0 if net is None else net, an, C, pts, {**cfg, "solver.max_iter": limit})
    return int(np.count_nonzero(st == 0))
