"""Brown's multilateration with P plate positions: batched adjustment in any station datum.

Seed: ``004_f5bd9e86c308241f.txt`` (Brown 1968). Measuring the plate in ``P`` positions
rotated about one pivot is geometrically the same as measuring it from ``P`` stations on a
circle of radius ``h`` about the plate centre (the pivot seen from the plate). Brown used
``P = 4``; :mod:`sim.instruments.ranges.multilateration` implements that case in Brown's datum. This module
generalises it to any ``P >= 3`` with the same observation equation

    (r_kj + alpha)^2 + beta^2 = (x_j - X_k)^2 + (y_j - Y_k)^2

and the same reduced-normal (EMBET) elimination of the 2x2 point blocks: the largest solve
per trial is ``(p + d) x (p + d)`` with ``p = 2P`` (+2 for ``alpha``, ``b = beta^2``) and
``d = 3`` datum constraints, and the cost grows linearly with the number of points.

Global vector ``theta`` ``(T, 2P + 2)``: ``X_1, Y_1, ..., X_P, Y_P, alpha, b`` (mm, mm^2).
Models: ``known`` (nothing free), ``stations`` (the 2P station coordinates free), ``pivot``
(also ``alpha`` and ``b``). The free network has a datum defect of 3 (two translations and a
rotation of stations and points together; the ranges fix the scale). The datum is imposed by
three linear constraints ``C^T d theta = 0`` on the corrections (bordered normal equations):

* ``brown`` (P = 4 only): ``X_1 = X_3 = 0``, ``Y_4 = -Y_2``, Brown's choice;
* ``inner``: inner constraints over the station coordinates (no mean translation or rotation
  of the stations with respect to their approximate values).

Any other datum, in particular one over the measured points, follows from
:mod:`sim.lsq.datum` (S-transformation). Units: mm.
"""

from __future__ import annotations

import numpy as np

from sim import lsq
from sim.lsq.normals import Reduced, reduce_blocks

__all__ = [
    "MODELS",
    "DATUMS",
    "circle_stations",
    "design_theta",
    "stations",
    "ranges",
    "n_free",
    "initial_points",
    "adjust",
    "covariance",
    "full_point_covariance",
    "from_brown_theta",
    "RangeModel",
    "arm_angles",
    "datum_constraints",
]

MODELS = ("known", "stations", "pivot")
DATUMS = ("brown", "inner")


def n_free(P: int, model: str) -> int:
    """Number of free globals of ``model`` with ``P`` stations."""
    return {"known": 0, "stations": 2 * P, "pivot": 2 * P + 2}[model]


def circle_stations(P: int, h_mm: float) -> np.ndarray:
    """``P`` stations equally spaced on a circle of radius ``h_mm`` about the plate centre,
    station 1 on the +y axis, numbered clockwise (for P = 4: top, right, bottom, left as in
    Brown's Figure 1). Shape ``(P, 2)``."""
    ang = np.pi / 2 - 2 * np.pi * np.arange(P) / P
    return h_mm * np.column_stack([np.cos(ang), np.sin(ang)])


def design_theta(P: int, h_mm: float, alpha_mm: float = 0.0, beta_mm: float = 0.0) -> np.ndarray:
    """Global parameters of the ideal comparator with ``P`` positions, shape ``(2P + 2,)``."""
    S = circle_stations(P, h_mm)
    S[np.abs(S) < 1e-12 * h_mm] = 0.0
    return np.concatenate([S.ravel(), [alpha_mm, beta_mm**2]])


def from_brown_theta(theta7: np.ndarray) -> np.ndarray:
    """Convert :mod:`sim.instruments.ranges.multilateration`'s 7-vector (Brown's datum) to the P = 4 layout."""
    y1, x2, y2, y3, x4, a, b = (theta7[..., i] for i in range(7))
    z = np.zeros_like(y1)
    return np.stack([z, y1, x2, y2, z, y3, x4, -y2, a, b], -1)


def stations(theta: np.ndarray) -> np.ndarray:
    """Station coordinates ``(..., P, 2)`` from ``theta`` ``(..., 2P + 2)``."""
    P = (theta.shape[-1] - 2) // 2
    return theta[..., : 2 * P].reshape(theta.shape[:-1] + (P, 2))


def ranges(points: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Scale readings ``r = sqrt(d^2 - b) - alpha`` (mm), shape ``(T, n, P)``."""
    d = points[:, :, None, :] - stations(theta)[:, None, :, :]
    q = np.sqrt(np.maximum(np.einsum("tnkc,tnkc->tnk", d, d) - theta[:, None, None, -1], 1e-300))
    return q - theta[:, None, None, -2]


def arm_angles(points: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Direction of the measuring arm (station -> point) in the *comparator* frame, radians,
    ``(T, n, P)``: the plate-frame direction minus the rotation of plate position ``k``
    (``2 pi k / P``, the plate turned so that station ``k`` comes to the pivot)."""
    d = points[:, :, None, :] - stations(theta)[:, None, :, :]
    P = d.shape[2]
    return np.arctan2(d[..., 1], d[..., 0]) + 2 * np.pi * np.arange(P) / P


def initial_points(r_obs: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Closed-form linear multilateration (differences of squared range equations)."""
    S = stations(theta)
    D2 = (r_obs + theta[:, None, None, -2]) ** 2 + theta[:, None, None, -1]
    A = -2.0 * (S[:, 1:, :] - S[:, :1, :])
    s2 = np.einsum("tkc,tkc->tk", S, S)
    rhs = D2[:, :, 1:] - D2[:, :, :1] - (s2[:, None, 1:] - s2[:, None, :1])
    N = np.einsum("tki,tkj->tij", A, A)
    u = np.einsum("tki,tnk->tni", A, rhs)
    return np.einsum("tij,tnj->tni", np.linalg.inv(N), u)


def datum_constraints(theta: np.ndarray, p: int, datum: str) -> np.ndarray:
    """Constraint matrix ``C`` ``(T, p, 3)`` of the station datum (``C^T d theta = 0``)."""
    T = theta.shape[0]
    P = (theta.shape[1] - 2) // 2
    C = np.zeros((T, p, 3))
    if datum == "brown":
        if P != 4:
            raise ValueError("the 'brown' datum needs exactly 4 stations")
        C[:, 0, 0] = 1.0  # X_1 = 0
        C[:, 4, 1] = 1.0  # X_3 = 0
        C[:, 3, 2] = 1.0  # Y_2 + Y_4 = 0
        C[:, 7, 2] = 1.0
    elif datum == "inner":
        S = stations(theta)
        c = S - S.mean(axis=1, keepdims=True)
        C[:, 0 : 2 * P : 2, 0] = 1.0
        C[:, 1 : 2 * P : 2, 1] = 1.0
        C[:, 0 : 2 * P : 2, 2] = -c[..., 1]
        C[:, 1 : 2 * P : 2, 2] = c[..., 0]
    else:
        raise ValueError(f"datum must be one of {', '.join(DATUMS)}, not {datum!r}")
    return C


class RangeModel:
    """Observation model of the ranges for :mod:`sim.lsq`: one point block ``(x_j, y_j)`` per
    point, ``P`` readings per point (one per station), misclosure ``r_obs - (q - alpha)``
    with ``q = sqrt(d^2 - b)``.

    r_obs : (T, n, P) mm (None: zero misclosures, for cofactors only); layout : None (the
    globals are ``X_1, Y_1, ..., X_P, Y_P, alpha, b``) or a constant matrix ``B``
    ``(2P + 2, q)`` mapping the model's own ``q`` globals to that vector (Brown's datum in
    :mod:`sim.instruments.ranges.multilateration`). ``P`` is taken from ``r_obs`` or from ``stations``.
    The engine takes the reduced normals from :meth:`reduced` (the sparse structure,
    :meth:`normal_blocks`); ``dense=True``
    makes it use the dense Jacobian of :meth:`linearize` instead (the same normals to
    rounding).
    """

    point_dim = 2

    def __init__(
        self,
        r_obs: np.ndarray | None,
        layout: np.ndarray | None = None,
        P: int | None = None,
        dense: bool = False,
    ):
        self.r_obs = None if r_obs is None else np.asarray(r_obs, float)
        self.layout = layout
        self.P = self.r_obs.shape[2] if P is None else P
        self.n_global = 2 * self.P + 2 if layout is None else layout.shape[1]
        if dense:  # the engine forms the normals from the dense Jacobian (the reference)
            self.reduced = None

    def full(self, theta: np.ndarray) -> np.ndarray:
        """The station/alpha/b vector ``(T, 2P + 2)`` of the globals."""
        return theta if self.layout is None else theta @ self.layout.T

    def initial_points(self, theta: np.ndarray) -> np.ndarray:
        return initial_points(self.r_obs, self.full(theta))

    def _ranges(self, points, theta):
        """``q = sqrt(d^2 - b)`` (T, n, P) mm, the unit vector ``(ux, uy)`` station -> point
        over ``q``, and the residual ``r = r_obs - (q - alpha)`` (zeros without readings)."""
        th = self.full(theta)
        S = stations(th)  # (T, P, 2)
        dx = points[:, :, None, 0] - S[:, None, :, 0]  # (T, n, P)
        dy = points[:, :, None, 1] - S[:, None, :, 1]
        q = np.sqrt(np.maximum(dx * dx + dy * dy - th[:, None, None, -1], 1e-300))
        r = np.zeros_like(q) if self.r_obs is None else self.r_obs - (q - th[:, None, None, -2])
        return q, dx / q, dy / q, r

    def linearize(self, points, theta, globals_needed=True) -> lsq.Linearization:
        q, ux, uy, r = self._ranges(points, theta)
        Jp = np.stack([ux, uy], -1)
        if not globals_needed:
            return lsq.Linearization(r, Jp, None)
        T, n, P = q.shape
        J = np.zeros((T, n, P, 2 * P + 2))
        k = np.arange(P)
        J[:, :, k, 2 * k] = -ux
        J[:, :, k, 2 * k + 1] = -uy
        J[..., 2 * P] = -1.0
        J[..., 2 * P + 1] = -0.5 / q
        return lsq.Linearization(r, Jp, J if self.layout is None else J @ self.layout)

    def reduced(self, points, theta, free, rcond: float = lsq.RCOND) -> Reduced:
        """Reduced normals of the free globals (for :mod:`sim.lsq`) without a Jacobian:
        :meth:`normal_blocks`, then :func:`~sim.lsq.normals.reduce_blocks`."""
        return reduce_blocks(*self.normal_blocks(points, theta, free), rcond=rcond)

    def normal_blocks(self, points, theta, free):
        """Normal-equation blocks of the free globals formed directly (for :mod:`sim.lsq`):
        the reading of station ``k`` at point ``j`` touches only ``x_j, y_j``, ``X_k, Y_k``,
        ``alpha`` and ``b``, so with ``u`` the unit vector station -> point and ``g = 1 / 2q``

            Npp_j = sum_k u u',  Npg_j = [-u_k u_k' (station k) | -sum_k u | -sum_k g u],
            Ngg = diag_k(sum_j u u') bordered by sum_j u, sum_j g u, n, sum g, sum g^2

        (the dense Jacobian ``(T, n, P, 2P + 2)`` is never built). Returns ``(Npp, up, Npg,
        Ngg, ug)`` for :func:`sim.lsq.normals.reduce_blocks`."""
        q, ux, uy, r = self._ranges(points, theta)
        xx, xy, yy = ux * ux, ux * uy, uy * uy
        T, n, P = q.shape
        on_k, on_j = np.ones(P), np.ones(n)  # sums over stations / points as products
        Npp = np.empty((T, n, 2, 2))
        Npp[..., 0, 0] = xx @ on_k
        Npp[..., 0, 1] = Npp[..., 1, 0] = xy @ on_k
        Npp[..., 1, 1] = yy @ on_k
        up = np.stack([(ux * r) @ on_k, (uy * r) @ on_k], -1)
        if len(free) == 0:
            return Npp, up, np.zeros((T, n, 2, 0)), np.zeros((T, 0, 0)), np.zeros((T, 0))
        g = 0.5 / q
        gx, gy = g * ux, g * uy
        q_all = 2 * P + 2
        Npg = np.empty((T, n, 2, q_all))
        Npg[:, :, 0, 0 : 2 * P : 2] = -xx
        Npg[:, :, 0, 1 : 2 * P : 2] = Npg[:, :, 1, 0 : 2 * P : 2] = -xy
        Npg[:, :, 1, 1 : 2 * P : 2] = -yy
        Npg[:, :, 0, 2 * P] = -(ux @ on_k)
        Npg[:, :, 1, 2 * P] = -(uy @ on_k)
        Npg[:, :, 0, 2 * P + 1] = -(gx @ on_k)
        Npg[:, :, 1, 2 * P + 1] = -(gy @ on_k)
        Ngg = np.zeros((T, q_all, q_all))
        k = np.arange(P)
        sx, sy = 2 * k, 2 * k + 1
        Ngg[:, sx, sx] = on_j @ xx
        Ngg[:, sx, sy] = Ngg[:, sy, sx] = on_j @ xy
        Ngg[:, sy, sy] = on_j @ yy
        for col, (ax, ay) in ((2 * P, (ux, uy)), (2 * P + 1, (gx, gy))):
            Ngg[:, sx, col] = Ngg[:, col, sx] = on_j @ ax
            Ngg[:, sy, col] = Ngg[:, col, sy] = on_j @ ay
        Ngg[:, 2 * P, 2 * P] = n * P
        Ngg[:, 2 * P, 2 * P + 1] = Ngg[:, 2 * P + 1, 2 * P] = g.sum(axis=(1, 2))
        Ngg[:, 2 * P + 1, 2 * P + 1] = (g * g).sum(axis=(1, 2))
        ug = np.empty((T, q_all))
        ug[:, 0 : 2 * P : 2] = -(on_j @ (ux * r))
        ug[:, 1 : 2 * P : 2] = -(on_j @ (uy * r))
        ug[:, 2 * P] = -r.sum(axis=(1, 2))
        ug[:, 2 * P + 1] = -(g * r).sum(axis=(1, 2))
        if self.layout is not None:  # the model's own globals: Jg = J_full L
            L = self.layout
            Npg, Ngg, ug = Npg @ L, L.T @ Ngg @ L, ug @ L
        return Npp, up, Npg[..., free], Ngg[:, free][:, :, free], ug[:, free]


def _datum(theta: np.ndarray, P: int, model: str, datum: str) -> lsq.Datum:
    p = n_free(P, model)
    if datum not in DATUMS:
        raise ValueError(f"datum must be one of {', '.join(DATUMS)}, not {datum!r}")
    return lsq.Datum(np.arange(p), datum_constraints(theta, p, datum) if p else None)


def adjust(
    r_obs: np.ndarray,
    model: str,
    theta0: np.ndarray,
    datum: str = "inner",
    tol_mm: float = 1e-10,
    max_iter: int = 30,
    rcond: float | None = None,
) -> lsq.Result:
    """Batched Gauss-Newton adjustment with ``P`` stations.

    r_obs : (T, n, P) mm. theta0 : (T, 2P+2) or (2P+2,) -- fixed values and starting values;
    for ``brown`` the start must satisfy Brown's datum (it is kept exactly). Solved by the
    engine :func:`sim.lsq.gauss_newton` (``rcond``: its scaled singularity threshold, default
    :data:`sim.lsq.RCOND`); returns :class:`sim.lsq.Result` (status 0 converged,
    1 not converged, 2 singular, 3 non-finite).
    """
    if model not in MODELS:
        raise ValueError(f"model must be one of {', '.join(MODELS)}, not {model!r}")
    r_obs = np.asarray(r_obs, float)
    T, n, P = r_obs.shape
    if P < 3:
        raise ValueError("at least 3 stations (plate positions) are needed")
    p = n_free(P, model)
    dof = P * n - 2 * n - p + (3 if p else 0)
    if dof < 0 or n < 3:
        raise ValueError(f"{n} points in {P} positions give {P * n} ranges for too many unknowns")
    theta = np.broadcast_to(np.asarray(theta0, float), (T, 2 * P + 2)).copy()
    rc = lsq.RCOND if rcond is None else rcond
    return lsq.gauss_newton(
        RangeModel(r_obs),
        theta,
        None,
        _datum(theta, P, model, datum),
        tol_mm,
        max_iter,
        rc,
        engine="numpy",
    )


def covariance(points: np.ndarray, theta: np.ndarray, model: str, datum: str = "inner"):
    """Cofactors (unit range variance) at ``points`` ``(T, n, 2)``, ``theta`` ``(T, 2P+2)``.

    Returns ``(Qpp (T,n,2,2), Qgg (T,p,p), K (T,n,2,p), Ninv (T,n,2,2))`` with
    ``Q(p_j, p_k) = delta_jk Ninv_j + K_j Qgg K_k^T`` and ``Q(p_j, g) = -K_j Qgg``, the
    station coordinates in the chosen ``datum`` (bordered inverse of the reduced normals).
    """
    P = (theta.shape[-1] - 2) // 2
    cof = lsq.cofactors(RangeModel(None, P=P), points, theta, _datum(theta, P, model, datum))
    return cof.points, cof.Qgg, cof.K, cof.Ninv


def full_point_covariance(
    points: np.ndarray, theta: np.ndarray, model: str, datum: str = "inner", dense: bool = False
) -> np.ndarray:
    """The full ``(T, 2n, 2n)`` cofactor of all point coordinates (x1, y1, x2, ...);
    ``dense``: normals from the dense Jacobian (:class:`RangeModel`)."""
    P = (theta.shape[-1] - 2) // 2
    return lsq.cofactors(
        RangeModel(None, P=P, dense=dense), points, theta, _datum(theta, P, model, datum)
    ).full_points
