"""``gama-local``'s rule for a set of directions (2.03, ``revision_observations``): a set of
fewer than two distinct targets is passive, left out of its adjustment and of its test of
absolute terms. One direction and its orientation add no degree of freedom and no precision,
so such a set is read and written as it is; a set whose directions all aim at one point (two
sightings of A) would leave ``gama-local`` with fewer degrees of freedom than this suite: the
reader (:mod:`sim.studies.network.gama_read`) refuses it and the export
(:mod:`sim.studies.network.gama`) does not write it, both in the words of :func:`one_target`."""

from __future__ import annotations

import numpy as np

__all__ = ["one_target", "one_target_set"]


def one_target(station: str, target: str, n: int) -> str:
    """Why ``n`` (>= 2) directions of one set at ``station``, all to ``target``, are not
    taken as they stand."""
    return (
        f"every direction of a set at {station!r} points to {target!r}: gama-local leaves a set "
        f"of fewer than two targets out of its adjustment; this suite would keep its {n} "
        f"directions (gama-local's degrees of freedom: {n - 1} fewer): give one, or add a "
        "direction to another point"
    )


def one_target_set(net) -> str | None:
    """:func:`one_target` of the network's first set of two directions or more that all aim
    at one point, or None (``net``: a :class:`~sim.studies.network.definition.Network`)."""
    d = np.flatnonzero(net.kind == 1)
    if d.size == 0:
        return None
    oset = net.oset[d]
    n_dir = np.bincount(oset)
    pairs = np.unique(np.stack([oset, net.j[d]]), axis=1)
    n_target = np.bincount(pairs[0], minlength=n_dir.size)
    bad = np.flatnonzero((n_dir >= 2) & (n_target == 1))
    if bad.size == 0:
        return None
    r = d[np.flatnonzero(oset == bad[0])[0]]
    return one_target(net.names[net.i[r]], net.names[net.j[r]], int(n_dir[bad[0]]))
