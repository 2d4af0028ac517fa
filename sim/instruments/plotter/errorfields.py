"""Smooth systematic error fields of a plotter used as a comparator, drawn at random.

Seed: ``000_668e60e68f004f98.txt`` (Wolf & Pearsall 1976, *The Kern PG-2 as a
Monocomparator*). The paper does not separate the sources of the PG-2's systematic errors but
lists what it expects them to stem from; each becomes a named component here, a displacement
field ``d(p)`` in micrometres at carrier position ``p = (X, Y)`` mm (origin at the carrier's
centre cross), with one amplitude (um) and random orientation, sign or phase per draw:

``plane_tilt``  non-parallel X-Y measurement plane and carrier-plate plane. To first order a
    tilt ``w`` of the plane seen through the projection centre is projective:
    ``d = A m (u cos psi + v sin psi) (u, v)`` with ``u, v = X, Y / R``.
``xy_scale``  different scales of the X and Y projection systems:
    ``d = A m s (-u, v) / 2`` (the common part of the scale is absorbed by the reduction).
``ways_nonorthogonal``  non-orthogonal ways of the coordinatograph: ``d = A m s (v, 0)``.
``ways_curvature``  curved ways: ``d = A m (cos g v^2, sin g u^2)`` -- the X way bowed
    along Y and the Y way along X.
``encoder_periodic``  periodic non-linearity of the encoders (screw or disc period
    ``lambda``): ``d = A m (sin(2 pi X / lambda + phi_x), sin(2 pi Y / lambda + phi_y))``.
``gimbal_eccentricity``  eccentricity ``e`` of the gimbal joint along the space rod that
    reaches the model point from the projection centre above ``c`` at height ``h``:
    ``d = A m s (p - c) / sqrt(|p - c|^2 + h^2)``. Mostly a change of scale; the rest is
    odd and cubic, largest at the edges.
``stress``  non-uniform, position-dependent stresses: a smooth Gaussian random field with
    correlation length ``L`` (random Fourier features, ``K`` waves), rms ``A`` per axis.

``m ~ U(lo, hi)`` (default 0.5-1.5) scales each amplitude per draw; ``psi, g, phi`` are
uniform angles, ``s = +-1``, ``c ~ N(0, sigma_c^2)`` per axis. A draw is a set of
per-trial parameters (leading axis ``T``); :func:`evaluate` turns it into displacements at
any points, so the same instrument can be read at grid, check and photo points.

Units: positions mm, displacements um, ``R = norm_mm`` (default 100 mm).

The ``stress`` sum runs compiled when numba is present (:mod:`sim.instruments.plotter.errorfield_kernel`: its
sines and cosines vectorised, equal to the NumPy path to rounding).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from sim.instruments.plotter import errorfield_kernel
from sim.lsq import compile

__all__ = ["COMPONENTS", "FieldSpec", "draw", "evaluate", "evaluate_components", "ar1_weights"]

#: component name -> the paper's wording of the source
COMPONENTS = {
    "plane_tilt": "non-parallel X-Y measurement plane and carrier-plate plane",
    "xy_scale": "non-uniform scale of the X and Y projection systems",
    "ways_nonorthogonal": "non-orthogonality of the ways of the X-Y coordinatograph",
    "ways_curvature": "curvature of the ways of the X-Y coordinatograph",
    "encoder_periodic": "non-linearities in the encoding system (periodic)",
    "gimbal_eccentricity": "eccentricities of the gimbal joints",
    "stress": "non-uniform stresses depending on the X-Y model position",
}


@dataclass(frozen=True)
class FieldSpec:
    """Amplitudes (um) and shape constants of the error-field families.

    Every ``*_um`` amplitude is the typical size of the component's displacement at 100 mm
    from the centre (``stress``: its rms per axis). Set one to 0 to switch it off.
    """

    plane_tilt_um: float = 0.0
    xy_scale_um: float = 0.0
    ways_nonorthogonal_um: float = 0.0
    ways_curvature_um: float = 0.0
    encoder_periodic_um: float = 0.0
    encoder_period_mm: float = 50.0
    gimbal_eccentricity_um: float = 0.0
    gimbal_height_mm: float = 200.0
    gimbal_centre_sigma_mm: float = 30.0
    stress_um: float = 0.0
    stress_length_mm: float = 60.0
    stress_waves: int = 16
    spread_lo: float = 0.5
    spread_hi: float = 1.5
    norm_mm: float = 100.0

    def amplitude(self, name: str) -> float:
        return float(getattr(self, f"{name}_um"))

    def scaled(self, factor: float) -> "FieldSpec":
        """The same families with every amplitude multiplied by ``factor``."""
        kw = {f.name: getattr(self, f.name) for f in fields(self)}
        for name in COMPONENTS:
            kw[f"{name}_um"] = kw[f"{name}_um"] * factor
        return FieldSpec(**kw)


def draw(spec: FieldSpec, rng: np.random.Generator, T: int) -> dict[str, dict[str, np.ndarray]]:
    """Draw ``T`` random fields of the families in ``spec``: ``{component: {param: (T, ...)}}``.

    Always draws every component (in a fixed order) so that switching one amplitude off does
    not change the random numbers of the others.
    """

    def mag(name):
        return spec.amplitude(name) * rng.uniform(spec.spread_lo, spec.spread_hi, T)

    def sign():
        return rng.choice(np.array([-1.0, 1.0]), T)

    def angle(*shape):
        return rng.uniform(0.0, 2 * np.pi, (T,) + shape)

    K = spec.stress_waves
    p = {
        "plane_tilt": {"a": mag("plane_tilt"), "psi": angle()},
        "xy_scale": {"a": mag("xy_scale") * sign()},
        "ways_nonorthogonal": {"a": mag("ways_nonorthogonal") * sign()},
        "ways_curvature": {"a": mag("ways_curvature"), "g": angle()},
        "encoder_periodic": {"a": mag("encoder_periodic"), "phi": angle(2)},
        "gimbal_eccentricity": {
            "a": mag("gimbal_eccentricity") * sign(),
            "c": rng.normal(0.0, spec.gimbal_centre_sigma_mm, (T, 2)),
        },
        "stress": {
            "a": np.full(T, spec.amplitude("stress")),
            "w": rng.normal(0.0, 1.0 / spec.stress_length_mm, (T, K, 2)),
            "phi": angle(K, 2),
            "b": rng.normal(0.0, 1.0, (T, K, 2)),
        },
    }
    return p


def _pts(pts: np.ndarray, T: int) -> np.ndarray:
    pts = np.asarray(pts, float)
    return np.broadcast_to(pts, (T,) + pts.shape[-2:]) if pts.ndim == 2 else pts


def evaluate_components(
    spec: FieldSpec, params: dict, pts: np.ndarray, skip_zero: bool = False
) -> dict[str, np.ndarray]:
    """Displacements ``(T, n, 2)`` um of each component at ``pts`` ``(T, n, 2)`` or ``(n, 2)`` mm.

    ``skip_zero`` leaves out the components whose amplitude in ``spec`` is zero.
    """
    T = len(params["plane_tilt"]["a"])
    P = _pts(pts, T)
    u = P / spec.norm_mm
    x, y = u[..., 0], u[..., 1]
    use = [k for k in COMPONENTS if not (skip_zero and spec.amplitude(k) == 0)]
    out = {}
    if "plane_tilt" in use:
        q = params["plane_tilt"]
        w = np.cos(q["psi"])[:, None] * x + np.sin(q["psi"])[:, None] * y
        out["plane_tilt"] = q["a"][:, None, None] * w[..., None] * u
    if "xy_scale" in use:
        q = params["xy_scale"]
        out["xy_scale"] = q["a"][:, None, None] * np.stack([-x, y], -1) / 2
    if "ways_nonorthogonal" in use:
        q = params["ways_nonorthogonal"]
        out["ways_nonorthogonal"] = q["a"][:, None, None] * np.stack([y, np.zeros_like(y)], -1)
    if "ways_curvature" in use:
        q = params["ways_curvature"]
        out["ways_curvature"] = q["a"][:, None, None] * np.stack(
            [np.cos(q["g"])[:, None] * y**2, np.sin(q["g"])[:, None] * x**2], -1
        )
    if "encoder_periodic" in use:
        q = params["encoder_periodic"]
        k = 2 * np.pi / spec.encoder_period_mm
        out["encoder_periodic"] = q["a"][:, None, None] * np.sin(k * P + q["phi"][:, None, :])
    if "gimbal_eccentricity" in use:
        q = params["gimbal_eccentricity"]
        r = P - q["c"][:, None, :]
        rod = np.sqrt(np.sum(r**2, -1, keepdims=True) + spec.gimbal_height_mm**2)
        out["gimbal_eccentricity"] = q["a"][:, None, None] * r / rod
    if "stress" in use:
        # sum_k b_kc cos(w_k . p + phi_kc) = cos(w.p) @ (b cos phi) - sin(w.p) @ (b sin phi)
        q = params["stress"]
        K = q["w"].shape[1]
        scale = q["a"] * np.sqrt(2.0 / K)
        if compile.available():  # one compiled pass, vectorised sine and cosine
            out["stress"] = errorfield_kernel.stress_field(P, q["w"], q["b"], q["phi"], scale)
        else:
            ph = np.matmul(P, q["w"].transpose(0, 2, 1))  # (T, n, K)
            bc, bs = q["b"] * np.cos(q["phi"]), q["b"] * np.sin(q["phi"])  # (T, K, 2)
            f = np.matmul(np.cos(ph), bc) - np.matmul(np.sin(ph), bs)
            out["stress"] = scale[:, None, None] * f
    return out


def evaluate(spec: FieldSpec, params: dict, pts: np.ndarray) -> np.ndarray:
    """Total displacement ``(T, n, 2)`` um of a drawn field at ``pts``."""
    comp = evaluate_components(spec, params, pts, skip_zero=True)
    if not comp:
        T = len(params["plane_tilt"]["a"])
        return np.zeros(_pts(pts, T).shape)
    return sum(comp.values())


def ar1_weights(dates_weeks, tau_weeks: float) -> np.ndarray:
    """Weights ``W (S, S)`` of a drifting field built from ``S`` independent draws ``G_j``.

    ``D_k = sum_j W[k, j] G_j`` is the AR(1) (Ornstein-Uhlenbeck) sequence
    ``D_0 = G_0``, ``D_k = r_k D_{k-1} + sqrt(1 - r_k^2) G_k`` with
    ``r_k = exp(-(t_k - t_{k-1}) / tau)`` for increasing dates ``t`` (weeks). Every ``D_k`` has
    the size of one draw and ``corr(D_j, D_k) = exp(-|t_k - t_j| / tau)``; ``tau = inf`` freezes
    the field.
    """
    t = np.asarray(dates_weeks, float)
    if np.any(np.diff(t) < 0):
        raise ValueError("dates must be increasing")
    S = len(t)
    W = np.zeros((S, S))
    W[0, 0] = 1.0
    for k in range(1, S):  # over dates (a handful), not trials
        r = np.exp(-(t[k] - t[k - 1]) / tau_weeks) if np.isfinite(tau_weeks) else 1.0
        W[k] = r * W[k - 1]
        W[k, k] = np.sqrt(max(1.0 - r * r, 0.0))
    return W
