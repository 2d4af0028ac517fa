"""Error budget of the multilaterative comparator: parameterised instrument error sources.

Seed: ``004_f5bd9e86c308241f.txt`` (Brown 1968, section *Calibration*). Besides the setting
error, the paper names three critical elements; each is modelled here as an error added to
the simulated scale readings (all amplitudes in um, readings in mm):

* **scale** -- every reading inherits the error of the graduation it is referred to, the whole
  millimetre ``floor(r)``. After calibration against the master the graduation errors are
  known to ``sigma_grad`` (paper: 0.54 um); the residual error of each of the 262
  graduations is drawn once per simulated instrument, N(0, sigma_grad^2), and shared by all
  readings on that graduation.
* **micrometer screw** -- the fractional millimetre ``f = r - floor(r)`` is set with the
  screw. Residual calibration error: a smooth random function of ``f`` with rms
  ``sigma_screw`` (paper: 0.3 um), a Fourier series of ``harmonics`` terms over the 1 mm
  range. Uncorrected periodic error from drum eccentricity: ``A sin(2 pi f / pitch + phi)``
  (paper: up to 0.5 um; the pitch is not printed).
* **uncalibrated scale** (``scale_spec``) -- the same model with the specification's 1 um.
* **ball sphericity** -- the ball's out-of-roundness (paper: 0.25 um) as a second-harmonic
  radial error over the arm's direction, like the wobble.
* **pivot wobble** -- a radial error depending on the direction ``psi`` of the measuring arm
  in the comparator frame, ``W cos(m (psi - psi0))`` (paper: up to 2 um at 3 kg thrust, none
  at 6 kg). The first harmonic ``m = 1`` is a fixed displacement of the pivot and is absorbed
  by the station coordinates; ``m >= 2`` is not.

Each source draws its own random instrument per trial, so a Monte Carlo over trials averages
over instruments built to the stated tolerances.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "graduation_error",
    "screw_error",
    "periodic_error",
    "wobble_error",
    "SOURCES",
    "source_error",
]

N_GRAD = 263  # graduations 0..261 mm plus one spare for readings at the very end


def graduation_error(r_mm: np.ndarray, rng: np.random.Generator, sigma_um: float) -> np.ndarray:
    """Error (um) of each reading ``r_mm`` ``(T, ...)`` from its graduation ``floor(r)``."""
    T = r_mm.shape[0]
    g = rng.normal(0.0, sigma_um, size=(T, N_GRAD))
    idx = np.clip(np.floor(r_mm).astype(int), 0, N_GRAD - 1).reshape(T, -1)
    return np.take_along_axis(g, idx, axis=1).reshape(r_mm.shape)


def screw_error(
    r_mm: np.ndarray, rng: np.random.Generator, sigma_um: float, harmonics: int = 3
) -> np.ndarray:
    """Smooth residual screw error (um): random Fourier series in ``f = r mod 1 mm`` with
    expected rms ``sigma_um`` over the range."""
    T = r_mm.shape[0]
    f = (r_mm - np.floor(r_mm)).reshape(T, -1)
    m = np.arange(1, harmonics + 1)
    ab = rng.normal(0.0, sigma_um / np.sqrt(harmonics), size=(T, 2, harmonics))
    ang = 2 * np.pi * f[:, :, None] * m
    e = (ab[:, None, 0] * np.cos(ang) + ab[:, None, 1] * np.sin(ang)).sum(-1)
    return e.reshape(r_mm.shape)


def periodic_error(
    r_mm: np.ndarray, rng: np.random.Generator, amp_um: float, pitch_mm: float
) -> np.ndarray:
    """Drum eccentricity: ``amp sin(2 pi f / pitch + phi)`` (um), random phase per trial."""
    T = r_mm.shape[0]
    phi = rng.uniform(0, 2 * np.pi, size=(T,) + (1,) * (r_mm.ndim - 1))
    f = r_mm - np.floor(r_mm)
    return amp_um * np.sin(2 * np.pi * f / pitch_mm + phi)


def wobble_error(
    psi: np.ndarray, rng: np.random.Generator, amp_um: float, harmonic: int = 2
) -> np.ndarray:
    """Radial pivot wobble ``amp cos(m (psi - psi0))`` (um) for arm directions ``psi`` (rad)."""
    T = psi.shape[0]
    psi0 = rng.uniform(0, 2 * np.pi, size=(T,) + (1,) * (psi.ndim - 1))
    return amp_um * np.cos(harmonic * (psi - psi0))


SOURCES = ("scale", "scale_spec", "screw", "drum_periodic", "wobble", "wobble_h1", "sphericity")


def source_error(
    name: str, r_mm: np.ndarray, psi: np.ndarray, rng: np.random.Generator, cfg: dict
) -> np.ndarray:
    """Error (um) of source ``name`` with the amplitudes of the flat config ``cfg``
    (keys ``budget.*``); every source of :data:`SOURCES`."""
    if name == "scale":
        return graduation_error(r_mm, rng, cfg["budget.graduation_um"])
    if name == "scale_spec":
        return graduation_error(r_mm, rng, cfg["budget.scale_spec_um"])
    if name == "sphericity":
        return wobble_error(psi, rng, cfg["budget.sphericity_um"], 2)
    if name == "screw":
        return screw_error(r_mm, rng, cfg["budget.screw_um"], cfg["budget.screw_harmonics"])
    if name == "drum_periodic":
        return periodic_error(r_mm, rng, cfg["budget.drum_periodic_um"], cfg["budget.pitch_mm"])
    if name == "wobble":
        return wobble_error(psi, rng, cfg["budget.wobble_um"], cfg["budget.wobble_harmonic"])
    if name == "wobble_h1":
        return wobble_error(psi, rng, cfg["budget.wobble_um"], 1)
    raise ValueError(f"unknown error source {name!r}")
