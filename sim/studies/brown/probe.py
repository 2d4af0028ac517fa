"""Whether the Brown studies' solver limits can be met (seed 004): a probe of a few plates of
the run's own error model, at ``sim check`` time (a limit no trial can meet was refused only
after every chunk had run).

Coordinates in mm, standard deviations in um.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.ranges import multilateration as ml
from sim.mc.config import ConfigError
from sim.mc.runner import PROBE_MAX_ITER, PROBE_SEED, PROBE_TRIALS, probe_limit
from sim.studies.brown.values import start_theta

#: the most points a plate's noise probe (:func:`check_noise`) adjusts
PROBE_POINTS = 2500

__all__ = ["check_noise", "check_solver", "check_start"]

#: the error keys of one range, in the order a refusal names them (the larger share first)
SIGMA_KEYS = ("errors.setting_sigma_um", "errors.comparator_sigma_um")
#: the solver's limits, named first when their defaults let every probe plate converge
SOLVER_KEYS = ("solver.max_iter", "solver.tol_mm")


def _probe_ranges(cfg: dict, pts: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """The ranges (mm) of :data:`PROBE_TRIALS` plates of the run's error model, drawn from a
    fixed stream (:data:`PROBE_SEED`), not the run's."""
    return ml.simulate_ranges(
        np.broadcast_to(pts, (PROBE_TRIALS,) + pts.shape),
        np.broadcast_to(theta, (PROBE_TRIALS, 7)),
        np.random.default_rng(PROBE_SEED),
        setting_sigma_um=cfg["errors.setting_sigma_um"],
        settings=cfg["errors.settings"],
        comparator_sigma_um=cfg["errors.comparator_sigma_um"],
        bias_um=cfg["errors.bias_um"],
    )


def _failing(cfg: dict, pts: np.ndarray, theta: np.ndarray, models) -> tuple[str, int]:
    """The first of ``models`` some probe plate (:func:`_probe_ranges`) does not converge
    with at the run's solver limits, and how many do not ("", 0: every one converges)."""
    obs = _probe_ranges(cfg, pts, theta)
    for m in models:
        res = ml.adjust(
            obs,
            m,
            start_theta(theta, m),
            tol_mm=cfg["solver.tol_mm"],
            max_iter=cfg["solver.max_iter"],
            engine="numpy",
        )
        if bad := int((res.status != 0).sum()):
            return m, bad
    return "", 0


def check_noise(
    cfg: dict, key: str, pts: np.ndarray, theta: np.ndarray, models, moved, defaults: dict
) -> None:
    """Every one of :data:`PROBE_TRIALS` plates of the run's error model converges with each
    model at the run's solver limits. The statistics of a run are taken over the trials that
    converged in all models: solver limits too tight for them, or range errors large against
    what the plate determines (the
    paper's plate with 14 mm range sigmas: 93 of 400 trials converged and the Monte-Carlo
    self-check passed on that selection; a 4 mm plate at 0.4 mm: none, refused after every
    chunk had run) passed ``sim check``; so did ``solver.max_iter = 3`` or ``solver.tol_mm =
    1e-15`` on the paper's plate, where 10 and 9 of the 16 do not converge. Named: a solver
    key whose default lets every probe plate converge, else the larger error share when the paper's
    errors (``defaults``) let the probe converge on this plate, else the first plate key of
    the ``moved`` range keys (:func:`sim.studies.brown.range_keys.moved_from_paper`), the
    last of them, or the points' ``key``. Probed up
    to :data:`PROBE_POINTS` points (a larger plate's probe would take tens of seconds)."""
    if len(pts) > PROBE_POINTS or not np.all(np.isfinite(ml.ranges(pts[None], theta[None]))):
        return
    m, bad = _failing(cfg, pts, theta, models)
    if not m:
        return
    limits = f"solver.max_iter = {cfg['solver.max_iter']}, solver.tol_mm = {cfg['solver.tol_mm']:g}"
    head = f"{bad} of {PROBE_TRIALS} probe plates of the run's error model (range sigma "
    shares = (cfg[SIGMA_KEYS[0]] ** 2 / cfg["errors.settings"], cfg[SIGMA_KEYS[1]] ** 2)
    head += f"{np.sqrt(sum(shares)):.3g} um) do not converge with the {m} model within {limits}"
    tail = "the run's statistics would be those of the trials that happened to converge"
    for k in SOLVER_KEYS:  # the solver's limits first: at their defaults the plates converge
        if cfg[k] != defaults[k] and not _failing({**cfg, k: defaults[k]}, pts, theta, models)[0]:
            raise ConfigError(k, f"{head} (they do at its default {defaults[k]:g}): {tail}")
    paper = {**cfg, **{k: defaults[k] for k in (*SIGMA_KEYS, "errors.settings")}}
    blame = SIGMA_KEYS[int(shares[1] > shares[0])]
    if _failing(paper, pts, theta, models)[0]:  # the plate's doing: its key, as changed
        blame = next((k for k in moved if k.startswith("plate.")), moved[-1] if moved else key)
    raise ConfigError(
        blame,
        f"{head}: the errors are too large for what the {len(pts)} points determine, and "
        f"{tail}; use smaller errors or a wider plate"
        + (f"; changed from their paper or nominal values: {', '.join(moved)}" if moved else ""),
    )


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
    obs = _probe_ranges(cfg, pts, theta)

    def statuses(m: str):
        t0 = start_theta(theta, m)
        return lambda max_iter: (
            ml.adjust(
                obs, m, t0, tol_mm=cfg["solver.tol_mm"], max_iter=max_iter, engine="numpy"
            ).status
        )

    for m in models:
        probe_limit(cfg, statuses(m), default, f"{m} model")


def _starts(cfg: dict, geometry, models, max_iter: int) -> str:
    """The first of ``models`` whose adjustment of the exact ranges of ``geometry(cfg)``
    (points (n, 2) mm, globals (7,)) does not converge from its start values ("": all do)."""
    pts, theta = geometry(cfg)
    r = ml.ranges(pts[None], theta[None])
    for m in models:
        t0 = start_theta(theta, m)
        res = ml.adjust(r, m, t0, tol_mm=cfg["solver.tol_mm"], max_iter=max_iter, engine="numpy")
        if res.status[0] != 0:
            return m
    return ""


def check_start(cfg: dict, key: str, geometry, models, moved, defaults: dict) -> None:
    """Every model's adjustment reaches the true globals from its start values (the design
    stations; the pivot model's alpha and beta^2 at 0) on the exact ranges, within the larger
    of ``solver.max_iter`` and its default: a 3 x 3 plate 60 mm apart with alpha = 50 mm took
    its first Gauss-Newton step to stations 50 mm in, where the normals are singular, and every
    trial failed after the run computed every chunk ("only 0 trials converged ... pivot 40").
    ``geometry``: the config's points and globals; ``moved``: the keys changed from
    ``defaults`` (:func:`sim.studies.brown.range_keys.moved_from_paper`), of which the one
    whose default value lets the model converge is named (alpha and beta first, which the
    start misses), else ``key`` (the points')."""
    it = max(cfg["solver.max_iter"], defaults["solver.max_iter"])
    m = _starts(cfg, geometry, models, it)
    if not m:
        return
    zeros = ("comparator.alpha_mm", "comparator.beta_mm")  # what the start misses first
    order = [k for k in zeros if k in moved] + [k for k in reversed(moved) if k not in zeros]
    blame = next((k for k in order if not _starts({**cfg, k: defaults[k]}, geometry, [m], it)), key)
    raise ConfigError(
        blame,
        f"the {m} model does not converge from its start values (the design stations"
        + (", alpha and beta at 0" if m == "pivot" else "")
        + f") within {it} iterations even on exact ranges, so no trial would (the run would "
        "compute every chunk, then refuse)"
        + (f"; changed from their paper or nominal values: {', '.join(moved)}" if moved else ""),
    )
