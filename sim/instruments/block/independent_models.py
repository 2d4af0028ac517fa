"""Block adjustment of independent stereomodels in 3-D, batched over Monte-Carlo trials.

Seed: ``003_5ce730a990a7ebc5.txt`` (Agnard, Nolette & Gagnon): a block of two strips of
eight models adjusted by independent models (the program SPACE-M of J. A. R. Blais), a
7-parameter similarity per model, pass points tying models and strips, control weighted
3 (planimetry) and 2 (height) against 0.1 on pass points; a first pass with 0.1 on control
and 1.0 on pass points; digital pugging (the pass point keeps the very same image
coordinates on the photo two models share) against mechanical pugging (re-centred).

The simulated measurements (stereomodel formation, the models' arbitrary frames, the pointing
errors) are in :mod:`sim.instruments.block.pointing` (imported here under their old names).

**Adjustment** (:func:`adjust_block`). Unknowns: per model ``m`` a similarity
``G = s_m R_m (x - c_m) + t_m`` (``c_m`` the centroid of the model's points, for
conditioning) and per point its ground coordinates ``X_j``. Observation equations

    v_mj = s_m R_m (x_mj - c_m) + t_m - X_j        (model points, weights w_obs)
    v_j  = X_j - X_j^control                        (control, weights w_ctrl)

linearised with the multiplicative corrections ``s <- s (1 + dl)``, ``R <- R(dtheta) R``.
Gauss-Newton over a leading trial axis. The point blocks (3 x 3, diagonal here) are
eliminated: the reduced normals of the model parameters have one 7 x 7 block per pair of
models that share a point, assembled from the list of such pairs with sparse scatter
matrices, so the work grows with the number of pairs, not with the square of the block.
Small blocks solve them by a Cholesky factorisation batched over trials; from
``SPARSE_FROM_MODELS`` models up (the engine's size rule, :mod:`sim.lsq.size`: 400 reduced
unknowns) by the sparse ``L D L'`` of :mod:`sim.lsq.sparse_batch` (models ordered by minimum
degree once, every trial factorised on the one pattern in a compiled pass), so a block of
hundreds of models costs about its factor's work.

**Data snooping**: :mod:`sim.instruments.block.data_snooping`.

Units: metres for ground and model coordinates; image coordinates in mm, errors in um.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim import lsq
from sim.instruments.block.pointing import (
    form_models,
    noisy_models,
    pointing_errors,
    random_similarities,
    to_model_frame,
)
from sim.instruments.geometry import similarity_fit
from sim.lsq.groups import chol_solve
from sim.lsq.size import SPARSE_MIN_UNKNOWNS

__all__ = [
    "rodrigues",
    "form_models",
    "random_similarities",
    "to_model_frame",
    "noisy_models",
    "BlockStructure",
    "AdjustResult",
    "adjust_block",
    "normal_step",
    "chol_solve",
    "pointing_errors",
    "initial_values",
    "point_cofactors",
    "SPARSE_FROM_MODELS",
]


# --------------------------------------------------------------------------- similarity
def _skew(v: np.ndarray) -> np.ndarray:
    z = np.zeros_like(v[..., 0])
    return np.stack(
        [
            np.stack([z, -v[..., 2], v[..., 1]], -1),
            np.stack([v[..., 2], z, -v[..., 0]], -1),
            np.stack([-v[..., 1], v[..., 0], z], -1),
        ],
        -2,
    )


def rodrigues(theta: np.ndarray) -> np.ndarray:
    """Rotation matrix ``(..., 3, 3)`` of the rotation vector ``theta`` ``(..., 3)``."""
    a = np.linalg.norm(theta, axis=-1)[..., None, None]
    K = _skew(theta)
    small = a < 1e-12
    a_ = np.where(small, 1.0, a)
    s = np.where(small, 1.0, np.sin(a_) / a_)
    c = np.where(small, 0.5, (1 - np.cos(a_)) / a_**2)
    return np.eye(3) + s * K + c * (K @ K)


def initial_values(st: "BlockStructure", xm: np.ndarray, X_approx: np.ndarray):
    """Starting similarities ``(s, R, t)`` per model by a closed-form fit of its model points
    to approximate ground coordinates ``X_approx`` (T, P, 3) (one fit per model)."""
    T = xm.shape[0]
    M = st.n_models
    s = np.empty((T, M))
    R = np.empty((T, M, 3, 3))
    t = np.empty((T, M, 3))
    for m in range(M):  # a handful of models, each fit batched over trials
        k = st.obs_model == m
        f = similarity_fit(xm[:, k], X_approx[:, st.obs_point[k]])
        s[:, m], R[:, m], t[:, m] = f.scale, f.R, f.t
    return s, R, t


# ------------------------------------------------------------------- the adjustment
#: from this many models up the reduced normals (7 unknowns a model) take the sparse path
SPARSE_FROM_MODELS = -(-SPARSE_MIN_UNKNOWNS // 7)


class BlockStructure(lsq.GroupStructure):
    """Which model observes which point (:class:`sim.lsq.groups.GroupStructure` with the
    models as groups): obs_model, obs_point : (K,); ctrl_point : (C,); n_models, n_points."""

    def __init__(self, obs_model, obs_point, ctrl_point, n_models: int, n_points: int):
        super().__init__(
            obs_model, obs_point, ctrl_point, n_models, n_points, sparse_from=SPARSE_FROM_MODELS
        )

    obs_model = property(lambda self: self.obs_group)
    ctrl_point = property(lambda self: self.point_rows)
    n_models = property(lambda self: self.n_groups)
    S_model = property(lambda self: self.S_group)


class SimilarityModel:
    """Observation model of the independent-model block for :mod:`sim.lsq` (group blocks).

    Points: ground ``X_j`` (d = 3). Groups: per model the corrections ``(dl, dtheta, dt)``
    of ``s <- s (1 + dl)``, ``R <- R(dtheta) R``, ``t' <- t' + dt`` (b = 7); the state
    ``theta`` (T, M, 13) holds ``s``, ``R`` (9) and ``t' = t + s R c``. Rows: model points
    ``x_mj - [s R (x_mj - c_m) + t'_m - X_j]`` (weights w_obs) and control
    ``X_j^control - X_j`` (weights w_ctrl); metres.
    """

    point_dim = 3

    def __init__(self, st: BlockStructure, xm, c, w_obs, ctrl_xyz, w_ctrl, solver="auto"):
        self.structure, self.xm, self.c, self.solver = st, xm, c, solver
        T, K = xm.shape[:2]
        self.w = np.broadcast_to(w_obs, (T, K, 3))
        self.ctrl = np.broadcast_to(ctrl_xyz, (T,) + np.shape(ctrl_xyz)[-2:])
        self.wc = np.broadcast_to(w_ctrl, self.ctrl.shape)
        self.n_global = 7 * st.n_models

    def linearize(self, X, theta, globals_needed=True) -> lsq.GroupLinearization:
        st = self.structure
        om, op = st.obs_model, st.obs_point
        T, C = X.shape[0], st.ctrl_point.size
        s, R, t = theta[..., 0], theta[..., 1:10].reshape(theta.shape[:2] + (3, 3)), theta[..., 10:]
        d = self.xm - self.c[:, om]
        Rk = R[:, om]  # y = s R (x - c), unrolled
        y = s[:, om, None] * (
            Rk[..., 0] * d[..., 0, None]
            + Rk[..., 1] * d[..., 1, None]
            + Rk[..., 2] * d[..., 2, None]
        )
        e = y + t[:, om] - X[:, op]
        K = y.shape[1]
        J = np.zeros((T, K, 3, 7))
        J[..., 0] = y
        J[..., 0, 2] = y[..., 2]  # -skew(y): d(R y) / dtheta
        J[..., 0, 3] = -y[..., 1]
        J[..., 1, 1] = -y[..., 2]
        J[..., 1, 3] = y[..., 0]
        J[..., 2, 1] = y[..., 1]
        J[..., 2, 2] = -y[..., 0]
        J[..., 0, 4] = J[..., 1, 5] = J[..., 2, 6] = 1.0
        return lsq.GroupLinearization(
            -e,
            np.broadcast_to(-np.eye(3), (T, K, 3, 3)),
            J,
            self.w,
            self.ctrl - X[:, st.ctrl_point],
            np.broadcast_to(np.eye(3), (T, C, 3, 3)),
            self.wc,
        )

    def take(self, idx: np.ndarray) -> "SimilarityModel":
        """The same model on the trials ``idx`` only (the loop's active trials)."""
        return SimilarityModel(
            self.structure,
            self.xm[idx],
            self.c[idx],
            self.w[idx],
            self.ctrl[idx],
            self.wc[idx],
            self.solver,
        )

    def retract(self, X, theta, dX, dg):
        T, M = theta.shape[:2]
        dg = dg.reshape(T, M, 7)
        R = rodrigues(dg[..., 1:4]) @ theta[..., 1:10].reshape(T, M, 3, 3)
        return X + dX, np.concatenate(
            [
                theta[..., :1] * (1.0 + dg[..., :1]),
                R.reshape(T, M, 9),
                theta[..., 10:] + dg[..., 4:7],
            ],
            -1,
        )


def _state(s, R, t):
    return np.concatenate(
        [np.asarray(s, float)[..., None], np.asarray(R, float).reshape(np.shape(s) + (9,)), t], -1
    )


def normal_step(
    st: BlockStructure,
    xm,
    c,
    s,
    R,
    t,
    X,
    w_obs,
    ctrl_xyz,
    w_ctrl,
    dense=False,
    solver: str = "auto",
):
    """One Gauss-Newton correction ``(dg (T, M, 7), dX (T, P, 3))`` at ``(s, R, t' = t)``.

    The engine's group-block step (:func:`sim.lsq.groups.step`: dense below
    ``SPARSE_FROM_MODELS`` models, sparse from there, or as ``solver`` says: ``dense``,
    ``sparse``, ``band``). ``dense=True``
    instead builds and solves the full normal matrix of all ``7M + 3P`` unknowns (for
    checking the reduced solution on small blocks).
    """
    T = xm.shape[0]
    M, P = st.n_models, st.n_points
    model = SimilarityModel(st, xm, c, w_obs, ctrl_xyz, w_ctrl, solver)
    lin = model.linearize(np.asarray(X, float), _state(s, R, t))
    if dense:
        K, C = st.obs_model.size, st.ctrl_point.size
        A = np.zeros((T, 3 * K + 3 * C, 7 * M + 3 * P))
        for k in range(K):  # test-only dense assembly
            A[:, 3 * k : 3 * k + 3, 7 * st.obs_model[k] : 7 * st.obs_model[k] + 7] = lin.Jg[:, k]
            A[:, 3 * k : 3 * k + 3, 7 * M + 3 * st.obs_point[k] + np.arange(3)] = -np.eye(3)
        for i, j in enumerate(st.ctrl_point):
            A[:, 3 * K + 3 * i + np.arange(3), 7 * M + 3 * j + np.arange(3)] = 1.0
        w = np.concatenate([lin.w.reshape(T, -1), lin.wc.reshape(T, -1)], 1)
        r = np.concatenate([lin.r.reshape(T, -1), lin.rc.reshape(T, -1)], 1)
        N = np.einsum("toi,to,toj->tij", A, w, A)
        d = chol_solve(N, np.einsum("toi,to->ti", A, w * r)[..., None])[..., 0]
        return d[:, : 7 * M].reshape(T, M, 7), d[:, 7 * M :].reshape(T, P, 3)
    dX, dg, _ = lsq.groups.step(st, lin, solver)
    return dg.reshape(T, M, 7), dX


@dataclass
class AdjustResult:
    """Result of :func:`adjust_block` (leading axis: trials).

    s (T, M), R (T, M, 3, 3), t (T, M, 3): ground = s R x + t for each model;
    X (T, P, 3) adjusted points; v_obs (T, K, 3) model-point residuals (ground units,
    adjusted minus observed); v_ctrl (T, C, 3) control residuals (adjusted minus given);
    sigma0 (T,) a-posteriori standard error of unit weight; dof (T,); iterations (the most
    any trial used); converged (T,) bool; status (T,) the engine's status codes; engine: the
    :class:`sim.lsq.Result` (its cofactors serve
    :func:`sim.instruments.block.data_snooping.residual_cofactors`); J (T, K, 3, 7)
    the Jacobian of the model points w.r.t. the corrections (``keep_normals``).
    """

    s: np.ndarray
    R: np.ndarray
    t: np.ndarray
    X: np.ndarray
    v_obs: np.ndarray
    v_ctrl: np.ndarray
    sigma0: np.ndarray
    dof: np.ndarray
    iterations: int
    converged: np.ndarray
    status: np.ndarray | None = None
    engine: lsq.Result | None = None
    J: np.ndarray | None = None


def adjust_block(
    st: BlockStructure,
    xm: np.ndarray,
    w_obs: np.ndarray,
    ctrl_xyz: np.ndarray,
    w_ctrl: np.ndarray,
    s0,
    R0,
    t0,
    X0,
    *,
    tol_m: float = 1e-5,
    max_iter: int = 20,
    keep_normals: bool = False,
    solver: str = "auto",
) -> AdjustResult:
    """Batched least-squares block adjustment of independent models, by the engine's
    Gauss-Newton loop (:func:`sim.lsq.gauss_newton`, group blocks).

    xm : (T, K, 3) model coordinates of observation ``k`` (model ``st.obs_model[k]``, point
    ``st.obs_point[k]``); w_obs : (T, K, 3) or (K, 3) weights (0 removes an observation);
    ctrl_xyz : (T, C, 3) given control coordinates; w_ctrl : (C, 3) weights.
    s0, R0, t0 : initial similarities (ground = s R x + t), X0 : (T, P, 3) initial points.
    A trial stops when its largest point or translation correction (m) is below ``tol_m``
    (or the engine's contraction estimate of the remaining error is). ``solver``: see
    :func:`normal_step`. ``keep_normals`` also keeps the Jacobian ``J``.
    """
    T, K = xm.shape[:2]
    w_obs = np.broadcast_to(w_obs, (T, K, 3)).astype(float)
    w_ctrl = np.broadcast_to(w_ctrl, (T,) + np.shape(w_ctrl)[-2:]).astype(float)
    wsum = lsq.groups.scatter(st.S_model, (w_obs.sum(-1) > 0).astype(float)[..., None])
    c = lsq.groups.scatter(st.S_model, xm * (w_obs.sum(-1, keepdims=True) > 0)) / np.maximum(
        wsum, 1
    )
    s = np.array(s0, float)
    R = np.array(R0, float)
    # work with t' = t + s R c (the ground position of the model centroid)
    t = np.array(t0, float) + s[..., None] * np.einsum("tmij,tmj->tmi", R, c)
    model = SimilarityModel(st, xm, c, w_obs, ctrl_xyz, w_ctrl, solver)
    scale = np.tile([np.inf] * 4 + [1.0] * 3, st.n_models)  # the test: points, translations
    res = lsq.gauss_newton(
        model, _state(s, R, t), np.array(X0, float), tol=tol_m, max_iter=max_iter, step_scale=scale
    )
    th = res.theta
    s, R = th[..., 0], th[..., 1:10].reshape(T, -1, 3, 3)
    t_out = th[..., 10:] - s[..., None] * np.einsum("tmij,tmj->tmi", R, c)
    J = model.linearize(res.points, th).Jg if keep_normals else None
    return AdjustResult(
        s,
        R,
        t_out,
        res.points,
        -res.residuals,
        -res.point_residuals,
        res.sigma0,
        res.dof,
        int(res.iterations.max()),
        res.converged,
        res.status,
        res,
        J,
    )


def point_cofactors(st: BlockStructure, res: AdjustResult) -> np.ndarray:
    """Diagonal cofactors of the adjusted points ``(T, P, 3)``; times the variance of unit
    weight they are the variances of the ground coordinates."""
    return np.einsum("tpii->tpi", res.engine.point_cofactors())
