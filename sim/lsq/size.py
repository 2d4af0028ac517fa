"""The one size rule of the engine: which problems take the sparse path.

A problem with at least :data:`SPARSE_MIN_UNKNOWNS` unknowns after the point blocks are
eliminated (where the model has point blocks) is solved on the sparse path: a network's normal
equations by :mod:`sim.lsq.sparse` (one factor per design), a block of independent models'
reduced normals by :mod:`sim.lsq.sparse_batch` (one order and pattern, a factor per trial).
Smaller problems keep the dense path, the reference of the tests (``tests/test_sparse*.py``).
The grid plate's combined adjustment (seed 001) has three unknowns after its point blocks are
eliminated, at every size: its point-by-point elimination is already the sparse factor of its
arrow-shaped normals (no fill), so it never needs the rule.

400 unknowns: below it a dense Cholesky of the (reduced) normals costs under a millisecond a
trial and the sparse path's ordering and symbolic analysis would cost more than they save.
"""

from __future__ import annotations

__all__ = ["SPARSE_MIN_UNKNOWNS", "use_sparse"]

#: unknowns (after the point blocks are eliminated) from which the sparse path is taken
SPARSE_MIN_UNKNOWNS = 400


def use_sparse(unknowns: int) -> bool:
    """Whether a problem of ``unknowns`` unknowns takes the sparse path."""
    return int(unknowns) >= SPARSE_MIN_UNKNOWNS
