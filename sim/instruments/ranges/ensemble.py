"""The affine-invariant ensemble sampler of ``emcee`` (stretch move), step for step, vectorised.

Model: Goodman & Weare (2010)'s stretch move with the red-blue split of Foreman-Mackey et al.
(2013), exactly as ``emcee.EnsembleSampler`` runs it with its default move
(``StretchMove(a=2)``, random split) and a vectorised log-probability: the same calls on the
same legacy ``RandomState`` in the same order (the move choice, the shuffle of the split,
the stretch factors, the partners, one uniform per walker for the acceptance), the same
arithmetic, so the chain, the log-probabilities and the acceptance are identical to emcee's
for the same seed (a test compares them bit for bit). What it leaves out is emcee's per-walker
Python bookkeeping (a Python loop over the walkers for the acceptance, a ``float`` per
walker, the generator state copied every step), which costs about a millisecond per step --
more than the log-probabilities of the suite's posteriors. The autocorrelation time is
taken about the ensemble's mean with emcee's window (:mod:`.autocorr`).

Used by :func:`sim.instruments.ranges.bayes.run_emcee` for the cross-checks of seed ``004_f5bd9e86c308241f.txt``
(Brown 1968) and seed ``001`` (the two-plate variance components). Units: those of the
parameters.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

__all__ = ["stretch_chain", "A_STRETCH"]

#: emcee's default stretch scale
A_STRETCH = 2.0


def _independent(coords: np.ndarray) -> bool:
    """emcee's check that the initial walkers span the space (``walkers_independent``)."""
    if not np.all(np.isfinite(coords)):
        return False
    C = coords - np.mean(coords, axis=0)[None, :]
    cmax = np.amax(np.abs(C), axis=0)
    if np.any(cmax == 0):
        return False
    C /= cmax
    C /= np.sqrt(np.sum(C**2, axis=0))
    return np.linalg.cond(C.astype(float)) <= 1e8


def _log_prob(fn: Callable[[np.ndarray], np.ndarray], x: np.ndarray) -> np.ndarray:
    if not np.isfinite(x).all():
        raise ValueError(
            "At least one parameter value was " + ("infinite" if np.isinf(x).any() else "NaN")
        )
    lp = np.asarray(fn(x), float).reshape(len(x))
    if np.isnan(lp).any():
        raise ValueError("Probability function returned NaN")
    return lp


def stretch_chain(
    log_prob: Callable[[np.ndarray], np.ndarray],
    p0: np.ndarray,
    steps: int,
    random: np.random.RandomState,
    a: float = A_STRETCH,
):
    """Run ``steps`` stretch-move steps from ``p0`` (walkers, d).

    log_prob : ``(m, d) -> (m,)``, vectorised over walkers; random : the legacy generator
    (emcee's ``sampler._random``), advanced in place. Returns ``(chain (steps, W, d),
    log_prob (steps, W), accepted (W,) counts)``.
    """
    coords = np.array(p0, float, copy=True)
    W, d = coords.shape
    if W < 2 * d:
        raise RuntimeError(
            "It is unadvisable to use a red-blue move with fewer walkers than "
            "twice the number of dimensions."
        )
    if not _independent(coords):
        raise ValueError(
            "Initial state has a large condition number. Make sure that your "
            "walkers are linearly independent for the best performance"
        )
    lp = _log_prob(log_prob, coords)
    chain = np.empty((steps, W, d))
    lps = np.empty((steps, W))
    n_acc = np.zeros(W, int)
    parity = np.arange(W) % 2
    for i in range(steps):
        random.random_sample()  # emcee's choice of its one move (choice(moves, p=...))
        accepted = np.zeros(W, bool)
        inds = parity.copy()
        random.shuffle(inds)
        for split in range(2):
            j = np.flatnonzero(inds == split)  # this half, in walker order
            s, c = coords[j], coords[inds != split]
            Ns, Nc = len(s), len(c)
            zz = ((a - 1.0) * random.rand(Ns) + 1) ** 2.0 / a
            factors = (d - 1.0) * np.log(zz)
            cr = c[random.randint(Nc, size=(Ns,))]
            q = cr - (cr - s) * zz[:, None]
            new_lp = _log_prob(log_prob, q)
            acc = factors + new_lp - lp[j] > np.log(random.rand(Ns))
            accepted[j] = acc
            coords[j[acc]] = q[acc]
            lp[j[acc]] = new_lp[acc]
        chain[i] = coords
        lps[i] = lp
        n_acc += accepted
    return chain, lps, n_acc
