"""What a problem is: an observation model, its blocks of unknowns, and a datum.

Unknowns come in two kinds, each batched over a leading trial axis ``T``:

* **point blocks** ``points`` ``(T, n, d)``: ``d`` unknowns per point (``d = 0``: none), each
  observation row belongs to one point, so the normal matrix of the points is block diagonal
  and is eliminated by the Schur complement (:mod:`sim.lsq.normals`);
* **globals** ``theta`` ``(T, q)``: everything else -- group blocks (per plate position, per
  model) and global parameters (a scale, Brown's ``alpha``) -- solved densely after the
  elimination.

An **observation model** is any object with

* ``point_dim`` (``d``) and ``n_global`` (``q``);
* ``linearize(points, theta, globals_needed) -> Linearization``: misclosures (observed minus
  computed) ``r`` ``(T, n, k)`` -- ``k`` rows per point, pad with zero weight -- and the
  Jacobians of the *computed* values with respect to the point blocks ``Jp``
  ``(T, n, k, d)`` and all ``q`` globals ``Jg`` ``(T, n, k, q)`` (None when not needed);
  optional weights ``w`` broadcastable to ``(T, n, k)``;
* ``initial_points(theta) -> (T, n, d)``: a start for the points from the globals;
* optionally ``n_obs`` (observations per trial, default ``n k``),
  ``retract(points, theta, dp, dg) -> (points, theta)`` (default: additive updates) and
  ``reduced(points, theta, free, rcond) -> Reduced``: the model's own reduced normals of the
  free globals, for a Jacobian that is mostly zero (the engine then never builds the dense
  one): the normal-equation blocks formed directly and eliminated by
  :func:`sim.lsq.normals.reduce_blocks`, or compiled, with the engine's singularity rule
  (:func:`sim.lsq.normals.inv_blocks`) on the point blocks.

The Jacobian sign convention: ``r ~ Jp dp + Jg dg`` (corrections that reduce the misclosure).

A **datum** picks the free globals (the rest stay at their given values) and optionally
constrains their corrections by ``C' dg = 0`` (``C`` ``(T, p, c)``: minimal constraints such
as Brown's ``x1 = x3 = 0, y4 = -y2`` or inner constraints); any other datum of the points
follows by an S-transformation (:mod:`sim.lsq.datum`).

**Fast paths**: a compiled kernel may be registered for a model class
(:func:`register_fast_path`); the engine calls it first and falls back to the generic loop
when it returns ``None`` (not applicable). Seed of the method: Brown 1968
(``004_f5bd9e86c308241f.txt``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np

__all__ = ["Linearization", "Datum", "Model", "register_fast_path", "fast_path"]


@dataclass
class Linearization:
    """Misclosures ``r`` (T, n, k), Jacobians ``Jp`` (T, n, k, d) | None and ``Jg``
    (T, n, k, q) | None, weights ``w`` broadcastable to (T, n, k) | None."""

    r: np.ndarray
    Jp: np.ndarray | None
    Jg: np.ndarray | None
    w: np.ndarray | None = None


class Model(Protocol):  # pragma: no cover - documentation of the interface
    point_dim: int
    n_global: int

    def linearize(
        self, points: np.ndarray, theta: np.ndarray, globals_needed: bool
    ) -> Linearization: ...

    def initial_points(self, theta: np.ndarray) -> np.ndarray: ...


@dataclass
class Datum:
    """Free globals (indices into ``theta``; None: all) and constraints ``C' dg = 0`` on their
    corrections: an array (T, p, c), a callable ``theta -> C`` evaluated at the start, or
    None (the free globals are determined by the observations)."""

    free: np.ndarray | None = None
    constraints: np.ndarray | Callable | None = None

    def free_index(self, q: int) -> np.ndarray:
        return np.arange(q) if self.free is None else np.asarray(self.free, int)

    def constraint_matrix(self, theta: np.ndarray) -> np.ndarray | None:
        C = self.constraints(theta) if callable(self.constraints) else self.constraints
        if C is None:
            return None
        C = np.asarray(C, float)
        return np.broadcast_to(C, (theta.shape[0],) + C.shape[-2:]) if C.ndim == 2 else C

    def n_constraints(self) -> int:
        C = self.constraints
        if C is None:
            return 0
        if callable(C):
            raise TypeError("n_constraints of a callable datum needs theta")
        return np.asarray(C).shape[-1]


_FAST: dict[type, Callable] = {}


def register_fast_path(model_cls: type, fn: Callable) -> None:
    """Register ``fn(model, theta, datum, tol, max_iter) -> Result | None`` for ``model_cls``:
    a compiled solver of the same adjustment, tried before the generic loop (points start
    from the kernel's own start, the same as ``model.initial_points``)."""
    _FAST[model_cls] = fn


def fast_path(model) -> Callable | None:
    return _FAST.get(type(model))
