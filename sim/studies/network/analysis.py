"""Pre-analysis and Monte Carlo of a declared network.

Analytic (at the true coordinates, one linearisation): the covariance of the unknowns in the
datum, per point standard deviations and 95 % error ellipses, the same in other datums by
S-transformation (:mod:`sim.lsq.datum`), per observation the redundancy number
``r_i = 1 - (A Q A' P)_ii`` (they sum to the degrees of freedom), Baarda's minimal detectable
bias ``MDB_i = delta0 sigma_i / sqrt(r_i)`` (internal reliability; ``delta0`` from the test's
``alpha0`` and power), its effect on the coordinates (external reliability: the largest point
displacement it causes) and the bias-to-noise ratio ``delta0 sqrt((1 - r_i) / r_i)``.

Monte Carlo (:func:`mc_chunk`, one chunk of trials, picklable): simulated readings, the
adjustment on the engine, and per-chunk sums of the coordinate errors, the count inside the
analytic 95 % ellipses and the count of global-test rejections (``v'Pv`` against the
chi-square quantile with the a-priori unit variance). Units: mm and rad; sigmas in the
tables in mm. Seeds: Baarda's reliability theory as used for comparator networks (``004``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim import lsq
from sim.lsq import distributions as D
from sim.lsq.datum import s_matrix, s_transform
from sim.mc.config import ConfigError
from sim.studies.network.definition import Network
from sim.studies.network.model import NetworkModel, defect_basis, simulate
from sim.studies.network.validate import name_index, select

__all__ = [
    "Analytic",
    "analyse",
    "delta0",
    "chunk_output",
    "mc_chunk",
    "point_cov_in",
    "in_datum",
    "inner_defect",
    "held_defect",
    "check_inner",
    "inner_left",
    "match_points",
    "estimated_points",
]

CHI2_2_95 = float(D.chi2_ppf(0.95, 2))


def delta0(alpha0: float, power: float) -> float:
    """Baarda's non-centrality (as a normal shift) of the one-dimensional w-test."""
    return float(D.norm_ppf(1 - alpha0 / 2) + D.norm_ppf(power))


@dataclass
class Analytic:
    """Analytic pre-analysis. ``free`` (p,) indices of the estimated globals; ``Q`` (p, p)
    their covariance (mm^2, rad^2); ``cov`` (n, 2, 2) point covariances (zero for points held
    fixed); ``redundancy``, ``mdb``, ``ext_max_mm``, ``bnr`` (m,); ``dof``; ``ok``; ``n_diag`` (p,) the
    diagonal of the normal matrix (for the variance inflation ``Q_ii N_ii``)."""

    free: np.ndarray
    Q: np.ndarray
    cov: np.ndarray
    redundancy: np.ndarray
    mdb: np.ndarray
    ext_max_mm: np.ndarray
    bnr: np.ndarray
    dof: int
    ok: bool
    n_diag: np.ndarray | None = None  # (p,) diagonal of the normal matrix A'PA


def point_cov_in(net: Network, free: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """The full ``(2n, 2n)`` coordinate covariance (zeros for fixed coordinates)."""
    full = np.zeros((net.q, net.q))
    full[np.ix_(free, free)] = Q
    return full[: 2 * net.n, : 2 * net.n]


#: rows of the hat matrix ``A Q A' P`` formed at a time for its diagonal: the whole (m, m)
#: matrix was formed (11.3 GiB for 198 points' 39,006 distances on the dense path, which the
#: estimate does not count); up to this many rows it is formed whole, as before
HAT_BLOCK = 2048


def hat_diagonal(AQ: np.ndarray, Aw: np.ndarray) -> np.ndarray:
    """The diagonal of ``AQ @ Aw.T`` (the redundancy numbers' ``(A Q A' P)_ii``, unitless),
    :data:`HAT_BLOCK` rows at a time: memory linear in the observations, not quadratic."""
    return np.concatenate(
        [
            np.diag(AQ[s : s + HAT_BLOCK] @ Aw[s : s + HAT_BLOCK].T)
            for s in range(0, max(len(Aw), 1), HAT_BLOCK)
        ]
    )


def analyse(net: Network, datum: lsq.Datum, a0: float, power: float) -> Analytic:
    """The analytic pre-analysis of ``net`` in ``datum``."""
    theta = net.theta_true()[None]
    model = NetworkModel(net, None)
    free = datum.free_index(net.q)
    cof = lsq.cofactors(model, np.zeros((1, net.m, 0)), theta, datum)
    Q = cof.Qgg[0]
    ok = bool(cof.ok[0])
    lin = model.linearize(np.zeros((1, net.m, 0)), theta, True)
    Aw = lin.Jg[0, :, 0][:, free] / net.sigma[:, None]  # weighted design (m, p)
    if not ok:
        nan = np.full(net.m, np.nan)
        return Analytic(free, Q, np.full((net.n, 2, 2), np.nan), nan, nan, nan, nan, 0, False)
    r = np.clip(1.0 - hat_diagonal(Aw @ Q, Aw), 0.0, 1.0)
    c = 0 if datum.constraint_matrix(theta) is None else datum.constraint_matrix(theta).shape[-1]
    dof = net.m - len(free) + c
    d0 = delta0(a0, power)
    with np.errstate(divide="ignore", invalid="ignore"):
        controlled = r > 1e-9
        mdb = np.where(controlled, d0 * net.sigma / np.sqrt(r), np.inf)
        bnr = np.where(controlled, d0 * np.sqrt((1 - r) / r), np.inf)
        # shift of the unknowns by an undetected MDB on observation i: Q Aw_i' (mdb_i / sigma_i)
        shift = (Q @ Aw.T) * np.where(controlled, mdb / net.sigma, 0.0)  # (p, m)
    full = np.zeros((net.q, net.m))
    full[free] = shift
    disp = np.hypot(full[0 : 2 * net.n : 2], full[1 : 2 * net.n : 2])  # (n, m)
    ext = np.where(controlled, disp.max(axis=0), np.inf)
    cov2 = point_cov_in(net, free, Q).reshape(net.n, 2, net.n, 2)
    cov = cov2[np.arange(net.n), :, np.arange(net.n), :]
    n_diag = np.einsum("ij,ij->j", Aw, Aw)
    return Analytic(free, Q, cov, r, mdb, ext, bnr, int(dof), True, n_diag)


def inner_defect(net: Network) -> np.ndarray:
    """Coordinate rows ``(2n, d)`` of the datum defects of ``net`` with every point free
    (translation, rotation and, for a network without a length, scale)."""
    orient = 2 * net.n + np.arange(len(net.stations))
    extra = [net.i_constant] * net.estimate_constant + [net.i_scale] * net.estimate_scale
    free = np.concatenate([np.arange(2 * net.n), orient, extra]).astype(int)
    return defect_basis(net, free)[: 2 * net.n]


def held_defect(net: Network, free: np.ndarray) -> np.ndarray:
    """Coordinate rows ``(2n, d)`` of the datum defects the free unknowns ``free`` leave, the
    fixed points held (one fixed point: the rotation, and scale, about it): what inner
    constraints over a datum's points must remove (a held point's rows are zero)."""
    G = defect_basis(net, free)
    H = np.zeros((2 * net.n, G.shape[1]))
    coord = free < 2 * net.n
    H[free[coord]] = G[coord]
    return H


def match_points(net: Network, key: str, pats) -> list[int]:
    """Indices of the points matching any of the name patterns (one set; each pattern must
    match a point)."""
    return select(key, pats, net.names, name_index(net.names), "no point matches")


def datum_weights(net: Network, points: list[int]) -> np.ndarray:
    w = np.zeros(2 * net.n)
    w[np.repeat(points, 2) * 2 + np.tile([0, 1], len(points))] = 1.0
    return w


def check_inner(net: Network, H: np.ndarray, points: list[int], key: str) -> None:
    """Refuse inner constraints over ``points`` that cannot remove the defects ``H``
    (``H' W H`` singular: e.g. one point against a rotation, collinear points against a
    rotation and scale)."""
    if not H.shape[1]:
        return
    w = datum_weights(net, points)
    ev = np.linalg.eigvalsh((H.T * w) @ H)
    if ev.min() <= 1e-10 * max(np.linalg.eigvalsh(H.T @ H).max(), 1e-300):
        names = ", ".join(net.names[a] for a in points[:5]) + (" ..." if len(points) > 5 else "")
        d = H.shape[1]
        raise ConfigError(
            key,
            f"the points {names} cannot fix the network's {d} datum defect{'s' * (d != 1)} "
            f"({defect_words(H, net.role)}): choose more points, not all on one line",
        )


def inner_over_defect(
    net: Network, free: np.ndarray, points: list[int], key: str
) -> tuple[np.ndarray, bool]:
    """The defects ``H`` (2n, d) the inner datum over ``points`` (``output.inner_over``)
    removes, and whether they are those the fixed points leave: every defect of the network
    adjusted free (translation, rotation, scale: :func:`inner_defect`; the held network's
    precision moved to the inner datum) where the points can hold them all, else the defects
    the fixed points leave (one fixed point: the rotation, and scale, about it,
    :func:`held_defect`, as ``compare.fix`` takes them), where the points hold those: one
    point beside a fixed point was refused, though it holds the rotation about it. Points
    that hold neither are refused naming ``key``."""
    H = inner_defect(net)
    try:
        check_inner(net, H, points, key)
        return H, False
    except ConfigError:
        held = held_defect(net, free)
        if not 0 < held.shape[1] < H.shape[1]:  # no fixed point, or none left: meaningless
            raise
        check_inner(net, held, points, key)
        return held, True


def inner_left(net: Network, H: np.ndarray, key: str) -> None:
    """Refuse an inner datum (``key``: ``datum.kind``, or ``datum.points`` when given) on a
    network whose fixed points leave no defect ``H`` (:func:`held_defect`): its run was the
    fixed datum's, said as ``datum `inner` (0 constraints)``, and ``datum.points`` changed
    nothing (P35's left item)."""
    if H.shape[1]:
        return
    # the fixed points and the weighted coordinates: both where both are (one fixed point and
    # a weighted one were "the fixed points A already fix", which one point cannot)
    parts = []
    for role, what in ((1, "fixed points"), (2, "observed (weighted) coordinates of")):
        held = [net.names[a] for a in np.flatnonzero(net.role == role)]
        if held:
            parts.append(f"{what} {', '.join(held[:5])}{' ...' if len(held) > 5 else ''}")
    raise ConfigError(
        key,
        f'datum.kind = "inner" has nothing to constrain: the {" and the ".join(parts)} already fix '
        "the network's datum (no defect is left for inner constraints over datum.points, which "
        'would change nothing): use datum.kind = "fixed" (output.inner_over states the '
        "precision in an inner datum too)",
    )


def defect_words(H: np.ndarray, role: np.ndarray | None = None) -> str:
    """What the datum defects ``H`` (rows of :func:`held_defect`) are, in words: with no point
    held two translations, a rotation and, without a length, a scale; with points held (their
    rows zero) a rotation and a scale about them. It said "translation, rotation, scale" for
    any count, also for the one rotation left by a fixed point. A point its observed (weighted)
    coordinates hold has rows of rounding noise, not zero (``role``: the points' roles, to say
    which): it said "1 motions of the whole network"."""
    d = H.shape[1]
    rows = np.abs(H.reshape(-1, 2 * d)).max(axis=1) if H.size else np.zeros(0)
    still = rows <= 1e-9 * rows.max(initial=0.0)
    held = bool(still.any())
    if not held and d in (3, 4):
        return "two translations and a rotation" + (", and a scale: no length" if d == 4 else "")
    if held and d in (1, 2):
        weighted = role is not None and bool(np.any(role[still] == 2))
        about = "the fixed or weighted points" if weighted else "the fixed points"
        return "a rotation" + (" and a scale" if d == 2 else "") + f" about {about}"
    return f"{d} motions of the whole network"


def in_datum(
    net: Network, an: Analytic, points: list[int], H: np.ndarray | None = None
) -> np.ndarray:
    """Point covariances ``(n, 2, 2)`` stated in the inner-constraint datum over ``points``
    (S-transformation removing every defect the network has: translation, rotation and, for
    a network without a length, scale; as ``gama-local``'s ``adj="XY"``; or the defects
    ``H`` only, ``(2n, d)``: those its fixed points leave, :func:`held_defect`)."""
    H = inner_defect(net) if H is None else H
    full = point_cov_in(net, an.free, an.Q)
    if H.shape[1]:
        full = s_transform(full, s_matrix(H, datum_weights(net, points)))
    Qs = full.reshape(net.n, 2, net.n, 2)
    return Qs[np.arange(net.n), :, np.arange(net.n), :]


def estimated_points(net: Network, an: Analytic) -> list[int]:
    """Estimated points whose 2 x 2 covariance is regular (a point held by a datum
    constraint, such as Brown's x1 = 0, has a singular block and no ellipse; a point inner
    constraints hold whole, two points against a rotation and a scale, has a block of rounding
    noise, 1e-18 mm^2, whose relative determinant is noise too: it was taken for estimated and
    the run refused for its "0 mm" sigma). Such noise is also far below what the point's own
    observations give it, ``1 / N_ii`` (the normal matrix's diagonal, :attr:`Analytic.n_diag`):
    a point measured at 0.1 um beside one at 1 m (a variance 1e-14 of the largest) was left
    out, "held in part by the datum constraints" of a fixed datum with none."""
    var = (an.cov[:, 0, 0] + an.cov[:, 1, 1]) / 2
    det = an.cov[:, 0, 0] * an.cov[:, 1, 1] - an.cov[:, 0, 1] ** 2
    # rounding noise of the inverse: up to 6e-17 of the largest variance (a 625-point sparse
    # network); a variance below 1e-14 of it, and below 1e-9 of its own 1 / N_ii, is none
    noise = np.full(net.n, 1e-14 * float(var.max(initial=0.0)))
    if an.n_diag is not None:
        own = np.zeros(net.q)
        with np.errstate(divide="ignore"):
            own[an.free] = 1.0 / np.asarray(an.n_diag, dtype=float)
        own = own[: 2 * net.n].reshape(net.n, 2).mean(axis=1)
        noise = np.minimum(noise, 1e-9 * own)
    return [
        a
        for a in range(net.n)
        if net.role[a] != 1 and var[a] > noise[a] and det[a] > 1e-12 * var[a] ** 2
    ]


def ellipse(cov: np.ndarray):
    """1-sigma semi-axes ``a >= b`` and the bearing of ``a`` (rad from +x) of ``(n, 2, 2)``."""
    sxx, syy, sxy = cov[:, 0, 0], cov[:, 1, 1], cov[:, 0, 1]
    h, g = (sxx + syy) / 2, np.sqrt(((sxx - syy) / 2) ** 2 + sxy**2)
    return (
        np.sqrt(np.maximum(h + g, 0)),
        np.sqrt(np.maximum(h - g, 0)),
        0.5 * np.arctan2(2 * sxy, sxx - syy),
    )


#: an ellipse whose semi-axes differ by less than this share is a circle: its bearing is not
#: defined (rounding alone would pick one), and stored as null with that reason
CIRCLE_RTOL = 1e-6


def bearing_deg(cov: np.ndarray) -> tuple[list, list[str]]:
    """Bearing of the 1-sigma ellipse's major axis of ``(n, 2, 2)`` covariances, in degrees
    from +x in ``(-90, 90]`` (an axis: compared modulo 180), and per point why it is None
    (undefined): a circle (``(a - b) / a < CIRCLE_RTOL``) or a point without variance."""
    sxx, syy, sxy = cov[:, 0, 0], cov[:, 1, 1], cov[:, 0, 1]
    h, g = (sxx + syy) / 2, np.hypot((sxx - syy) / 2, sxy)
    th = np.degrees(0.5 * np.arctan2(2 * sxy, sxx - syy))
    th = np.where(th <= -90.0, th + 180.0, th)
    why = [
        "no variance"
        if hh <= 0
        else (f"a circle to {CIRCLE_RTOL:g}: no major axis" if gg <= CIRCLE_RTOL * hh else "")
        for hh, gg in zip(h, g)
    ]
    return [None if w else float(t) for t, w in zip(th, why)], why


def chunk_output(
    net: Network,
    err: np.ndarray,
    ok: np.ndarray,
    pts: np.ndarray,
    cov_inv: np.ndarray,
    vpv: np.ndarray,
    crit: float,
    par: np.ndarray | None,
    status: np.ndarray,
    sigma0: np.ndarray,
    iterations: np.ndarray,
) -> dict:
    """What one chunk of ``n`` adjustments returns, from the errors ``err`` (n, q) of the
    estimated globals (coordinates mm) and which trials converged (``ok``): per chunk, the
    count, the sums and sums of squares of the coordinate errors of ``pts`` and of the
    parameter errors ``par``, the points inside their analytic 95 % ellipse (``cov_inv``),
    the global tests rejected (``vpv > crit``); per trial, status, sigma0 (-1: none) and
    iterations."""
    n = err.shape[0]
    e = err[:, : 2 * net.n].reshape(n, net.n, 2)[:, pts][ok]  # (N, k, 2)
    inside = np.einsum("tki,kij,tkj->tk", e, cov_inv, e) <= CHI2_2_95
    par = np.zeros(0, int) if par is None else np.asarray(par, int)
    g = err[:, par][ok]  # (N, k_par)
    return {
        "sum.n": np.array([[ok.sum()]], float),
        "sum.pe": g.sum(0)[None],
        "sum.pee": (g * g).sum(0)[None],
        "sum.e": e.sum(0)[None],
        "sum.ee": np.einsum("tki,tkj->kij", e, e)[None],
        "sum.inside": inside.sum(0)[None].astype(float),
        "sum.reject": np.array([[(vpv[ok] > crit).sum()]], float),
        "rows.converged": ok,
        "rows.status": status.astype(np.int8),
        "rows.sigma0": np.where(np.isfinite(sigma0), sigma0, -1.0),
        "rows.iterations": iterations,
    }


def mc_chunk(
    rng: np.random.Generator,
    n: int,
    net: Network,
    free: np.ndarray,
    C: np.ndarray | None,
    cov_inv: np.ndarray,
    pts: np.ndarray,
    crit: float,
    tol: float,
    max_iter: int,
    par: np.ndarray | None = None,
) -> dict:
    """One chunk of ``n`` simulated adjustments (see the module doc). ``pts`` are the point
    indices whose coordinates are estimated; ``cov_inv`` (len(pts), 2, 2) their inverse
    analytic covariances; ``crit`` the global test's chi-square critical value; ``par`` the
    indices of the estimated globals that are not coordinates (their errors are summed)."""
    obs = simulate(net, rng, n)
    theta = np.repeat(net.theta_true()[None], n, 0)
    res = lsq.gauss_newton(
        NetworkModel(net, obs), theta, datum=lsq.Datum(free, C), tol=tol, max_iter=max_iter
    )
    ok = res.converged
    vpv = res.sigma0**2 * res.dof if res.dof > 0 else np.zeros(n)
    err = res.theta - theta
    return chunk_output(
        net, err, ok, pts, cov_inv, vpv, crit, par, res.status, res.sigma0, res.iterations
    )
