"""A rank defect of a network's normals that its datum does not cover, named for ``sim check``:
the distances' constant and scale (``network.estimate_constant``, ``network.estimate_scale``)
that no observation tells apart, the sigmas when the datum holds the defect
(:func:`sim.studies.network.weights.refuse_weights`), else the defect's size and what to do
about it in the datum kind given. Units: those of the network (mm, rad); no model of its own.
"""

from __future__ import annotations

import numpy as np

from sim.mc.config import ConfigError
from sim.studies.network.analysis import defect_words, held_defect
from sim.studies.network.model import computed
from sim.studies.network.weights import covered, equilibrated, refuse_weights

__all__ = ["refuse_defect"]


def _parameters(net, A: np.ndarray, free: np.ndarray, rank: int) -> None:
    """A rank defect among the distances' constant and scale (and orientations) alone, no
    coordinate in it: no datum covers it, so name the keys that estimate them."""
    _, _, vt = np.linalg.svd(A, full_matrices=False)
    w = (vt[rank:] ** 2).sum(axis=0)
    involved = free[w > 1e-6 * w.max()] if w.size else free[:0]
    if not involved.size or involved.min() < 2 * net.n:
        # coordinates move (a datum defect), or fewer observations than unknowns (the
        # reduced SVD holds no null space to look at): the caller's message
        return
    names = [net.parameter_names()[g - 2 * net.n] for g in involved]
    pairs = (("network.estimate_constant", net.i_constant), ("network.estimate_scale", net.i_scale))
    keys = [k for k, g in pairs if g in involved]
    raise ConfigError(
        keys[0] if keys else "network.observations",
        f"the {' and the '.join(names)} cannot be told apart by these observations (a rank "
        f"defect of {len(free) - rank} among them, no coordinate in it: no datum covers it): "
        + ("estimate fewer of them, or " if keys else "")
        + "add observations of other lengths or directions",
    )


#: what to do about a rank defect the datum leaves, by datum kind (never the datum it has)
_DEFECT_ADVICE = {
    "fixed": "fix points, add observations, or use datum.kind = inner",
    "constraints": "add constraints or observations, or use datum.kind = inner",
    "inner": "add observations that tie every point to the rest, or fix points",
}


def refuse_defect(net, dt, key: str, kind: str = "fixed") -> None:
    free = dt.free_index(net.q)
    _, J = computed(net, net.theta_true()[None], jac=True)
    A = J[0][:, free] / net.sigma[:, None]
    B = equilibrated(A)
    sv = np.linalg.svd(B, compute_uv=False)
    rank = int((sv > sv[0] * 1e-10).sum()) if sv.size else 0
    if sv.size and rank == len(free):
        refuse_weights(net, A, free, key)
    C = dt.constraint_matrix(net.theta_true()[None])
    c = 0 if C is None else C.shape[-1]
    if sv.size and rank < len(free) and covered(B, None if C is None else C[0]):
        refuse_weights(net, A, free, key, C[0])  # the datum holds the defect: the sigmas
    if sv.size and rank < len(free):
        _parameters(net, A, free, rank)
    advice = _DEFECT_ADVICE.get(kind, _DEFECT_ADVICE["fixed"])
    H = held_defect(net, free)
    if len(free) - rank > H.shape[1]:  # more than a datum can hold
        advice = _DEFECT_ADVICE["inner"]  # (inner or constraints: the same refusal again)
    # a datum's motions alone and no constraint: say which (distances alone about one fixed
    # point leave its rotation; it said "a rank defect of 1" and left the user to guess)
    what = f": {defect_words(H, net.role)}" if C is None and len(free) - rank == H.shape[1] else ""
    raise ConfigError(
        key,
        f"the network has a rank defect of {len(free) - rank} ({len(free)} "
        f"unknowns, rank {rank}{what}) that the datum ({c} constraints) does not cover: " + advice,
    )
