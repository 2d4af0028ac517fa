"""Block adjustment of independent stereomodels in 3-D, batched over Monte-Carlo trials.

Seed: ``003_5ce730a990a7ebc5.txt`` (Agnard, Nolette & Gagnon): a block of two strips of
eight models adjusted by independent models (the program SPACE-M of J. A. R. Blais), a
7-parameter similarity per model, pass points tying models and strips, control weighted
3 (planimetry) and 2 (height) against 0.1 on pass points; a first pass with 0.1 on control
and 1.0 on pass points; digital pugging (the pass point keeps the very same image
coordinates on the photo two models share) against mechanical pugging (re-centred).

**Stereomodel formation** (:func:`form_models`). Normal-case photography and a known
relative orientation: the model follows from the measured image coordinates by the
parallax equations ``X = x' B / p``, ``Y = (y' + y'') B / (2 p)``, ``Z = -f B / p`` with
``p = x' - x''``. The relative orientation is not re-estimated: the point errors reach the
model through the exact intersection, including the height amplification ``H / B`` and
the correlation of pass points shared by two models; the part of an image error a relative
orientation would absorb (y-parallax) is not removed, which makes the model slightly
pessimistic. Each model is then expressed in its own arbitrary frame by a random
similarity (:func:`random_similarities`), which the block adjustment has to recover.

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
``SPARSE_FROM_MODELS`` models up the models are reordered to a narrow band and eliminated
block by block, still batched over trials (:mod:`sim.lsq.group_solve`), so a block of
hundreds of models costs little more than its number of model pairs.

**Data snooping**: :mod:`sim.instruments.block.data_snooping`.

Units: metres for ground and model coordinates; image coordinates in mm, errors in um.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim import lsq
from sim.instruments.geometry import rotation, similarity_fit
from sim.lsq.groups import chol_solve

__all__ = [
    "rodrigues",
    "form_models",
    "random_similarities",
    "to_model_frame",
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


# ------------------------------------------------------------------ model simulation
def form_models(xl_mm: np.ndarray, xr_mm: np.ndarray, focal_mm: float, base_m: float) -> np.ndarray:
    """Model coordinates (m, origin at the left projection centre, ground-parallel axes)
    from measured image coordinates of the left and right photo, ``(..., 2)`` each, by the
    parallax equations of normal-case photography. Returns ``(..., 3)``."""
    p = xl_mm[..., 0] - xr_mm[..., 0]
    k = base_m / p
    return np.stack(
        [xl_mm[..., 0] * k, 0.5 * (xl_mm[..., 1] + xr_mm[..., 1]) * k, -focal_mm * k], -1
    )


def random_similarities(
    rng: np.random.Generator,
    shape: tuple,
    *,
    tilt_rad: float = 0.02,
    scale_range: tuple[float, float] = (0.5, 2.0),
    shift_m: float = 1000.0,
):
    """Arbitrary model frames: ``(s, R, t)`` with any heading, small tilts, a scale and a
    shift, shapes ``shape``, ``shape + (3, 3)``, ``shape + (3,)``."""
    om = rng.normal(0.0, tilt_rad, shape)
    ph = rng.normal(0.0, tilt_rad, shape)
    ka = rng.uniform(-np.pi, np.pi, shape)
    s = np.exp(rng.uniform(np.log(scale_range[0]), np.log(scale_range[1]), shape))
    t = rng.normal(0.0, shift_m, shape + (3,))
    return s, rotation(om, ph, ka), t


def to_model_frame(ground_xyz: np.ndarray, obs_model: np.ndarray, s, R, t) -> np.ndarray:
    """Express ground-frame model points ``(T, K, 3)`` in the frames of their models:
    ``x = R^T (X - t) / s`` with ``s (T, M)``, ``R (T, M, 3, 3)``, ``t (T, M, 3)``."""
    d = ground_xyz - t[:, obs_model]
    return np.einsum("tkji,tkj->tki", R[:, obs_model], d) / s[:, obs_model, None]


def noisy_models(block, rng: np.random.Generator, trials: int, sigma_m=0.0):
    """Model coordinates of every observation of ``block`` (:mod:`sim.instruments.block.layout`) in
    random model frames, for checks of the adjustment: each model point formed from its
    error-free image coordinates, shifted to the ground frame, plus Gaussian errors of
    ``sigma_m`` (m; a scalar or one per axis), then expressed in frames of
    :func:`random_similarities`. Returns ``xm (T, K, 3)`` and the frames ``(s, R, t)``."""
    xl = block.image_coords(block.obs_left, block.obs_point)
    xr = block.image_coords(block.obs_right, block.obs_point)
    G = (
        form_models(xl, xr, block.focal_mm, block.base_m)
        + block.photos.reshape(-1, 3)[block.obs_left]
    )
    G = G + rng.normal(0.0, 1.0, (trials,) + G.shape) * np.asarray(sigma_m, float)
    s, R, t = random_similarities(rng, (trials, block.n_models))
    return to_model_frame(G, block.obs_model, s, R, t), (s, R, t)


def pointing_errors(
    rng: np.random.Generator,
    trials: int,
    obs_left: np.ndarray,
    obs_right: np.ndarray,
    obs_point: np.ndarray,
    photos_per_strip: int,
    n_strips: int,
    n_points: int,
    *,
    mark_um: float,
    parallax_um: float,
    digital: np.ndarray | None = None,
    mechanical: np.ndarray | None = None,
    transfer_um: float = 0.0,
    recentre_um: float = 0.0,
    gross_rate: float = 0.0,
    gross_um: tuple[float, float] = (0.0, 0.0),
):
    """Image-measurement errors (um) on the left and right photo of every model point.

    Observation ``k`` (a point in a model) is measured on the flat photo indices
    ``obs_left[k]`` and ``obs_right[k]`` (``strip * photos_per_strip + i``). Errors are image
    shifts; in normal-case photography a shift of the pointed ground detail moves its image
    by the same vector on every photo.

    * Signalised points (default): re-pointed in every model. A setting error common to both
      photos, N(0, ``mark_um``) per coordinate, plus a stereo (parallax) setting error:
      N(0, ``parallax_um / sqrt(2)``) on each photo, so the x-parallax error has sigma
      ``parallax_um``.
    * Digital pugging (``digital`` (P,) True): the pixel marked on a photo is stored and
      reused, so a photo shared by two models has the very same image coordinates in both;
      the next photo of the strip is pointed stereoscopically to the stored pixel with a
      parallax error N(0, ``parallax_um``). Along a strip the errors are a random walk over
      the photos that see the point, starting from a setting error N(0, ``mark_um``); across
      strips the point is marked afresh.
    * Mechanical pugging (``mechanical`` (P,) True): a hole drilled on each photo (transfer
      error N(0, ``transfer_um``) per photo, shared by the models using the photo),
      re-centred in every model (N(0, ``recentre_um``) per photo and measurement); with
      probability ``gross_rate`` per model point the hole is missed on one of the two photos
      (white area, poor contrast of the scan) by a distance uniform in ``gross_um``.

    Returns ``(e_left, e_right, gross)``: (T, K, 2), (T, K, 2) and (T, K) bool.
    """
    K = obs_point.size
    T = trials
    mu = rng.normal(0.0, mark_um, (T, K, 1, 2))
    e = mu + rng.normal(0.0, parallax_um / np.sqrt(2.0), (T, K, 2, 2))
    gross = np.zeros((T, K), bool)
    S, F, P = n_strips, photos_per_strip, n_points
    strip = obs_left // F
    if digital is not None and np.any(digital):
        dk = np.asarray(digital, bool)[obs_point]
        first = np.full((S, P), F, np.intp)
        np.minimum.at(first, (strip[dk], obs_point[dk]), obs_left[dk] % F)
        walk = np.cumsum(rng.normal(0.0, parallax_um, (T, S, F, P, 2)), axis=2)
        mark = rng.normal(0.0, mark_um, (T, S, P, 2))
        sk, pk = strip[dk], obs_point[dk]
        start = mark[:, sk, pk] - walk[:, sk, first[sk, pk], pk]
        e[:, dk, 0] = start + walk[:, sk, obs_left[dk] % F, pk]
        e[:, dk, 1] = start + walk[:, sk, obs_right[dk] % F, pk]
    if mechanical is not None and np.any(mechanical):
        mk = np.asarray(mechanical, bool)[obs_point]
        n = int(mk.sum())
        hole = rng.normal(0.0, transfer_um, (T, S * F, P, 2))
        rec = rng.normal(0.0, recentre_um, (T, n, 2, 2))
        hit = rng.random((T, n)) < gross_rate
        side = rng.integers(0, 2, (T, n))
        ang = rng.uniform(0, 2 * np.pi, (T, n))
        mag = rng.uniform(gross_um[0], gross_um[1], (T, n)) * hit
        g = np.stack([mag * np.cos(ang), mag * np.sin(ang)], -1)  # (T, n, 2)
        for c, hole_photo in ((0, obs_left[mk]), (1, obs_right[mk])):
            e[:, mk, c] = (
                hole[:, hole_photo, obs_point[mk]]
                + rec[:, :, c]
                + np.where((side == c)[..., None], g, 0.0)
            )
        gross[:, mk] = hit
    return e[:, :, 0], e[:, :, 1], gross


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
#: from this many models up the reduced normals are solved by the banded elimination
SPARSE_FROM_MODELS = 60


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
    ``SPARSE_FROM_MODELS`` models, sparse above, or as ``solver`` says). ``dense=True``
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
