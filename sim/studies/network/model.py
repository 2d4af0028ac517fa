"""The observation model of a declared network, on the one engine (:mod:`sim.lsq`).

All unknowns are globals (``point_dim = 0``): the coordinates of every point (x, y in mm), one
orientation per direction set (rad), the additive constant of distances (mm) and their scale
error (ppm); a distance reads ``(1 + s) sqrt(d^2 - beta^2) - alpha``; a network's
observations tie two or three points together, so there is no per-point block to eliminate.
Each observation is one row; weights are ``1 / sigma^2`` (sigma in mm or rad), so cofactors are
covariances. The datum (:func:`datum`) frees the estimated globals and adds fixed points,
inner constraints over chosen points, or a user's minimal constraints. Seed papers: Brown 1968
(``004``: ranges with the pivot offsets) and the grid plates of ``001`` (weighted coordinates).
"""

from __future__ import annotations

import numpy as np

from sim import lsq
from sim.lsq import sparse as lsq_sparse
from sim.lsq.size import SPARSE_MIN_UNKNOWNS
from sim.mc.config import ConfigError
from sim.mc.lookalike import alike, char_name
from sim.studies.network.definition import Network
from sim.studies.network.validate import hits, name_index

__all__ = [
    "NetworkModel",
    "computed",
    "jacobian_sparse",
    "pattern",
    "simulate",
    "datum",
    "null_space",
    "defect_basis",
    "weighted_design",
    "use_sparse",
    "SPARSE_MIN_UNKNOWNS",
]

_TWO_PI = 2 * np.pi


def _wrap(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % _TWO_PI - np.pi


def _terms(net: Network, theta: np.ndarray) -> dict:
    """The computed observations ``val`` (T, m) and the pieces of their derivatives."""
    T = theta.shape[0]
    xy = theta[:, : 2 * net.n].reshape(T, net.n, 2)
    kind, i, j, k = net.kind, net.i, net.j, net.k
    pi, pj = xy[:, i], xy[:, np.where(j >= 0, j, 0)]
    dx, dy = pj[..., 0] - pi[..., 0], pj[..., 1] - pi[..., 1]
    d2 = dx * dx + dy * dy
    beta2 = net.offset_mm**2
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.sqrt(np.maximum(d2 - beta2, 0.0))
        bear = np.arctan2(dy, dx)
    ori = theta[:, 2 * net.n + np.where(net.oset >= 0, net.oset, 0)] if len(net.stations) else 0.0
    alpha = theta[:, net.i_constant, None]
    f = 1.0 + 1e-6 * theta[:, net.i_scale, None]
    pk = xy[:, np.where(k >= 0, k, 0)]
    ex, ey = pk[..., 0] - pi[..., 0], pk[..., 1] - pi[..., 1]
    bear_k = np.arctan2(ey, ex)
    val = np.select(
        [kind == 0, kind == 1, kind == 2, kind == 3, kind == 4, kind == 5],
        [f * s - alpha, bear - ori, (bear_k - bear) % _TWO_PI, dx, dy, pi[..., 0]],
        pi[..., 1],
    )
    return {"val": val, "dx": dx, "dy": dy, "d2": d2, "s": s, "f": f, "ex": ex, "ey": ey}


def _derivatives(net: Network, t: dict) -> list[np.ndarray]:
    """Derivatives ``(T, m)`` by x_i, y_i, x_j, y_j, x_k, y_k (see :func:`computed`)."""
    kind = net.kind
    dx, dy, d2, s, f, ex, ey = (t[a] for a in ("dx", "dy", "d2", "s", "f", "ex", "ey"))
    with np.errstate(invalid="ignore", divide="ignore"):
        gx = np.select([kind == 0, kind == 1, kind == 2], [f * dx / s, -dy / d2, dy / d2], 0.0)
        gy = np.select([kind == 0, kind == 1, kind == 2], [f * dy / s, dx / d2, -dx / d2], 0.0)
        e2 = ex * ex + ey * ey
        hx, hy = np.where(kind == 2, -ey / e2, 0.0), np.where(kind == 2, ex / e2, 0.0)
    lin = kind <= 2
    # d/d(point j) = (gx, gy); d/d(point i) = -(gx + hx, gy + hy); d/d(point k) = (hx, hy)
    return [
        np.where(lin, -(gx + hx), np.select([kind == 3, kind == 5], [-1.0, 1.0], 0.0)),
        np.where(lin, -(gy + hy), np.select([kind == 4, kind == 6], [-1.0, 1.0], 0.0)),
        np.where(lin, gx, np.where(kind == 3, 1.0, 0.0)),
        np.where(lin, gy, np.where(kind == 4, 1.0, 0.0)),
        hx,
        hy,
    ]


def computed(net: Network, theta: np.ndarray, jac: bool = False):
    """Computed observations ``(T, m)`` at globals ``theta`` ``(T, q)`` and, with ``jac``,
    their Jacobian ``(T, m, q)`` (dense)."""
    t = _terms(net, theta)
    if not jac:
        return t["val"]
    T = theta.shape[0]
    i, j, k = net.i, net.j, net.k
    J = np.zeros((T, net.m, net.q + 1))  # the last column collects padding
    rows = np.arange(net.m)
    cx_i, cy_i = 2 * i, 2 * i + 1
    cx_j = np.where(j >= 0, 2 * j, net.q)
    cy_j = np.where(j >= 0, 2 * j + 1, net.q)
    cx_k = np.where(k >= 0, 2 * k, net.q)
    cy_k = np.where(k >= 0, 2 * k + 1, net.q)
    di, dyi, dj, dyj, hx, hy = _derivatives(net, t)
    J[:, rows, cx_j] = dj
    J[:, rows, cy_j] = dyj
    J[:, rows, cx_k] = hx
    J[:, rows, cy_k] = hy
    J[:, rows, cx_i] = di
    J[:, rows, cy_i] = dyi
    if len(net.stations):
        d = net.kind == 1
        J[:, rows[d], 2 * net.n + net.oset[d]] = -1.0
    dist = rows[net.kind == 0]
    J[:, dist, net.i_constant] = -1.0
    J[:, dist, net.i_scale] = 1e-6 * t["s"][:, net.kind == 0]
    return t["val"], J[..., : net.q]


def _slots(net: Network) -> np.ndarray:
    """The column of each of the nine slots of each row ``(m, 9)`` (-1: unused): x_i, y_i,
    x_j, y_j, x_k, y_k, orientation, constant, scale."""
    i, j, k, kind = net.i, net.j, net.k, net.kind
    pt = lambda a, c: np.where(a >= 0, 2 * a + c, -1)  # noqa: E731
    return np.stack(
        [
            np.where((kind == 4) | (kind == 6), -1, 2 * i),
            np.where((kind == 3) | (kind == 5), -1, 2 * i + 1),
            np.where(kind == 4, -1, pt(j, 0)),
            np.where(kind == 3, -1, pt(j, 1)),
            pt(k, 0),
            pt(k, 1),
            np.where(kind == 1, 2 * net.n + net.oset, -1),
            np.where(kind == 0, net.i_constant, -1),
            np.where(kind == 0, net.i_scale, -1),
        ],
        1,
    )


def pattern(net: Network) -> np.ndarray:
    """The Jacobian's pattern ``(m, s)``: the columns of the slots some row uses (see
    :func:`_slots`; -1 where a row does not use a slot)."""
    cols = _slots(net)
    return cols[:, (cols >= 0).any(0)]


def jacobian_sparse(net: Network, theta: np.ndarray):
    """Computed observations ``(T, m)`` and the Jacobian on :func:`pattern`'s slots
    ``(T, m, s)``: the same derivatives as :func:`computed`, without the dense array."""
    t = _terms(net, theta)
    T = theta.shape[0]
    kind = net.kind
    dist = (kind == 0)[None, :]
    full = _derivatives(net, t) + [
        np.broadcast_to(np.where(kind == 1, -1.0, 0.0), (T, net.m)),
        np.broadcast_to(np.where(dist, -1.0, 0.0), (T, net.m)),
        np.where(dist, 1e-6 * t["s"], 0.0),
    ]
    used = np.flatnonzero((_slots(net) >= 0).any(0))
    return t["val"], np.stack([full[a] for a in used], -1)


def simulate(net: Network, rng: np.random.Generator, T: int) -> np.ndarray:
    """``T`` sets of readings ``(T, m)``: true values plus bias plus Gaussian noise."""
    true = computed(net, net.theta_true()[None])
    return true + net.bias + net.sigma * rng.standard_normal((T, net.m))


class NetworkModel:
    """Engine model (:mod:`sim.lsq.problem`) of ``net`` with observations ``obs`` ``(T, m)``."""

    point_dim = 0

    def __init__(self, net: Network, obs: np.ndarray | None):
        self.net = net
        self.obs = obs
        self.n_global = net.q
        self.n_obs = net.m
        self.w = (1.0 / net.sigma**2)[None, :, None]

    def linearize(self, points, theta, globals_needed):
        val, J = computed(self.net, theta, jac=True)
        obs = val if self.obs is None else self.obs
        r = obs - val
        ang = (self.net.kind == 1) | (self.net.kind == 2)
        r = np.where(ang, _wrap(r), r)
        return lsq.Linearization(
            r[..., None], None, J[:, :, None, :] if globals_needed else None, self.w
        )

    def initial_points(self, theta):
        return np.zeros((theta.shape[0], self.net.m, 0))


def null_space(net: Network, free: np.ndarray) -> np.ndarray:
    """Candidate datum defects restricted to the free globals ``(p, 4)``: translation x, y,
    rotation and scale of every point (orientations turn with a rotation; an estimated scale
    error of the distances shrinks as the coordinates grow)."""
    return _similarity(net)[free]


def _similarity(net: Network) -> np.ndarray:
    c = net.xy - net.xy.mean(axis=0)
    G = np.zeros((net.q, 4))
    G[0 : 2 * net.n : 2, 0] = 1
    G[1 : 2 * net.n : 2, 1] = 1
    G[0 : 2 * net.n : 2, 2], G[1 : 2 * net.n : 2, 2] = -c[:, 1], c[:, 0]
    G[2 * net.n : 2 * net.n + len(net.stations), 2] = 1.0
    G[0 : 2 * net.n : 2, 3], G[1 : 2 * net.n : 2, 3] = c[:, 0], c[:, 1]
    G[net.i_scale, 3] = -(1e6 + net.scale_ppm)
    return G


# networks with at least SPARSE_MIN_UNKNOWNS unknowns take the sparse path (the engine's one
# size rule, sim.lsq.size; smaller ones the dense one, the reference of the tests)


def use_sparse(net: Network) -> bool:
    """Whether ``net`` is adjusted on the sparse path (:data:`SPARSE_MIN_UNKNOWNS`)."""
    return net.q >= SPARSE_MIN_UNKNOWNS


def weighted_design(net: Network, free: np.ndarray):
    """The weighted design ``A / sigma`` ``(m, p)`` at the true coordinates (sparse CSR)."""
    _, vals = jacobian_sparse(net, net.theta_true()[None])
    return lsq_sparse.design(pattern(net), vals[0], 1.0 / net.sigma**2, free, net.q)


def defect_basis(net: Network, free: np.ndarray) -> np.ndarray:
    """Orthonormal columns ``(p, d)`` spanning the datum defects of the design over the free
    globals ``free``: the similarity transformations (translation, rotation, scale) that
    leave every point held fixed in place and change no observation. With one fixed point
    these are the rotation (and scale) about it; with none, those about the centroid. A
    candidate is a defect where ``|A g| <= 1e-9 |A|_F`` for the weighted design ``A``: dense
    below :data:`SPARSE_MIN_UNKNOWNS` unknowns, sparse (:func:`weighted_design`) from there."""
    G = _similarity(net)
    held = np.setdiff1d(np.arange(2 * net.n), free)
    K = np.eye(4)
    if held.size:  # U of G[held] (2 x held points, squared) is never wanted: thin from 4 rows
        _, sv, vt = np.linalg.svd(G[held], full_matrices=held.size < G.shape[1])
        rank = int((sv > 1e-12 * max(sv.max(initial=0.0), 1.0)).sum())
        K = vt[rank:].T
    if K.shape[1] == 0:
        return np.zeros((len(free), 0))
    Q, _ = np.linalg.qr(G[free] @ K)
    if use_sparse(net):
        A = weighted_design(net, free)
        norm_a = float(np.sqrt(np.sum(A.data**2)))
    else:
        _, J = computed(net, net.theta_true()[None], jac=True)
        A = J[0][:, free] / net.sigma[:, None]
        norm_a = float(np.linalg.norm(A))
    B = A @ Q
    # U of B (m x m) is never wanted: the thin SVD, unless B has fewer rows than columns
    _, sv, vt = np.linalg.svd(B, full_matrices=B.shape[0] < B.shape[1])
    sv = np.concatenate([sv, np.zeros(Q.shape[1] - sv.size)])
    null = vt[sv <= 1e-9 * norm_a]
    return Q @ null.T


def _param_index(net: Network, key: str, name: str) -> int:
    """The index of ``name`` (``"P.x"``) among the globals; refused naming what is wrong: no
    axis, an axis that is not x or y (a Cyrillic у named), or no such point (the one that looks
    the same named: ``"\ufeffA.x"`` was "is not <point>.x or <point>.y", as was ``"A.у"``)."""
    pt, dot, ax = name.rpartition(".")
    if not dot:
        raise ConfigError(key, f"{name!r} is not <point>.x or <point>.y of a network point")
    if ax not in ("x", "y"):
        odd = next((f", {char_name(c)}" for c in ax if not c.isascii() or not c.isprintable()), "")
        raise ConfigError(
            key, f"{name!r}: the axis after its last dot must be x or y ({ax!r}{odd})"
        )
    try:
        return 2 * net.index(pt) + "xy".index(ax)
    except ValueError:
        raise ConfigError(
            key, f"{name!r}: {pt!r} is no point of the network{alike(pt, net.names)}"
        ) from None


def datum(net: Network, cfg: dict, extra_fixed: tuple = ()) -> lsq.Datum:
    """The datum of the config: ``datum.kind`` ``fixed`` (the fixed points), ``inner``
    (inner constraints over ``datum.points``, the defects the network has) or ``constraints``
    (``datum.constraints``: records ``{"P1.x" = 1.0, ...}``, each ``sum c_k dx_k = 0``)."""
    free = net.free_index(extra_fixed)
    kind = cfg["datum.kind"]
    if kind == "fixed":
        return lsq.Datum(free)
    if kind == "constraints":
        recs = cfg["datum.constraints"]
        if not recs:
            raise ConfigError("datum.constraints", "datum.kind = constraints needs constraints")
        C = np.zeros((len(free), len(recs)))
        pos = {g: a for a, g in enumerate(free)}
        for b, rec in enumerate(recs):
            for name, coef in rec.items():
                if isinstance(coef, dict) and coef:  # { P.x = 1.0 }: a table P to TOML
                    pair = f"{name}.{next(iter(coef))}"
                    raise ConfigError(
                        f"datum.constraints[{b}]",
                        f"{pair} without quotes is read by TOML as a table {name} with a key "
                        f'{next(iter(coef))}: write "{pair}" = ... in quotes',
                    )
                g = _param_index(net, f"datum.constraints[{b}]", name)
                if g not in pos:
                    if g // 2 in extra_fixed:
                        continue  # held fixed in this parameterisation
                    raise ConfigError(f"datum.constraints[{b}]", f"{name} is not a free unknown")
                if (
                    isinstance(coef, bool)
                    or not isinstance(coef, (int, float))
                    or not np.isfinite(coef)
                    or abs(coef) > 1e12
                ):
                    raise ConfigError(
                        f"datum.constraints[{b}]",
                        f"{name}: coefficient must be a finite number up to 1e12 (got {coef!r})",
                    )
                C[pos[g], b] = coef
            if all(c == 0 for c in rec.values() if isinstance(c, (int, float))):
                raise ConfigError(
                    f"datum.constraints[{b}]", "every coefficient is zero: it constrains nothing"
                )
        keep = np.abs(C).sum(0) > 0
        return lsq.Datum(free, C[:, keep] if keep.any() else None)
    # inner constraints over the chosen points, for the defects the network really has
    pats = cfg["datum.points"] or ["*"]
    sel = np.zeros(net.n, bool)
    index = name_index(net.names)
    for p in pats:
        sel[hits(p, net.names, index)] = True
    if not sel.any():
        raise ConfigError("datum.points", f"no point matches {pats}")
    G = defect_basis(net, free)
    if not G.shape[1]:
        return lsq.Datum(free)
    mask = np.zeros(net.q)
    mask[: 2 * net.n] = np.repeat(sel, 2)
    C = G * mask[free][:, None]
    return lsq.Datum(free, C)
