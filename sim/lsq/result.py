"""The one result object of the engine and its cofactor accessors.

Cofactors are for unit weight: multiply by the variance of unit weight (a-priori ``sigma^2``
or the estimate ``sigma0^2``) for covariances. With the point blocks eliminated
(:mod:`sim.lsq.normals`) the full cofactor of the unknowns is

    Q(p_j, p_k) = delta_jk Ninv_j + K_j Qgg K_k',    Q(p_j, g) = -K_j Qgg,

``Qgg`` the bordered inverse of the reduced normals in the datum. Seed of the method: Brown
1968 (``004_f5bd9e86c308241f.txt``, "rigorous error propagation" of the EMBET solution).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from sim.lsq.groups import cofactors as group_cofactors
from sim.lsq.normals import RCOND, bordered_inverse, reduced_normals
from sim.lsq.problem import Datum

__all__ = ["STATUS", "Cofactors", "cofactors", "Result"]

#: per-trial status codes and their messages
STATUS = {
    0: "converged",
    1: "not converged within the iteration limit",
    2: "singular normal equations (scaled reciprocal condition below rcond)",
    3: "non-finite corrections (diverged or bad observations)",
}


@dataclass
class Cofactors:
    """Cofactor pieces at one linearisation point.

    Qgg : (T, p, p) free globals (NaN where singular); K : (T, n, d, p); Ninv : (T, n, d, d)
    the inverse point blocks; ok : (T,) regular.
    """

    Qgg: np.ndarray
    K: np.ndarray
    Ninv: np.ndarray
    ok: np.ndarray

    @property
    def points(self) -> np.ndarray:
        """Per-point cofactor blocks ``(T, n, d, d)``."""
        if self.Qgg.shape[-1] == 0:
            return self.Ninv
        KQ = np.einsum("tnip,tpq->tniq", self.K, self.Qgg)
        return self.Ninv + np.einsum("tniq,tnjq->tnij", KQ, self.K)

    @property
    def full_points(self) -> np.ndarray:
        """The full cofactor of all point unknowns ``(T, n d, n d)`` (x1, y1, x2, ...)."""
        T, n, d, p = self.K.shape
        Kf = self.K.reshape(T, n * d, p)
        Q = Kf @ self.Qgg @ Kf.transpose(0, 2, 1) if p else np.zeros((T, n * d, n * d))
        Qb = Q.reshape(T, n, d, n, d)
        idx = np.arange(n)
        Qb[:, idx, :, idx, :] += self.Ninv.transpose(1, 0, 2, 3)
        return Qb.reshape(T, n * d, n * d)

    @property
    def point_global(self) -> np.ndarray:
        """Cross cofactor ``Q(p_j, g) = -K_j Qgg`` ``(T, n, d, p)``."""
        return -np.einsum("tnip,tpq->tniq", self.K, self.Qgg)


def cofactors(
    model, points: np.ndarray, theta: np.ndarray, datum: Datum | None = None, rcond: float = RCOND
) -> Cofactors:
    """Cofactors of ``model`` at ``points`` (T, n, d), ``theta`` (T, q) in ``datum`` (a
    :class:`sim.lsq.groups.GroupCofactors` for group-block models)."""
    if getattr(model, "structure", None) is not None:  # group blocks
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            return group_cofactors(model.structure, model.linearize(points, theta), rcond)
    datum = Datum() if datum is None else datum
    free = datum.free_index(model.n_global)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        red = reduced_normals(model, points, theta, free, rcond)
        if len(free):
            Qgg, ok = bordered_inverse(red.Nbar, datum.constraint_matrix(theta), rcond)
            ok &= red.ok
            Qgg[~ok] = np.nan
        else:
            Qgg, ok = np.zeros((points.shape[0], 0, 0)), red.ok
    return Cofactors(Qgg, red.K, red.Ninv, ok)


@dataclass
class Result:
    """Result of :func:`sim.lsq.gauss_newton` (leading axis: trials).

    points : (T, n, d); theta : (T, q) (fixed entries unchanged); residuals : (T, n, k)
    observed minus adjusted; sigma0 : (T,) a-posteriori standard error of unit weight
    (``sqrt(v'Pv / dof)``, NaN for ``dof = 0``); dof : int (per trial (T,) for group-block
    models, whose zero weights remove observations); iterations : (T,) int;
    status : (T,) int8 (:data:`STATUS`); converged : (T,) bool. ``model`` and ``datum`` are
    kept for the cofactor accessors.
    """

    points: np.ndarray
    theta: np.ndarray
    residuals: np.ndarray
    sigma0: np.ndarray
    dof: int
    iterations: np.ndarray
    status: np.ndarray
    model: object = field(default=None, repr=False)
    datum: Datum | None = field(default=None, repr=False)
    _cof: Cofactors | None = field(default=None, repr=False)
    #: residuals of point-only rows (group-block models), else None
    point_residuals: np.ndarray | None = field(default=None, repr=False)

    @property
    def converged(self) -> np.ndarray:
        return self.status == 0

    @property
    def message(self) -> np.ndarray:
        """Per-trial message ``(T,)`` of strings."""
        return np.array([STATUS[int(s)] for s in self.status], dtype=object)

    def cofactors(self) -> Cofactors:
        """Cofactors at the solution (computed once)."""
        if self._cof is None:
            self._cof = cofactors(self.model, self.points, self.theta, self.datum)
        return self._cof

    def point_cofactors(self) -> np.ndarray:
        """Per-point cofactor blocks ``(T, n, d, d)``."""
        return self.cofactors().points

    def global_cofactor(self) -> np.ndarray:
        """Cofactor of the free globals ``(T, p, p)``."""
        return self.cofactors().Qgg

    def full_point_cofactor(self) -> np.ndarray:
        """Full cofactor of all point unknowns ``(T, n d, n d)``."""
        return self.cofactors().full_points
