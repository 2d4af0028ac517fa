"""A network made singular by its sigmas, not by its datum: the weakest unknown and the
reciprocal condition number of the normals scaled to unit diagonal (docs/network.md), under
the engine's limit :data:`sim.lsq.normals.RCOND`.

Under a fixed datum the normals are of full rank and that matrix is theirs. Under an inner
datum or minimal constraints the normals keep the network's datum defect, which the
constraints hold: the matrix is then the normals bordered by the constraints, as the engine
solves them (:mod:`sim.lsq.normals`). A network held so, with one sight of 1e-9 mm beside
sights of 1e-3 mm (each sigma within its bounds), was refused as "a rank defect of 3 ... that
the datum (3 constraints) does not cover", a defect the constraints did cover.
"""

from __future__ import annotations

import numpy as np

from sim.lsq.normals import RCOND, _scaled_system, scaled_rcond
from sim.mc.config import ConfigError

__all__ = ["unknown", "covered", "refuse_weights", "equilibrated"]


def unknown(net, par: int) -> str:
    """The unknown of column ``par`` for a message: a point's coordinate (``point 'P1' (x)``)
    or the name of a network parameter (a scale, a constant, an orientation)."""
    if par < 2 * net.n:
        return f"point {net.names[par // 2]!r} ({'xy'[par % 2]})"
    return net.parameter_names()[par - 2 * net.n]


def covered(B: np.ndarray, C: np.ndarray | None) -> bool:
    """Whether the constraints ``C`` (p, c) leave no defect of the equilibrated design ``B``
    (m, p): the stacked rows are of rank ``p`` at the same relative tolerance as ``B``'s own."""
    if C is None or C.shape[-1] == 0:
        return False
    with np.errstate(divide="ignore", invalid="ignore"):
        n = np.linalg.norm(C, axis=0)
        Cn = C / np.where(n > 0, n, 1.0)
    sv = np.linalg.svd(np.vstack([B, Cn.T]), compute_uv=False)
    return bool(sv.size) and int((sv > sv[0] * 1e-10).sum()) == B.shape[1]


def _rcond(A: np.ndarray, C) -> tuple[np.ndarray, float]:
    """The weakest direction (p,) of the design ``A`` (m, p), bordered by ``C`` (p, c) when
    given, and the reciprocal condition number of its (bordered) normals scaled to unit
    diagonal."""
    N = A.T @ A
    if C is None:
        return np.linalg.svd(A, full_matrices=False)[2][-1], float(scaled_rcond(N))
    M = _scaled_system(N[None], C[None])[0][0]
    w, V = np.linalg.eigh(M)
    return V[: A.shape[1], int(np.argmin(np.abs(w)))], float(scaled_rcond(M))


def refuse_weights(net, A: np.ndarray, free: np.ndarray, key: str, C=None) -> None:
    """Refuse the network whose weighted design ``A`` (m, p) has full rank, or whose defect
    the constraints ``C`` (p, c) hold, while the engine finds its (bordered) normals singular:
    name the weakest unknown and the reciprocal condition number of the scaled matrix. When
    the design with every row of unit weight is as near-singular, the geometry is the cause,
    not the sigmas (an estimated scale that only the distances' offset tells from the
    network's size), and the key that estimates that unknown is named where there is one."""
    v, rc = _rcond(A, C)
    g = int(free[int(np.argmax(np.abs(v)))])
    what = unknown(net, g)
    held = "" if C is None else " bordered by the datum's constraints"
    rc_eq = _rcond(equilibrated(A), C)[1]
    if rc_eq > RCOND:
        raise ConfigError(
            key,
            f"the network is near-singular from its weights: {what} is nearly undetermined "
            f"(the normal matrix{held} scaled to unit diagonal has a reciprocal condition "
            f"number of {rc:.2g}, under the engine's limit of {RCOND:g}, more than ten digits "
            "lost): bring the observations' sigmas closer together, or fix points",
        )
    pairs = (("network.estimate_constant", net.i_constant), ("network.estimate_scale", net.i_scale))
    raise ConfigError(
        next((k for k, i in pairs if i == g), key),
        f"the network is near-singular: {what} is nearly undetermined (the normal matrix{held} "
        f"scaled to unit diagonal has a reciprocal condition number of {rc:.2g}, and "
        f"{rc_eq:.2g} with every observation of one weight: its geometry, not its sigmas, "
        f"under the engine's limit of {RCOND:g}): estimate fewer quantities, or add "
        "observations of other lengths or directions",
    )


def equilibrated(A: np.ndarray) -> np.ndarray:
    """``A`` with unit rows, then unit columns (zero ones left zero): the same rank, without
    the spread of the weights. A sight of 1e-6 mm weighs 1e22 times a 100 m one; its rows
    pushed seven honest singular values below the relative tolerance, so a network of full
    rank held by four fixed points read as a rank defect of 12 the datum does not cover."""
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.linalg.norm(A, axis=1)
        B = A / np.where(r > 0, r, 1.0)[:, None]
        c = np.linalg.norm(B, axis=0)
        return B / np.where(c > 0, c, 1.0)
