"""The simulated measurements of a block of independent stereomodels: the models formed from
image coordinates, their arbitrary frames, and the image-pointing errors (signalised points,
digital and mechanical pugging, gross errors).

Seed: ``003_5ce730a990a7ebc5.txt`` (Agnard, Nolette & Gagnon). **Stereomodel formation**
(:func:`form_models`): normal-case photography with a known relative orientation, so the
model follows from the measured image coordinates by the parallax equations
``X = x' B / p``, ``Y = (y' + y'') B / (2 p)``, ``Z = -f B / p`` with ``p = x' - x''``. The
relative orientation is not re-estimated: the point errors reach the model through the exact
intersection, including the height amplification ``H / B`` and the correlation of pass points
shared by two models; the part of an image error a relative orientation would absorb
(y-parallax) is not removed, which makes the model slightly pessimistic. Each model is then
expressed in its own arbitrary frame by a random similarity (:func:`random_similarities`),
which the block adjustment (:mod:`sim.instruments.block.independent_models`) has to recover.

Units: metres for ground and model coordinates; image coordinates in mm, errors in um.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.geometry import rotation

__all__ = [
    "form_models",
    "random_similarities",
    "to_model_frame",
    "noisy_models",
    "pointing_errors",
]


def form_models(xl_mm: np.ndarray, xr_mm: np.ndarray, focal_mm: float, base_m: float) -> np.ndarray:
    """Model coordinates (m, origin at the left projection centre, ground-parallel axes)
    from measured image coordinates of the left and right photo, ``(..., 2)`` each, by the
    parallax equations of normal-case photography. Returns ``(..., 3)``."""
    p = xl_mm[..., 0] - xr_mm[..., 0]
    k = base_m / p
    return np.stack(
        [xl_mm[..., 0] * k, 0.5 * (xl_mm[..., 1] + xr_mm[..., 1]) * k, -focal_mm * k], -1
    )


def random_similarities(
    rng: np.random.Generator,
    shape: tuple,
    *,
    tilt_rad: float = 0.02,
    scale_range: tuple[float, float] = (0.5, 2.0),
    shift_m: float = 1000.0,
):
    """Arbitrary model frames: ``(s, R, t)`` with any heading, small tilts, a scale and a
    shift, shapes ``shape``, ``shape + (3, 3)``, ``shape + (3,)``."""
    om = rng.normal(0.0, tilt_rad, shape)
    ph = rng.normal(0.0, tilt_rad, shape)
    ka = rng.uniform(-np.pi, np.pi, shape)
    s = np.exp(rng.uniform(np.log(scale_range[0]), np.log(scale_range[1]), shape))
    t = rng.normal(0.0, shift_m, shape + (3,))
    return s, rotation(om, ph, ka), t


def to_model_frame(ground_xyz: np.ndarray, obs_model: np.ndarray, s, R, t) -> np.ndarray:
    """Express ground-frame model points ``(T, K, 3)`` in the frames of their models:
    ``x = R^T (X - t) / s`` with ``s (T, M)``, ``R (T, M, 3, 3)``, ``t (T, M, 3)``."""
    d = ground_xyz - t[:, obs_model]
    return np.einsum("tkji,tkj->tki", R[:, obs_model], d) / s[:, obs_model, None]


def noisy_models(block, rng: np.random.Generator, trials: int, sigma_m=0.0):
    """Model coordinates of every observation of ``block`` (:mod:`sim.instruments.block.layout`) in
    random model frames, for checks of the adjustment: each model point formed from its
    error-free image coordinates, shifted to the ground frame, plus Gaussian errors of
    ``sigma_m`` (m; a scalar or one per axis), then expressed in frames of
    :func:`random_similarities`. Returns ``xm (T, K, 3)`` and the frames ``(s, R, t)``."""
    xl = block.image_coords(block.obs_left, block.obs_point)
    xr = block.image_coords(block.obs_right, block.obs_point)
    G = (
        form_models(xl, xr, block.focal_mm, block.base_m)
        + block.photos.reshape(-1, 3)[block.obs_left]
    )
    G = G + rng.normal(0.0, 1.0, (trials,) + G.shape) * np.asarray(sigma_m, float)
    s, R, t = random_similarities(rng, (trials, block.n_models))
    return to_model_frame(G, block.obs_model, s, R, t), (s, R, t)


def pointing_errors(
    rng: np.random.Generator,
    trials: int,
    obs_left: np.ndarray,
    obs_right: np.ndarray,
    obs_point: np.ndarray,
    photos_per_strip: int,
    n_strips: int,
    n_points: int,
    *,
    mark_um: float,
    parallax_um: float,
    digital: np.ndarray | None = None,
    mechanical: np.ndarray | None = None,
    transfer_um: float = 0.0,
    recentre_um: float = 0.0,
    gross_rate: float = 0.0,
    gross_um: tuple[float, float] = (0.0, 0.0),
):
    """Image-measurement errors (um) on the left and right photo of every model point.

    Observation ``k`` (a point in a model) is measured on the flat photo indices
    ``obs_left[k]`` and ``obs_right[k]`` (``strip * photos_per_strip + i``). Errors are image
    shifts; in normal-case photography a shift of the pointed ground detail moves its image
    by the same vector on every photo.

    * Signalised points (default): re-pointed in every model. A setting error common to both
      photos, N(0, ``mark_um``) per coordinate, plus a stereo (parallax) setting error:
      N(0, ``parallax_um / sqrt(2)``) on each photo, so the x-parallax error has sigma
      ``parallax_um``.
    * Digital pugging (``digital`` (P,) True): the pixel marked on a photo is stored and
      reused, so a photo shared by two models has the very same image coordinates in both;
      the next photo of the strip is pointed stereoscopically to the stored pixel with a
      parallax error N(0, ``parallax_um``). Along a strip the errors are a random walk over
      the photos that see the point, starting from a setting error N(0, ``mark_um``); across
      strips the point is marked afresh.
    * Mechanical pugging (``mechanical`` (P,) True): a hole drilled on each photo (transfer
      error N(0, ``transfer_um``) per photo, shared by the models using the photo),
      re-centred in every model (N(0, ``recentre_um``) per photo and measurement); with
      probability ``gross_rate`` per model point the hole is missed on one of the two photos
      (white area, poor contrast of the scan) by a distance uniform in ``gross_um``.

    Returns ``(e_left, e_right, gross)``: (T, K, 2), (T, K, 2) and (T, K) bool.
    """
    K = obs_point.size
    T = trials
    mu = rng.normal(0.0, mark_um, (T, K, 1, 2))
    e = mu + rng.normal(0.0, parallax_um / np.sqrt(2.0), (T, K, 2, 2))
    gross = np.zeros((T, K), bool)
    S, F, P = n_strips, photos_per_strip, n_points
    strip = obs_left // F
    if digital is not None and np.any(digital):
        dk = np.asarray(digital, bool)[obs_point]
        first = np.full((S, P), F, np.intp)
        np.minimum.at(first, (strip[dk], obs_point[dk]), obs_left[dk] % F)
        walk = np.cumsum(rng.normal(0.0, parallax_um, (T, S, F, P, 2)), axis=2)
        mark = rng.normal(0.0, mark_um, (T, S, P, 2))
        sk, pk = strip[dk], obs_point[dk]
        start = mark[:, sk, pk] - walk[:, sk, first[sk, pk], pk]
        e[:, dk, 0] = start + walk[:, sk, obs_left[dk] % F, pk]
        e[:, dk, 1] = start + walk[:, sk, obs_right[dk] % F, pk]
    if mechanical is not None and np.any(mechanical):
        mk = np.asarray(mechanical, bool)[obs_point]
        n = int(mk.sum())
        hole = rng.normal(0.0, transfer_um, (T, S * F, P, 2))
        rec = rng.normal(0.0, recentre_um, (T, n, 2, 2))
        hit = rng.random((T, n)) < gross_rate
        side = rng.integers(0, 2, (T, n))
        ang = rng.uniform(0, 2 * np.pi, (T, n))
        mag = rng.uniform(gross_um[0], gross_um[1], (T, n)) * hit
        g = np.stack([mag * np.cos(ang), mag * np.sin(ang)], -1)  # (T, n, 2)
        for c, hole_photo in ((0, obs_left[mk]), (1, obs_right[mk])):
            e[:, mk, c] = (
                hole[:, hole_photo, obs_point[mk]]
                + rec[:, :, c]
                + np.where((side == c)[..., None], g, 0.0)
            )
        gross[:, mk] = hit
    return e[:, :, 0], e[:, :, 1], gross
