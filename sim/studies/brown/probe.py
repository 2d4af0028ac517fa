"""Whether the Brown studies' solver limits can be met (seed 004): a probe of a few plates of
the run's own error model, at ``sim check`` time (a limit no trial can meet was refused only
after every chunk had run).

Coordinates in mm, standard deviations in um.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.ranges import multilateration as ml
from sim.mc.config import ConfigError
from sim.mc.runner import PROBE_MAX_ITER, PROBE_SEED, PROBE_TRIALS
from sim.studies.brown.values import start_theta

__all__ = ["check_solver"]


def check_solver(cfg: dict, pts: np.ndarray, theta: np.ndarray, models, default: int) -> None:
    """The solver limits can be met: ``PROBE_TRIALS`` plates of the run's error model (a fixed
    stream, not the run's) adjusted with each model from the run's start values. When no
    probe plate of a model converges within ``solver.max_iter`` (status 1, the iteration
    limit), no trial of the run would either: the run computed every chunk and then
    refused (``solver.max_iter = 1``, or 2 for the pivot model, which starts at alpha =
    beta = 0). Run only for a small limit (``PROBE_MAX_ITER``): a 100 x 100 plate's probe
    takes seconds. ``theta``: the run's true globals (7,); ``models``: the models the run
    adjusts with; ``default``: the key's default limit."""
    if cfg["solver.max_iter"] > PROBE_MAX_ITER:
        return
    if not np.all(np.isfinite(ml.ranges(pts[None], theta[None]))):
        return  # the scale check names the overflow when the scale is enforced
    obs = ml.simulate_ranges(
        np.broadcast_to(pts, (PROBE_TRIALS,) + pts.shape),
        np.broadcast_to(theta, (PROBE_TRIALS, 7)),
        np.random.default_rng(PROBE_SEED),
        setting_sigma_um=cfg["errors.setting_sigma_um"],
        settings=cfg["errors.settings"],
        comparator_sigma_um=cfg["errors.comparator_sigma_um"],
        bias_um=cfg["errors.bias_um"],
    )
    tol, limit = cfg["solver.tol_mm"], cfg["solver.max_iter"]

    def status(m: str, max_iter: int) -> np.ndarray:
        t0 = start_theta(theta, m)
        return ml.adjust(obs, m, t0, tol_mm=tol, max_iter=max_iter, engine="numpy").status

    for m in models:
        # the limit is the cause only when the same plates converge with the key's default
        if np.all(status(m, limit) == 1) and np.any(status(m, default) == 0):
            raise ConfigError(
                "solver.max_iter",
                f"{limit} iteration{'s' * (limit > 1)} to solver.tol_mm = {tol:g}: none of "
                f"{PROBE_TRIALS} probe plates of the {m} model converged, so no trial would "
                "(the run would compute every chunk, then refuse): raise solver.max_iter (or "
                "tol_mm)",
            )
