"""Projection centres as model points: an option of the independent-model block.

Seed: ``003_5ce730a990a7ebc5.txt`` (Agnard, Nolette & Gagnon), whose program is "the
least-squares block adjustment of independent stereoscopic models SPACE-M". SPACE-M carries
each model's two projection centres as model points: "The perspective centres are treated in
exactly the same manner as any other photogrammetric points in the stereomodels" (Blais's
description of the formulation). A photo shared by two consecutive models of a strip has one
centre, so the centres tie consecutive models like a pass point at flying height, which is
what transfers height and tilt along a strip between sparse control.

The option adds, to a block of :mod:`sim.instruments.block.layout`, one point per photo (its
projection centre, ground coordinates in metres) after the block's own points, and one
observation per model and photo (the left and right centre of each model). In the model
frame of :mod:`sim.instruments.block.pointing` (origin at the left centre, ground-parallel
axes, the known base) the centres are ``(0, 0, 0)`` and ``(B, 0, 0)``; "in exactly the same
manner as any other point" is read as: the same weight in the adjustment, and an error of the
size of a model point's (``sigma_m`` per axis, drawn independently per model: the model's
relative orientation places its centres no better than its points). The tie's strength
follows that error: in a 2 x 8 block with five control points, centres as precise as the
model points bring the check-point height rms from 0.7-2.4 m to about 0.3-0.5 m, centres four
times worse to about 0.5-0.9 m (``agnard_block``'s region, docs/referee-reading.md).
Without the option the block is unchanged (the default everywhere).

Arrays in, arrays out: model coordinates ``(T, K, 3)`` with a leading trial axis.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from sim.instruments.block.layout import Block
from sim.instruments.block.pointing import to_model_frame

__all__ = ["Centred", "with_centres", "centre_models"]


@dataclass(frozen=True)
class Centred:
    """A block with its projection centres as points.

    block : the block with the ``n_photo`` centres appended to its points (indices
    ``base.n_points + flat photo index``) and their observations merged, sorted by model;
    order : (K + Kc,) where each merged observation comes from in the concatenation
    ``[base observations, centre observations]``; n_base_obs : K; n_base_points : P."""

    block: Block
    order: np.ndarray
    n_base_obs: int
    n_base_points: int

    @property
    def centre_obs(self) -> tuple[np.ndarray, np.ndarray]:
        """(model, flat photo index) of the centre observations, in concatenation order."""
        k = np.arange(self.n_base_obs, self.order.size)
        inv = np.argsort(self.order)[k]
        b = self.block
        return b.obs_model[inv], b.obs_point[inv] - self.n_base_points

    def merge(self, xm: np.ndarray, xc: np.ndarray) -> np.ndarray:
        """Model coordinates of the merged observations from the block's ``xm`` (T, K, 3) and
        the centres' ``xc`` (T, Kc, 3)."""
        return np.concatenate([xm, xc], axis=1)[:, self.order]

    def extend(self, X: np.ndarray) -> np.ndarray:
        """Points (T, P, 3) of the base block extended by the true centres (approximations)."""
        c = self.block.points[self.n_base_points :]
        return np.concatenate([X, np.broadcast_to(c, (X.shape[0],) + c.shape)], axis=1)


def with_centres(block: Block) -> Centred:
    """The block with each model's left and right projection centres as model points."""
    S, M = block.strips, block.models
    m = np.arange(S * M)
    left = (m // M) * (M + 1) + m % M
    c_model = np.repeat(m, 2)
    c_photo = np.stack([left, left + 1], -1).ravel()
    P, K = block.n_points, block.obs_model.size
    model = np.concatenate([block.obs_model, c_model])
    point = np.concatenate([block.obs_point, P + c_photo])
    order = np.lexsort((point, model))
    b = replace(
        block,
        points=np.vstack([block.points, block.photos.reshape(-1, 3)]),
        obs_model=model[order],
        obs_point=point[order],
        obs_left=np.concatenate([block.obs_left, np.repeat(left, 2)])[order],
        obs_right=np.concatenate([block.obs_right, np.repeat(left + 1, 2)])[order],
    )
    return Centred(b, order, K, P)


def centre_models(cb: Centred, rng: np.random.Generator, s, R, t, sigma_m=0.0) -> np.ndarray:
    """Model coordinates (T, Kc, 3) of the centre observations in the models' frames
    ``(s, R, t)`` (:func:`sim.instruments.block.pointing.random_similarities`): the true
    centre plus N(0, ``sigma_m``) per axis (a scalar or one per axis, m), drawn per model."""
    model, photo = cb.centre_obs
    G = cb.block.photos.reshape(-1, 3)[photo]
    G = G + rng.normal(0.0, 1.0, (s.shape[0],) + G.shape) * np.asarray(sigma_m, float)
    return to_model_frame(G, model, s, R, t)
