"""The one Gauss-Newton loop of the suite, batched over a leading trial axis.

Each iteration linearises the model at the current unknowns of every trial, eliminates the
point blocks (:func:`sim.lsq.normals.reduce`), solves the (bordered) reduced normals of the
free globals and applies the corrections. Per-trial status (:data:`sim.lsq.result.STATUS`):
a trial stops when its largest correction -- or the remaining error estimated from the
observed contraction, ``rho / (1 - rho)`` times the correction with ``rho`` the ratio of the
last two corrections -- falls below ``tol``; a singular trial (the one scaled rule of
:mod:`sim.lsq.normals`) or one with non-finite corrections is flagged with its message and
frozen; nothing raises, so one bad trial never kills its chunk. Seed of the method: Brown
1968 (``004_f5bd9e86c308241f.txt``, iterated reduced normal equations).
"""

from __future__ import annotations

import numpy as np

from sim.lsq import groups
from sim.lsq.normals import RCOND, bordered_solve, reduced_normals
from sim.lsq.problem import Datum, fast_path
from sim.lsq.result import Result

__all__ = ["gauss_newton", "degrees_of_freedom"]


class _Progress:
    """Per-trial bookkeeping: status, iterations, the previous step (contraction estimate)."""

    def __init__(self, T: int):
        self.active = np.ones(T, bool)
        self.status = np.ones(T, np.int8)
        self.iters = np.zeros(T, np.int32)
        self.prev = np.full(T, np.nan)

    def update(self, it: int, ok: np.ndarray, step: np.ndarray, tol: float) -> np.ndarray:
        """Flag singular and non-finite trials; return the trials whose corrections apply."""
        self.status[~ok & self.active] = 2
        self.active &= ok
        finite = np.isfinite(step)
        self.status[self.active & ~finite] = 3
        self.active &= finite
        upd = self.active.copy()
        self.iters[upd] = it
        with np.errstate(invalid="ignore", divide="ignore"):
            rho = step / self.prev
            est = np.where(rho < 0.5, rho / (1.0 - rho) * step, np.inf)
        done = upd & ((step < tol) | (est < tol))
        self.status[done] = 0
        self.active &= ~done
        self.prev = step
        return upd


def degrees_of_freedom(
    model, n_points: int, datum: Datum, theta: np.ndarray, rows: int | None = None
) -> int:
    """Observations (``model.n_obs``, else ``rows``) minus unknowns plus datum constraints."""
    free = datum.free_index(model.n_global)
    m = getattr(model, "n_obs", None)
    m = rows if m is None else m
    C = datum.constraint_matrix(theta) if len(free) else None
    c = 0 if C is None else C.shape[-1]
    return int(m) - n_points * model.point_dim - len(free) + c


def _retract(model, points, theta, dp, dg_full):
    if hasattr(model, "retract"):
        return model.retract(points, theta, dp, dg_full)
    return points + dp, theta + dg_full


def gauss_newton(
    model,
    theta0: np.ndarray,
    points0: np.ndarray | None = None,
    datum: Datum | None = None,
    tol: float = 1e-10,
    max_iter: int = 30,
    rcond: float = RCOND,
    engine: str = "auto",
    step_scale=None,
) -> Result:
    """Batched Gauss-Newton adjustment of ``model`` (see :mod:`sim.lsq.problem`).

    theta0 : (T, q) the fixed globals and the start of the free ones; points0 : (T, n, d)
    start of the point blocks (None: ``model.initial_points(theta0)``, or the fast path's own
    start). tol : convergence threshold on the largest correction, in the units of the
    unknowns divided by ``step_scale`` (optional per-global scale (q,) -- points use 1).
    engine : ``auto`` (a registered fast path when it applies, else the loop), ``numpy``
    (always the loop) or ``fast`` (the fast path; ValueError if none applies).
    """
    if engine not in ("auto", "numpy", "fast"):
        raise ValueError(f"engine must be auto, numpy or fast, not {engine!r}")
    datum = Datum() if datum is None else datum
    theta = np.array(theta0, float, copy=True)
    T = theta.shape[0]
    if engine != "numpy" and points0 is None and step_scale is None:
        fp = fast_path(model)
        res = None if fp is None else fp(model, theta, datum, tol, max_iter)
        if res is not None:
            return res
    if engine == "fast":
        raise ValueError(f"no fast path applies to {type(model).__name__} with this datum")
    if getattr(model, "structure", None) is not None:
        return _grouped(model, theta, points0, datum, tol, max_iter, rcond, step_scale)
    free = datum.free_index(model.n_global)
    p = len(free)
    C = datum.constraint_matrix(theta) if p else None
    scale = None if step_scale is None else np.asarray(step_scale, float)[free]
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        pts = (
            model.initial_points(theta) if points0 is None else np.array(points0, float, copy=True)
        )
        prog = _Progress(T)
        for it in range(1, max_iter + 1):
            red = reduced_normals(model, pts, theta, free, rcond)
            ok = red.ok
            if p:
                dg, okg = bordered_solve(red.Nbar, red.ubar, C, rcond)
                ok = ok & okg
            else:
                dg = np.zeros((T, 0))
            dp = red.points_step(dg)
            step = np.abs(dp).max(axis=(1, 2), initial=0.0)
            if p:
                g = np.abs(dg) if scale is None else np.abs(dg) / scale
                step = np.maximum(step, g.max(axis=1))
            step = np.where(
                np.isfinite(dp).all(axis=(1, 2)) & np.isfinite(dg).all(axis=1), step, np.nan
            )
            upd = prog.update(it, ok, step, tol)
            dg_full = np.zeros_like(theta)
            dg_full[:, free] = np.where(upd[:, None], dg, 0.0)
            new_pts, new_theta = _retract(
                model, pts, theta, np.where(upd[:, None, None], dp, 0.0), dg_full
            )
            pts = np.where(upd[:, None, None], new_pts, pts)
            theta = np.where(upd[:, None], new_theta, theta)
            if not prog.active.any():
                break
        lin = model.linearize(pts, theta, False)
        wr2 = lin.r * lin.r if lin.w is None else lin.w * lin.r * lin.r
        vpv = wr2.reshape(T, -1).sum(1)
    dof = degrees_of_freedom(model, pts.shape[1], datum, theta, lin.r[0].size)
    s0 = np.sqrt(vpv / dof) if dof > 0 else np.full(T, np.nan)
    return Result(pts, theta, lin.r, s0, dof, prog.iters, prog.status, model, datum)


def _bcast(mask: np.ndarray, a: np.ndarray) -> np.ndarray:
    return mask.reshape(mask.shape + (1,) * (a.ndim - 1))


def _grouped(model, theta, points0, datum, tol, max_iter, rcond, step_scale) -> Result:
    """The same loop for models whose globals are group blocks (:mod:`sim.lsq.groups`):
    ``model.structure`` a :class:`~sim.lsq.groups.GroupStructure`, ``model.linearize``
    returning a :class:`~sim.lsq.groups.GroupLinearization`, ``theta`` any per-trial state
    that ``model.retract`` updates with the tangent corrections (T, G b). A model with a
    ``take(trials)`` method (the same model on some trials) is linearised, once some trials
    have stopped, on the active trials only."""
    if datum.free is not None or datum.constraints is not None:
        raise ValueError("group-block models take their datum from weighted point rows")
    st = model.structure
    T = theta.shape[0]
    scale = None if step_scale is None else np.asarray(step_scale, float)
    solver = getattr(model, "solver", "auto")
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        pts = (
            model.initial_points(theta) if points0 is None else np.array(points0, float, copy=True)
        )
        prog = _Progress(T)
        for it in range(1, max_iter + 1):
            act = np.flatnonzero(prog.active)
            if act.size < T and hasattr(model, "take"):  # only the trials still iterating
                dp_a, dg_a, ok_a = groups.step(
                    st, model.take(act).linearize(pts[act], theta[act]), solver, rcond, it == 1
                )
                dp, dg = np.zeros_like(pts), np.zeros((T,) + dg_a.shape[1:])
                ok = np.ones(T, bool)
                dp[act], dg[act], ok[act] = dp_a, dg_a, ok_a
            else:
                dp, dg, ok = groups.step(st, model.linearize(pts, theta), solver, rcond, it == 1)
            g = np.abs(dg) if scale is None else np.abs(dg) / scale
            step = np.maximum(np.abs(dp).max(axis=(1, 2)), g.max(axis=1))
            step = np.where(
                np.isfinite(dp).all(axis=(1, 2)) & np.isfinite(dg).all(axis=1), step, np.nan
            )
            upd = prog.update(it, ok, step, tol)
            new_pts, new_theta = model.retract(
                pts, theta, np.where(upd[:, None, None], dp, 0.0), np.where(upd[:, None], dg, 0.0)
            )
            pts = np.where(upd[:, None, None], new_pts, pts)
            theta = np.where(_bcast(upd, theta), new_theta, theta)
            if not prog.active.any():
                break
        lin = model.linearize(pts, theta)
        vpv = np.einsum("tkm,tkm->t", lin.w * lin.r, lin.r) + np.einsum(
            "tcm,tcm->t", lin.wc * lin.rc, lin.rc
        )
    present = groups.scatter(st.S_point, lin.w) + groups.scatter(st.S_rows, lin.wc) > 0
    dof = (
        (lin.w > 0).sum(axis=(1, 2))
        + (lin.wc > 0).sum(axis=(1, 2))
        - st.n_groups * lin.Jg.shape[-1]
        - model.point_dim * present.any(-1).sum(-1)
    )
    s0 = np.sqrt(vpv / np.maximum(dof, 1))
    res = Result(pts, theta, lin.r, s0, dof, prog.iters, prog.status, model, datum)
    res.point_residuals = lin.rc
    return res
