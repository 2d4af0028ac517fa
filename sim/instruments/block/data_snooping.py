"""Data snooping in a block of independent models, batched over Monte-Carlo trials.

Seed: ``003_5ce730a990a7ebc5.txt`` (Agnard, Nolette & Gagnon): after the block adjustment
(:func:`sim.instruments.block.independent_models.adjust_block`) the candidate points (the pass points) are
tested;
Baarda's w-test on each residual component with the
a-priori variance of unit weight (weights ``1 / sigma^2``), ``w = v / sqrt(q_vv)``, or
Pope's tau-test with the a-posteriori one; the pass point with the largest ``|w|`` above
the critical value is removed and the block re-adjusted until none exceeds it.

Residual cofactors come from the engine's group-block cofactors
(:meth:`sim.lsq.groups.GroupCofactors.residuals`), computed only for the observations of
the candidate points. Units: metres (residuals), cofactors for unit weight.
"""

from __future__ import annotations

import numpy as np

from sim import lsq
from sim.instruments.block.independent_models import AdjustResult, BlockStructure, adjust_block

__all__ = ["residual_cofactors", "snoop"]


def residual_cofactors(
    st: BlockStructure, res: AdjustResult, w_obs: np.ndarray, points: np.ndarray | None = None
) -> np.ndarray:
    """Diagonal of the residual cofactor matrix ``Q_vv = W^-1 - A Q_xx A^T`` of the model
    points, ``(T, K, 3)`` (:meth:`sim.lsq.groups.GroupCofactors.residuals`, with the weights
    of the adjustment; ``w_obs`` must be those). Removed observations (weight 0) get NaN, and
    so do, with ``points`` (bool (P,)), the observations of the other points."""
    eng = res.engine
    lin = eng.model.linearize(eng.points, eng.theta)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        return lsq.groups.cofactors(st, lin).residuals(lin, points)


def snoop(
    st: BlockStructure,
    xm,
    w_obs,
    ctrl_xyz,
    w_ctrl,
    s0,
    R0,
    t0,
    X0,
    candidates: np.ndarray,
    crit: float,
    max_reject: int = 30,
    a_posteriori: bool = False,
):
    """Iterative data snooping (Baarda's w-test) on the points flagged in ``candidates``.

    Weights must be ``1 / sigma^2`` (a-priori variance of unit weight 1). At each round
    the candidate point with the largest ``|w| = |v| / (sigma0 sqrt(q_vv))`` over its
    observation components is removed (all its model observations) when ``|w| > crit``; the
    block is re-adjusted and tested again. ``sigma0`` is 1 (Baarda's w-test) or, with
    ``a_posteriori``, the block's own estimate (Pope's tau-test). Only trials that still
    reject are re-adjusted. Returns ``(rejected (T, P) bool, sigma0 (T,), w_max (T,),
    rounds (T,))`` with ``w_max`` the largest remaining ``|w|`` of a candidate.
    """
    T, K = xm.shape[:2]
    w = np.array(np.broadcast_to(w_obs, (T, K, 3)), float)
    ctrl_xyz = np.broadcast_to(ctrl_xyz, (T,) + np.shape(ctrl_xyz)[-2:])
    rejected = np.zeros((T, st.n_points), bool)
    cand = np.asarray(candidates, bool)
    cand_obs = cand[st.obs_point]
    s, R, t, X = (np.array(a, float) for a in (s0, R0, t0, X0))
    sigma0 = np.ones(T)
    wmax = np.zeros(T)
    rounds = np.zeros(T, np.int32)
    act = np.arange(T)
    for _ in range(max_reject + 1):
        res = adjust_block(
            st, xm[act], w[act], ctrl_xyz[act], w_ctrl, s[act], R[act], t[act], X[act]
        )
        s[act], R[act], t[act], X[act] = res.s, res.R, res.t, res.X
        sigma0[act] = res.sigma0
        q = residual_cofactors(st, res, w[act], cand)
        s0 = res.sigma0[:, None, None] if a_posteriori else 1.0
        ok = (w[act] > 0) & (q > 1e-9 / np.maximum(w[act], 1e-300)) & cand_obs[None, :, None]
        wt = np.where(ok, np.abs(res.v_obs) / (s0 * np.sqrt(np.where(ok, q, 1.0))), 0.0)
        wk = wt.max(-1)  # (n_act, K)
        kbest = wk.argmax(1)
        wmax[act] = wk[np.arange(act.size), kbest]
        flag = wmax[act] > crit
        if not flag.any() or rounds.max() >= max_reject:
            break
        hit = act[flag]
        rejected[hit, st.obs_point[kbest[flag]]] = True
        rounds[hit] += 1
        w[hit] = np.where(rejected[hit][:, st.obs_point, None], 0.0, w[hit])
        act = hit
    return rejected, sigma0, wmax, rounds
