"""What makes a large network's normals singular, named for ``sim check``.

The sparse path (:mod:`sim.studies.network.sparse_analysis`) factorises the normals once and,
when they are singular, knows only that a pivot failed. A user needs the point: this module
looks for the two usual causes, cheaply at any size (linear in the observations):

* an unknown no observation determines (a zero diagonal of the normals: a point whose only
  sights are distances along one line, say);
* a part of the network tied to the datum by no observation (a connected component of the
  graph of points and observations that holds no fixed or observed point, and no inner-datum
  point, nor, in a network with no point held, a point of ``datum.constraints``): the
  nearest-neighbour observations of a random network leave such islands.

Units: those of the network (mm, rad); no model of its own.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from sim.studies.network.definition import Network
from sim.studies.network.model import jacobian_sparse, pattern

__all__ = ["singular_cause", "loose_part", "unreached", "unreached_message"]


def _unobserved(net: Network, free: np.ndarray) -> str:
    cols = pattern(net)
    _, vals = jacobian_sparse(net, net.theta_true()[None])
    w = np.where(cols >= 0, (vals[0] / net.sigma[:, None]) ** 2, 0.0)
    diag = np.zeros(net.q + 1)
    np.add.at(diag, np.where(cols >= 0, cols, net.q), w)
    zero = [g for g in free if not diag[g] > 0]
    if not zero:
        return ""
    g = int(zero[0])
    what = (
        f"point {net.names[g // 2]!r} ({'xy'[g % 2]})"
        if g < 2 * net.n
        else net.parameter_names()[g - 2 * net.n]
    )
    return f"{what} is determined by no observation ({len(zero)} such unknowns)"


def _constrained(net: Network, cfg: dict) -> np.ndarray:
    """The points ``datum.constraints`` name (their coefficients hold the part they lie in)."""
    names = {k.rsplit(".", 1)[0] for rec in cfg["datum.constraints"] for k in rec}
    return np.array([i for i, x in enumerate(net.names) if x in names], int)


def _islands(net: Network, cfg: dict) -> str:
    n = net.n
    anchored = net.role != 0
    inner = cfg["datum.kind"] == "inner"
    held = cfg["datum.kind"] == "constraints" and not anchored.any()
    a, b = [net.i], [np.where(net.j >= 0, net.j, net.i)]
    a.append(net.i)
    b.append(np.where(net.k >= 0, net.k, net.i))
    a.append(np.flatnonzero(anchored))
    b.append(np.full(int(anchored.sum()), n))  # node n: the datum
    a, b = np.concatenate(a), np.concatenate(b)
    graph = coo_matrix((np.ones(a.size), (a, b)), shape=(n + 1, n + 1))
    _, label = connected_components(graph, directed=False)
    loose = label[:n] != label[n]
    # the inner datum of a network no point holds holds one part: the largest loose one; with
    # points held it removes only the defect they leave (the rotation about one), not a
    # part's own (a part with no tie to two fixed points was "a rank defect of 3 that the
    # datum (0 constraints) does not cover", unnamed)
    if inner and loose.any() and not anchored.any():
        loose &= label[:n] != np.bincount(label[:n][loose]).argmax()
    if held:  # minimal constraints of a network with no point held hold the parts they name
        loose &= ~np.isin(label[:n], label[_constrained(net, cfg)])
    loose = np.flatnonzero(loose)
    if not loose.size:
        return ""
    parts = np.unique(label[loose])
    sizes = [int((label[:n] == p).sum()) for p in parts]
    part = parts[int(np.argmin(sizes))]
    names = [net.names[p] for p in np.flatnonzero(label[:n] == part)]
    shown = ", ".join(repr(x) for x in names[:3]) + (
        f" and {len(names) - 3} more" if len(names) > 3 else ""
    )
    return (
        f"points {shown} are tied to the datum by no observation ({len(parts)} such "
        f"part{'s' if len(parts) > 1 else ''} of the network, {loose.size} points in all)"
    )


def singular_cause(net: Network, cfg: dict, free: np.ndarray) -> str:
    """The first cause found of singular normals (see the module doc), or ""."""
    return _unobserved(net, free) or _islands(net, cfg)


def loose_part(net: Network, cfg: dict) -> str:
    """A part of the network tied to the datum by no observation, named (see the module
    doc), or "": minimal constraints hold the network's datum defect, not a part's own."""
    return _islands(net, cfg)


def unreached(net: Network) -> np.ndarray:
    """The points no observation reaches (neither station, target nor sight of one, and no
    observed coordinate), in the network's order."""
    seen = np.zeros(net.n, bool)
    for a in (net.i, net.j, net.k):
        seen[a[a >= 0]] = True
    return np.flatnonzero(~seen)


def unreached_message(net: Network, points: np.ndarray, where: str) -> str:
    """One line naming the declared ``points`` no observation reaches (``where``: the file or
    key that declares them): a free one's position cannot be estimated, a fixed one holds
    nothing of the network in place."""
    fixed = bool(np.all(net.role[points] == 1))
    names = ", ".join(repr(net.names[p]) for p in points[:3])
    more = f" and {len(points) - 3} more" if len(points) > 3 else ""
    one = len(points) == 1
    what = f"{'fixed ' if fixed else ''}point{'' if one else 's'} {names}{more}"
    verb = "is" if one else "are"
    it = "it" if one else "them"
    if fixed:
        why = f"{'it holds' if one else 'they hold'} nothing of the network in place"
        fix = f"observe {it}, or hold the network by points it observes"
    else:
        why = f"{'its position' if one else 'their positions'} cannot be estimated"
        fix = f"observe {it} or remove {it}"
    return f"{what} {verb} declared in {where} but no observation reaches {it}: {why}; {fix}"
