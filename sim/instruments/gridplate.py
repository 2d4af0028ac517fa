"""Comparator calibration with grid plates whose coordinates are weighted observations.

Seed: ``001_7e3a2951e7fed426.txt`` (*Calibration of a Comparator*, two grid plates on the
Zeiss PSK stereocomparator, Ohio State University).

Pieces, each batched over a leading trial axis ``T``:

* :func:`repeat_precision` -- the paper's "precision of observations": from ``L`` repeated
  readings of ``N`` points on two plates, ``sigma_i^2 = sum(Vx^2 + Vy^2)/(L - 1)`` per point
  and ``sigma^2 = sum sigma_i^2 / 4N`` (the paper's "4N degrees of freedom" is the divisor:
  two coordinates on two plates; each ``sigma_i^2`` estimates ``2 sigma^2``). The true
  number of degrees of freedom is ``4N(L - 1)``.

* :func:`combined_adjustment` -- the paper's simultaneous adjustment of one comparator
  coordinate (``x'`` or ``y'``, "handled independently")::

      x'_i - (A x_a,i + B y_a,i + C) = v'_i      weight P_x
      x_i  - x_a,i                   = v_x,i     weight P_cx
      y_i  - y_a,i                   = v_y,i     weight P_cx

  with unknowns ``(A, B, C)`` and the adjusted grid coordinates ``(x_a, y_a)`` of every point
  (``2N + 3`` unknowns, ``3N`` observations, redundancy ``N - 3``): the observation model
  :class:`AffineRowModel` solved by the engine :mod:`sim.lsq` from the observed grid
  coordinates; each point's 2 x 2 block is eliminated (reduced normal equations), so the
  largest solve is 3 x 3. ``P_cx = inf`` gives the ordinary affine row.

* :func:`chi2_test` -- the test of the a-posteriori variance of unit weight against its
  a-priori value (two-sided, ``dof * s0^2 / sigma0^2 ~ chi2(dof)``). The paper tests the
  grid variance implied by the weights, ``sigma_g^2 = s0^2 / P_cx``, against the stated
  one; with ``P_cx = 1 / sigma_g,stated^2`` in the same units this is the same statistic.

* :func:`reweight` -- the paper's re-weighting of ``P_x : P_cx`` until the test passes. The
  estimator: ``P_x = 1`` is held fixed (so ``s0^2`` estimates the comparator variance
  ``sigma_x'^2``), the grid variance is held at its stated value, and ``P_cx`` is updated
  to ``s0^2 / sigma_g^2`` -- a one-component variance-component estimate with the other
  component known. Each point of the x' adjustment contributes one condition, whose
  misclosure ``w = x' - A x - B y - C`` has variance ``sigma_x'^2 + (A^2+B^2) sigma_g^2``;
  only that sum is estimable, so the fixed point is
  ``sigma_x'^2 = s_w^2 - (A^2+B^2) sigma_g^2`` (a subtraction estimate) and the iteration
  converges geometrically with factor ``1/(1 + P_cx)``. Helmert's two-group estimate has no
  unique solution here for the same reason.

Units: any consistent length unit; the studies use millimetres for coordinates and report
micrometres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sim import lsq
from sim.instruments import transforms2d as t2
from sim.instruments.plates import grid_points
from sim.lsq import distributions as D

__all__ = [
    "repeat_precision",
    "CombinedResult",
    "AffineRowModel",
    "combined_adjustment",
    "chi2_test",
    "reweight",
]


def repeat_precision(readings: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Seed 001's precision of observation from repeated readings.

    Parameters
    ----------
    readings : (T, P, N, L, 2) -- ``L`` readings of ``N`` points on ``P`` plates.

    Returns
    -------
    sigma_i : (T, P, N) per-point ``sqrt(sum(Vx^2 + Vy^2) / (L - 1))``.
    sigma : (T,) ``sqrt(sum sigma_i^2 / (2 P N))`` -- with ``P = 2`` the paper's divisor 4N;
        an unbiased estimate of the per-coordinate variance of one reading.
    """
    r = np.asarray(readings, float)
    L = r.shape[3]
    v = r - r.mean(axis=3, keepdims=True)
    si2 = np.einsum("tpnlk,tpnlk->tpn", v, v) / (L - 1)
    P, N = r.shape[1], r.shape[2]
    return np.sqrt(si2), np.sqrt(si2.sum(axis=(1, 2)) / (2 * P * N))


@dataclass
class CombinedResult:
    """Result of :func:`combined_adjustment` for one comparator coordinate.

    params : (T, 3) ``(A, B, C)``; grid : (T, N, 2) adjusted grid coordinates;
    cofactor : (T, 3, 3) ``Q`` of the parameters (``cov = sigma0^2 Q``); s0 : (T,)
    a-posteriori standard error of unit weight; v_comp : (T, N) comparator residuals
    (observed minus adjusted); v_grid : (T, N, 2) grid residuals; dof : ``N - 3``;
    iterations : Gauss-Newton iterations used.
    """

    params: np.ndarray
    grid: np.ndarray
    cofactor: np.ndarray
    s0: np.ndarray
    v_comp: np.ndarray
    v_grid: np.ndarray
    dof: int
    iterations: int


class AffineRowModel:
    """Observation model of the combined adjustment for :mod:`sim.lsq` (seed 001).

    Point blocks: the adjusted grid coordinates ``(x_a, y_a)`` of each point (``d = 2``; none
    when the grid is fixed). Globals: ``(A, B, C)``. Rows per point: the comparator reading
    ``x' - (A x_a + B y_a + C)`` (weight ``P_x``) and, for a weighted grid, the grid
    coordinates ``x - x_a``, ``y - y_a`` (weight ``P_cx``). comp : (T, N); grid : (T, N, 2);
    p_comp, p_grid : (T,).
    """

    n_global = 3

    def __init__(self, comp, grid, p_comp, p_grid, fixed_grid: bool):
        self.comp, self.grid, self.fixed = comp, grid, fixed_grid
        self.point_dim = 0 if fixed_grid else 2
        w = [p_comp] if fixed_grid else [p_comp, p_grid, p_grid]
        self.w = np.stack(w, -1)[:, None, :]  # (T, 1, k)

    def initial_points(self, theta):
        return self.grid.copy() if not self.fixed else self.grid[..., :0]

    def linearize(self, points, theta, globals_needed=True):
        u = self.grid if self.fixed else points
        T, N = self.comp.shape
        G = np.concatenate([u, np.ones((T, N, 1))], -1)  # d comp / d (A, B, C)
        r0 = self.comp - np.einsum("tni,ti->tn", G, theta)
        if self.fixed:
            return lsq.Linearization(r0[..., None], None, G[:, :, None, :], self.w)
        r = np.concatenate([r0[..., None], self.grid - u], -1)  # (T, N, 3)
        Jp = np.zeros((T, N, 3, 2))
        Jp[:, :, 0, :] = theta[:, None, :2]
        Jp[:, :, 1, 0] = Jp[:, :, 2, 1] = 1.0
        Jg = np.zeros((T, N, 3, 3))
        Jg[:, :, 0, :] = G
        return lsq.Linearization(r, Jp, Jg, self.w)


def _adjust(comp, g, Px, Pc, fixed: bool, max_iter: int, tol: float):
    """One engine run: the affine row starts at zero, whose first Gauss-Newton step is the
    ordinary least-squares row on the given grid (the grid enters linearly at A = B = 0)."""
    m = AffineRowModel(comp, g, Px, Pc, fixed)
    T = comp.shape[0]
    res = lsq.gauss_newton(
        m, np.zeros((T, 3)), m.initial_points(None), tol=tol, max_iter=max_iter + 1
    )
    u = g if fixed else res.points
    v_comp = res.residuals[..., 0]
    v_grid = g - u
    return res, u, v_comp, v_grid


def combined_adjustment(
    comp: np.ndarray,
    grid: np.ndarray,
    p_comp=1.0,
    p_grid=np.inf,
    max_iter: int = 10,
    tol: float = 1e-13,
) -> CombinedResult:
    """Seed 001's simultaneous adjustment of one comparator coordinate, by the engine
    :func:`sim.lsq.gauss_newton` (each point's 2 x 2 block eliminated; largest solve 3 x 3).

    Parameters
    ----------
    comp : (T, N) observed comparator coordinate (``x'`` or ``y'``).
    grid : (T, N, 2) or (N, 2) grid-plate coordinates as given (observations).
    p_comp, p_grid : weights ``P_x`` and ``P_cx`` (scalars or (T,)); ``p_grid = inf`` keeps
        the grid fixed (ordinary least squares of one affine row).
    max_iter, tol : Gauss-Newton stops when the largest correction, relative to the
        coordinate scale ``max(1, max |grid|)``, is below ``tol``. ``iterations`` counts the
        steps after the ordinary least-squares start.
    """
    comp = np.asarray(comp, float)
    T, N = comp.shape
    g = np.broadcast_to(np.asarray(grid, float), (T, N, 2)).copy()
    Px = np.broadcast_to(np.asarray(p_comp, float), (T,)).copy()
    Pc = np.broadcast_to(np.asarray(p_grid, float), (T,)).copy()
    fixed = ~np.isfinite(Pc)
    tol_abs = tol * max(1.0, float(np.abs(g).max()))
    params, u = np.zeros((T, 3)), g.copy()
    Q, s0 = np.zeros((T, 3, 3)), np.zeros(T)
    v_comp, v_grid = np.zeros((T, N)), np.zeros((T, N, 2))
    iters = 0
    for is_fixed in (True, False):
        sel = fixed if is_fixed else ~fixed
        if not sel.any():
            continue
        res, uu, vc, vg = _adjust(comp[sel], g[sel], Px[sel], Pc[sel], is_fixed, max_iter, tol_abs)
        params[sel], u[sel], v_comp[sel], v_grid[sel] = res.theta, uu, vc, vg
        Q[sel], s0[sel] = res.global_cofactor(), res.sigma0
        iters = max(iters, int(res.iterations.max()) - 1)
    return CombinedResult(params, u, Q, s0, v_comp, v_grid, N - 3, iters)


def chi2_test(s0: np.ndarray, dof: int, sigma0: float | np.ndarray = 1.0, alpha: float = 0.05):
    """Two-sided chi-square test of ``s0^2`` against the a-priori ``sigma0^2``.

    Returns ``(statistic, p_value, reject)`` with ``statistic = dof s0^2 / sigma0^2``.
    """
    x = dof * np.asarray(s0, float) ** 2 / np.asarray(sigma0, float) ** 2
    cdf = D.chi2_cdf(x, dof)
    p = 2 * np.minimum(cdf, 1 - cdf)
    return x, p, p < alpha


def reweight(
    comp: np.ndarray,
    grid: np.ndarray,
    sigma_grid: float,
    ratio0: float = 1.0,
    max_rounds: int = 20,
    rtol: float = 1e-9,
    alpha: float = 0.05,
) -> dict:
    """Seed 001's re-weighting of ``P_x : P_cx`` until the chi-square test passes.

    ``P_x = 1`` throughout; start at ``P_cx = ratio0``. The paper's rule is
    ``P_cx <- s0^2 / sigma_grid^2`` (force the grid variance implied by the weights,
    ``s0^2 / P_cx``, to the stated one). That iteration converges slowly when the stated grid
    variance is close to the total, so each round jumps to its fixed point instead: from one
    adjustment the misclosure variance ``s_w^2 = s0^2 (1 + (A^2 + B^2) / P_cx)`` (exact for the
    linearised model) gives ``P_cx = s_w^2 / sigma_grid^2 - (A^2 + B^2)``; a few rounds absorb
    the non-linearity. ``sigma_grid`` is in the units of the coordinates.

    Returns a dict with ``ratio`` (T,) final ``P_cx / P_x`` (NaN where no positive fixed point
    exists: the stated grid variance exceeds the total misclosure variance), ``s0`` (T,) the
    final ``s0`` -- the estimate of the comparator standard error ``sigma_x'`` (0 where no
    fixed point), ``sigma_grid_implied`` (T,) ``s0 / sqrt(P_cx)``, ``passes`` (T,) whether the
    chi-square test of the implied grid variance against the stated one passes, ``rounds``
    and ``result`` (the last :class:`CombinedResult`).
    """
    T = np.asarray(comp).shape[0]
    ratio = np.full(T, float(ratio0))
    rounds = 0
    ok = np.ones(T, bool)
    for rounds in range(1, max_rounds + 1):
        res = combined_adjustment(comp, grid, 1.0, ratio)
        r2 = res.params[:, 0] ** 2 + res.params[:, 1] ** 2
        sw2 = res.s0**2 * (1.0 + r2 / ratio)
        new = sw2 / sigma_grid**2 - r2
        ok = new > 1e-6
        new = np.where(ok, new, 1e-6)
        done = np.all((np.abs(new - ratio) <= rtol * ratio) | ~ok)
        ratio = new
        if done:
            break
    res = combined_adjustment(comp, grid, 1.0, ratio)
    implied = res.s0 / np.sqrt(ratio)
    _, _, rej = chi2_test(implied, res.dof, sigma_grid, alpha)
    return {
        "ratio": np.where(ok, ratio, np.nan),
        "s0": np.where(ok, res.s0, 0.0),
        "sigma_grid_implied": implied,
        "passes": ~rej & ok,
        "rounds": rounds,
        "result": res,
    }


def simulate_calibrations(
    rng: np.random.Generator,
    n: int,
    *,
    grid: int,
    spacing_mm: float,
    plates: int,
    readings: int,
    scale_diff_ppm: float,
    nonorth_arcsec: float,
    kappa_deg: float,
    reading_sigma_um: float,
    coord_sigma_um: float,
    grid_sigma_um: float,
) -> dict[str, np.ndarray]:
    """Readings and grid certificates of ``n`` two-plate calibrations (seed 001's setup).

    A comparator whose x and y scales differ by ``scale_diff_ppm`` (S = 1 - d/2, S' = 1 + d/2)
    with a non-orthogonality of ``nonorth_arcsec`` measures ``plates`` k x k grid plates
    (``grid``, ``spacing_mm``; a uniform kappa rotation up to ``kappa_deg`` and a shift of
    120 +- 5 mm each), ``readings`` readings per point with ``reading_sigma_um`` each and a
    point error making the mean's coordinate sigma ``coord_sigma_um``; the certificate is
    the grid with ``grid_sigma_um`` per coordinate. Returns ``readings`` (n, P, N, L, 2) mm,
    ``cert`` (n, P, N, 2) mm and ``true`` (n, P, 6), the true affine grid -> comparator.
    """
    G = grid_points(grid, spacing_mm)
    P, N, L = plates, G.shape[0], readings
    d = scale_diff_ppm * 1e-6
    S, S2, eps = 1.0 - d / 2, 1.0 + d / 2, nonorth_arcsec * t2.ARCSEC
    kap = rng.uniform(-1, 1, (n, P)) * np.deg2rad(kappa_deg)
    shift = rng.uniform(-5, 5, (n, P, 2)) + np.array([120.0, 120.0])
    true = t2.affine_from_rows(S, S2, eps, kap, (shift[..., 0], shift[..., 1]))
    ideal = t2.apply_affine(true.reshape(-1, 6), G).reshape(n, P, N, 2)
    sp, sc = reading_sigma_um * 1e-3, coord_sigma_um * 1e-3
    s_point = np.sqrt(max(sc**2 - sp**2 / L, 0.0))
    comp_err = rng.normal(0.0, 1.0, (n, P, N, 2)) * s_point
    rd = (ideal + comp_err)[:, :, :, None, :] + rng.normal(0.0, sp, (n, P, N, L, 2))
    cert = G + rng.normal(0.0, 1.0, (n, P, N, 2)) * grid_sigma_um * 1e-3
    return {"readings": rd, "cert": cert, "true": true}
