"""Whether the Brown studies' solver limits can be met (seed 004): a probe of a few plates of
the run's own error model, at ``sim check`` time (a limit no trial can meet was refused only
after every chunk had run).

Coordinates in mm, standard deviations in um.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.ranges import multilateration as ml
from sim.mc.runner import PROBE_MAX_ITER, PROBE_SEED, PROBE_TRIALS, probe_limit
from sim.studies.brown.values import start_theta

__all__ = ["check_solver"]


def check_solver(cfg: dict, pts: np.ndarray, theta: np.ndarray, models, default: int) -> None:
    """The solver limits can be met: ``PROBE_TRIALS`` plates of the run's error model (a fixed
    stream, not the run's) adjusted with each model from the run's start values; a limit no
    probe plate meets is refused by :func:`sim.mc.runner.probe_limit`. Before this check,
    ``solver.max_iter = 1`` (or 2 for the pivot model, which starts at alpha = beta = 0) passed
    ``sim check`` and the run refused only after computing every chunk. Run only for a small
    limit (``PROBE_MAX_ITER``): a 100 x 100 plate's probe takes seconds.
    ``theta``: the run's true globals (7,); ``models``: the models the run adjusts with;
    ``default``: the key's default limit."""
    if cfg["solver.max_iter"] > PROBE_MAX_ITER:
        return  # no plates simulated
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

    def statuses(m: str):
        t0 = start_theta(theta, m)
        return lambda max_iter: (
            ml.adjust(
                obs, m, t0, tol_mm=cfg["solver.tol_mm"], max_iter=max_iter, engine="numpy"
            ).status
        )

    for m in models:
        probe_limit(cfg, statuses(m), default, f"{m} model")
