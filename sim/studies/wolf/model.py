"""The simulated PG-2: error field over dates, placements, quantised readings, reductions.

Wolf & Pearsall 1976 (seed ``000_668e60e68f004f98.txt``). A plotter whose measuring system
carries a smooth systematic error field (:mod:`sim.instruments.plotter.errorfields`: the six sources the paper
lists), read in *counts* of about 4 um, ``n`` readings per point averaged, approached from one
side (backlash ``+b/2``). Dates and drift: the field of date ``t`` is
``sqrt(1 - f) F + sqrt(f) D(t)`` with ``D`` an AR(1) sequence of independent draws
(:func:`sim.instruments.plotter.errorfields.ar1_weights`, time constant ``tau``), plus a fresh small
*restitution* field at every placement of a plate. Each calibration set is reduced with the
paper's non-redundant two-point transformation and the polynomial is fitted to the pooled sets
(:mod:`sim.instruments.plotter.polynomial`). Coordinates in mm, displacements and discrepancies in um.

:func:`place` draws everything random about one reading of a plate once (placement, field
and restitution displacements, standard-normal pointing noise for up to ``nmax`` readings,
approach signs); :func:`read_placed` turns it into averaged counts for a given pointing sigma,
number of readings, approach and common factor on the field amplitudes (the field is linear
in its amplitudes). So sweeps over these inputs use common random numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from sim.instruments import transforms2d as tf
from sim.instruments.plotter import errorfields as ef
from sim.instruments.plotter import polynomial as pl

AXES = ("x", "y")
STATS = ("max", "rms", "mean")
#: the field components a cubic polynomial cannot fit (periodic and short-wave); with the
#: restitution field they are scaled together by a region cell's ``noncubic_factor``
NONCUBIC = ("encoder_periodic", "stress")


def field_spec(cfg: dict, **over) -> ef.FieldSpec:
    kw = {name + "_um": cfg[f"field.{name}_um"] for name in ef.COMPONENTS}
    kw.update(
        encoder_period_mm=cfg["field.encoder_period_mm"],
        gimbal_height_mm=cfg["field.gimbal_height_mm"],
        stress_length_mm=cfg["field.stress_length_mm"],
        spread_lo=cfg["field.spread"][0],
        spread_hi=cfg["field.spread"][1],
    )
    kw.update(over)
    return ef.FieldSpec(**kw)


def restitution_spec(cfg: dict) -> ef.FieldSpec:
    return ef.FieldSpec(
        stress_um=cfg["field.restitution_um"], stress_length_mm=cfg["field.restitution_length_mm"]
    )


# ----------------------------------------------------------------------------- simulation core


class Instrument:
    """``T`` simulated plotters: a static field, a drifting field over given dates, and the
    reading process. ``disp(k, P)`` is the systematic displacement (um) on date ``k``."""

    def __init__(
        self,
        cfg: dict,
        rng: np.random.Generator,
        T: int,
        dates_weeks,
        drift_fraction: float | None = None,
    ):
        self.cfg, self.T = cfg, T
        self.spec = field_spec(cfg)
        self.rspec = restitution_spec(cfg)
        self.static = ef.draw(self.spec, rng, T)
        self.dates = np.asarray(dates_weeks, float)
        self.drift = [ef.draw(self.spec, rng, T) for _ in self.dates]
        self.W = ef.ar1_weights(self.dates, cfg["field.drift_tau_weeks"])
        self.f = cfg["field.drift_fraction"] if drift_fraction is None else drift_fraction

    def _field(self, params: dict, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A drawn field at ``P``: the total (as :func:`ef.evaluate`, bit for bit) and its part
        a cubic cannot fit (``NONCUBIC``: the encoder's periodic error and the stresses)."""
        comp = ef.evaluate_components(self.spec, params, P, skip_zero=True)
        if not comp:
            z = np.zeros(np.broadcast_shapes(np.shape(P), (self.T, 1, 2)))
            return z, z
        nc = [v for k, v in comp.items() if k in NONCUBIC]
        return sum(comp.values()), (sum(nc) if nc else np.zeros_like(next(iter(comp.values()))))

    def disp(self, k: int, P: np.ndarray, f: float | None = None) -> np.ndarray:
        f = self.f if f is None else f
        d = math.sqrt(1 - f) * ef.evaluate(self.spec, self.static, P)
        if f > 0:
            for j in range(k + 1):  # over dates, not trials
                if self.W[k, j] != 0:
                    d = d + math.sqrt(f) * self.W[k, j] * ef.evaluate(self.spec, self.drift[j], P)
        return d

    def parts(self, k: int, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The static field and the drifting field of date ``k`` at ``P``, each at full size:
        the displacement is ``sqrt(1 - f) static + sqrt(f) drift``."""
        st, dr, _, _ = self.parts_noncubic(k, P)
        return st, dr

    def parts_noncubic(self, k: int, P: np.ndarray):
        """:meth:`parts` and, of each, the part a cubic cannot fit (``NONCUBIC``):
        ``(static, drift, static_nc, drift_nc)``, each ``(T, m, 2)`` um."""
        st, st_nc = self._field(self.static, P)
        dr, dr_nc = np.zeros_like(st), np.zeros_like(st)
        for j in range(k + 1):  # over dates, not trials
            if self.W[k, j] != 0:
                d, d_nc = self._field(self.drift[j], P)
                dr = dr + self.W[k, j] * d
                dr_nc = dr_nc + self.W[k, j] * d_nc
        return st, dr, st_nc, dr_nc

    def restitution(self, rng, P, unit: bool = False):
        """A fresh restitution field at ``P`` (rms ``field.restitution_um``, or 1 um with
        ``unit``: the field is linear in its amplitude and draws the same numbers)."""
        spec = (
            ef.FieldSpec(stress_um=1.0, stress_length_mm=self.rspec.stress_length_mm)
            if unit
            else self.rspec
        )
        return ef.evaluate(spec, ef.draw(spec, rng, self.T), P)


def rotate(P: np.ndarray, th: np.ndarray) -> np.ndarray:
    c, s = np.cos(th)[:, None], np.sin(th)[:, None]
    return np.stack([c * P[..., 0] - s * P[..., 1], s * P[..., 0] + c * P[..., 1]], -1)


def reading_noise(rng, shape: tuple, n: int, sigma_um: float, backlash_um: float, approach: str):
    """The random part of ``n`` readings of coordinates of shape ``shape``: pointing noise and
    backlash (um), each ``shape + (n,)`` (or a scalar)."""
    noise = rng.normal(0.0, sigma_um, tuple(shape) + (n,)) if sigma_um > 0 else 0.0
    if approach == "one_side":
        bl = backlash_um / 2
    else:
        bl = backlash_um / 2 * rng.choice(np.array([-1.0, 1.0]), tuple(shape) + (n,))
    return noise, bl


def quantise(P_mm: np.ndarray, d_um: np.ndarray, noise, bl, count_um: float) -> np.ndarray:
    """Mean of the readings (counts) rounded to whole counts: true position ``P_mm`` plus the
    systematic displacement ``d_um``, the pointing noise and the backlash of
    :func:`reading_noise`."""
    true_um = (P_mm * 1000.0 + d_um)[..., None]
    return _mean_counts(np.round((true_um + noise + bl) / count_um))


def _mean_counts(r: np.ndarray) -> np.ndarray:
    """Mean over the last axis (the readings) of whole counts: summed slice by slice (sums of
    whole numbers are exact, so this is ``r.mean(-1)`` to the bit, without a reduction along
    a short axis)."""
    s = r[..., 0].copy()
    for i in range(1, r.shape[-1]):  # over the readings, not trials
        s += r[..., i]
    return s / r.shape[-1]


def read_counts(
    rng,
    P_mm: np.ndarray,
    d_um: np.ndarray,
    count_um: float,
    n: int,
    sigma_um: float,
    backlash_um: float,
    approach: str,
) -> np.ndarray:
    """Mean of ``n`` quantised readings (counts) of carrier positions ``P_mm (T, m, 2)`` with
    systematic displacement ``d_um``: each reading adds pointing noise and backlash and is
    rounded to whole counts."""
    noise, bl = reading_noise(rng, P_mm.shape, n, sigma_um, backlash_um, approach)
    return quantise(P_mm, d_um, noise, bl, count_um)


@dataclass(frozen=True)
class Reading:
    """Everything random about one reading of a placed plate (see :func:`measure_parts`),
    kept so that the same reading can be turned into counts for several drifting shares.

    P : (T, m, 2) mm; static : (T, m, 2) um the static field; drift : ((weight, field), ...)
    the weighted independent drift draws of the date (empty when not evaluated); rest :
    (T, m, 2) um restitution field; noise, bl : pointing noise and backlash (um).
    """

    P: np.ndarray
    static: np.ndarray
    drift: tuple
    rest: np.ndarray
    noise: object
    bl: object
    count_um: float

    def counts(self, f: float) -> np.ndarray:
        """Averaged counts ``(T, m, 2)`` with drifting share ``f`` (the same numbers as
        :func:`measure`)."""
        d = math.sqrt(1 - f) * self.static
        if f > 0:
            for w, D in self.drift:
                d = d + math.sqrt(f) * w * D
        return quantise(self.P, d + self.rest, self.noise, self.bl, self.count_um)


def measure_parts(
    rng,
    inst: Instrument,
    k: int,
    plate_true: np.ndarray,
    rot_sigma_deg: float,
    shift_sigma_mm: float,
    n: int | None = None,
    sigma_um: float | None = None,
    approach: str | None = None,
    drift: bool = True,
) -> Reading:
    """Place a plate (true coordinates ``(T, m, 2)`` mm in its own system) on date ``k``, draw
    everything random about reading it (the draws of :func:`measure`) and evaluate the
    fields (the drifting ones only with ``drift``)."""
    cfg, T = inst.cfg, inst.T
    th = np.deg2rad(rot_sigma_deg) * rng.normal(size=T)
    sh = rng.normal(0.0, shift_sigma_mm, (T, 2))
    P = rotate(plate_true, th) + sh[:, None, :]
    static = ef.evaluate(inst.spec, inst.static, P)
    dr = (
        tuple(
            (inst.W[k, j], ef.evaluate(inst.spec, inst.drift[j], P))
            for j in range(k + 1)
            if inst.W[k, j] != 0
        )
        if drift
        else ()
    )
    rest = inst.restitution(rng, P)
    noise, bl = reading_noise(
        rng,
        P.shape,
        cfg["reading.n"] if n is None else n,
        cfg["reading.pointing_sigma_um"] if sigma_um is None else sigma_um,
        cfg["reading.backlash_um"],
        cfg["reading.approach"] if approach is None else approach,
    )
    return Reading(P, static, dr, rest, noise, bl, cfg["reading.count_um"])


def measure(
    rng,
    inst: Instrument,
    k: int,
    plate_true: np.ndarray,
    rot_sigma_deg: float,
    shift_sigma_mm: float,
    n: int | None = None,
    sigma_um: float | None = None,
    approach: str | None = None,
    f: float | None = None,
):
    """Place a plate (true coordinates ``(T, m, 2)`` mm in its own system) on date ``k`` and read
    every point: averaged counts ``(T, m, 2)``."""
    f = inst.f if f is None else f
    return measure_parts(
        rng, inst, k, plate_true, rot_sigma_deg, shift_sigma_mm, n, sigma_um, approach, drift=f > 0
    ).counts(f)


def true_plate(rng, known: np.ndarray, T: int, sigma_um: float) -> np.ndarray:
    """True coordinates of a plate whose known values are ``known (m, 2)``: known + N(0, sigma)."""
    return known + rng.normal(0.0, sigma_um * 1e-3, (T,) + known.shape)


def calib_dates(cfg: dict, n_sets: int) -> np.ndarray:
    return np.linspace(0.0, cfg["calib.span_weeks"], n_sets) if n_sets > 1 else np.zeros(1)


def calibrate(cfg, G, counts_sets, ia, ib, degree, terms=None, corrected=False):
    """Reduce each set two-point, fit the polynomial to the pooled sets.

    Returns the reduced sets ``(S, T, n, 2)``, the two-point transforms, the fit (with the
    pooled sets corrected when ``corrected``), and the mean reduction (scale, centre-cross
    reading, alpha) used for later plates.
    """
    tps = [pl.two_point_transform(c[:, ia], c[:, ib], G[ia], G[ib]) for c in counts_sets]
    red = np.stack([pl.apply_two_point(tp, c) for tp, c in zip(tps, counts_sets)])
    S, T, n, _ = red.shape
    meas = red.transpose(1, 0, 2, 3).reshape(T, S * n, 2)
    fit = pl.fit_poly(meas, np.tile(G, (S, 1)), degree=degree, terms=terms, corrected=corrected)
    mean_tp = pl.TwoPoint(
        np.mean([tp.scale for tp in tps], 0),
        np.mean([tp.origin for tp in tps], 0),
        np.mean([tp.alpha for tp in tps], 0),
        np.asarray(G[ia], float),
    )
    return red, tps, fit, mean_tp


def correct_plate(fit, mean_tp, counts, known, use_poly=True, fiducials=None):
    """Reduce a later plate: counts to mm and to the centre cross with the calibration's
    reduction, the polynomial, then a least-squares similarity onto the plate's own system
    (on ``fiducials`` indices, default all points). Returns discrepancies (um) ``(T, m, 2)``."""
    X = pl.apply_two_point(mean_tp, counts)
    if use_poly:
        X = pl.apply_poly(fit, X)
    sel = slice(None) if fiducials is None else fiducials
    return (
        ls_map("similarity", X[:, sel], known[sel] if known.ndim == 2 else known[:, sel], X) - known
    ) * 1000.0


def stats_cols(prefix: str, d_um: np.ndarray, out: dict):
    st = pl.discrepancy_stats(d_um, axis=1)
    for s in STATS:
        for i, ax in enumerate(AXES):
            out[f"{prefix}.{s}_{ax}_um"] = st[s][:, i]


def photo_points(rng, cfg, T):
    """``(T, 4 + n, 2)``: four midside fiducials then ``n`` random PUG marks in the format."""
    w, h = cfg["repeat.format_mm"]
    cx, cy = cfg["repeat.centre_mm"]
    fid = np.array([[-w / 2, 0.0], [w / 2, 0.0], [0.0, -h / 2], [0.0, h / 2]])
    pts = rng.uniform(
        [-w / 2 * 0.95, -h / 2 * 0.95], [w / 2 * 0.95, h / 2 * 0.95], (T, cfg["repeat.n_points"], 2)
    )
    allp = np.concatenate([np.broadcast_to(fid, (T, 4, 2)), pts], axis=1)
    return allp + np.array([cx, cy])


@dataclass(frozen=True)
class Placed:
    """One plate placed on the carrier and everything random about reading it (see module doc).

    P : (T, m, 2) mm carrier positions; static, drift : (T, m, 2) um the static and the
    drifting field (:meth:`Instrument.parts`, at unit amplitude factor); rest : (T, m, 2) um
    restitution field of rms 1 um; z : (T, m, 2, nmax) standard-normal pointing noise;
    sign : (T, m, 2, nmax) approach signs for the ``random`` approach; static_nc, drift_nc :
    (T, m, 2) um the parts of static and drift a cubic cannot fit (``NONCUBIC``).
    """

    P: np.ndarray
    static: np.ndarray
    drift: np.ndarray
    rest: np.ndarray
    z: np.ndarray
    sign: np.ndarray
    static_nc: np.ndarray
    drift_nc: np.ndarray


def place(
    rng,
    inst: "Instrument",
    k: int,
    plate_true: np.ndarray,
    rot_sigma_deg: float,
    shift_sigma_mm: float,
    nmax: int,
) -> Placed:
    """Place a plate (true coordinates ``(T, m, 2)`` mm in its own system) on date ``k``."""
    T = inst.T
    th = np.deg2rad(rot_sigma_deg) * rng.normal(size=T)
    sh = rng.normal(0.0, shift_sigma_mm, (T, 2))
    P = rotate(plate_true, th) + sh[:, None, :]
    static, drift, st_nc, dr_nc = inst.parts_noncubic(k, P)
    rest = inst.restitution(rng, P, unit=True)
    z = rng.normal(size=P.shape + (nmax,))
    sign = rng.choice(np.array([-1.0, 1.0]), P.shape + (nmax,))
    return Placed(P, static, drift, rest, z, sign, st_nc, dr_nc)


def read_placed(
    pl_: Placed,
    count_um: float,
    n: int,
    sigma_um: float,
    backlash_um: float,
    approach: str,
    field_scale: float = 1.0,
    drift_fraction: float = 0.0,
    restitution_um: float = 0.0,
    noncubic_factor: float = 1.0,
) -> np.ndarray:
    """Mean of ``n`` quantised readings (counts) of a :class:`Placed` plate ``(T, m, 2)``.

    ``noncubic_factor`` multiplies the sources a cubic cannot fit (the encoder's periodic
    error, the stresses, the restitution field) on top of ``field_scale``; at 1 the readings
    are those of the configured instrument, bit for bit."""
    f, g = drift_fraction, noncubic_factor
    st, dr = pl_.static, pl_.drift
    if g != 1:
        st, dr = st + (g - 1) * pl_.static_nc, dr + (g - 1) * pl_.drift_nc
    field = math.sqrt(1 - f) * st + (math.sqrt(f) * dr if f > 0 else 0.0)
    true_um = (pl_.P * 1000.0 + field_scale * field + g * restitution_um * pl_.rest)[..., None]
    bl = backlash_um / 2 if approach == "one_side" else backlash_um / 2 * pl_.sign[..., :n]
    return _mean_counts(np.round((true_um + sigma_um * pl_.z[..., :n] + bl) / count_um))


def reading_error_rms(rng, count_um, n, sigma_um, backlash_um, approach, size=200_000):
    """rms error (um, per coordinate) of the mean of ``n`` quantised readings, true positions
    uniform within a count, after removing the constant one-sided backlash offset."""
    x = rng.uniform(0.0, count_um, (size, 1))
    noise = rng.normal(0.0, sigma_um, (size, n))
    bl = (
        backlash_um / 2
        if approach == "one_side"
        else backlash_um / 2 * rng.choice(np.array([-1.0, 1.0]), (size, n))
    )
    e = _mean_counts(np.round((x + noise + bl) / count_um)) * count_um - x[:, 0]
    e = e - (backlash_um / 2 if approach == "one_side" else 0.0)
    return float(np.sqrt(np.mean(e**2)))


def ls_map(kind: str, src: np.ndarray, dst: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Fit a least-squares ``similarity`` or ``affine`` mapping ``src`` (T, n, 2) onto ``dst``
    ((T, n, 2) or (n, 2)) with :mod:`sim.instruments.transforms2d` and apply it to ``pts`` (T, m, 2)."""
    src = np.asarray(src, float)
    dst = np.broadcast_to(np.asarray(dst, float), src.shape)
    if kind == "similarity":
        return tf.apply_similarity(tf.fit_similarity(src, dst).params, pts)
    return tf.apply_affine(tf.fit_affine(src, dst).params, pts)
