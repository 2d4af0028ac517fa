"""A plane measuring network declared as data: points, observations, parameters.

The study file's ``[network]`` table declares (coordinates in mm, x and y of a right-handed
plane system; bearings are measured from +x towards +y, as ``gama-local``'s ``axes-xy = "ne"``):

* points: ``points`` (``{name, x_mm, y_mm, role, sigma_mm}``), ``grids`` (``{prefix, nx, ny,
  spacing_mm, origin_mm, role, sigma_mm}``) and ``random`` (``{prefix, n, half_extent_mm,
  center_mm, role, sigma_mm}``, drawn once from the study seed); a field network may give
  every length in metres instead (``x_m``, ``y_m``, ``spacing_m``, ``origin_m``,
  ``half_extent_m``, ``center_m``; not both units for one field). ``role`` is ``free``,
  ``fixed`` (known, defines the datum) or ``observed`` (its coordinates are observations with
  standard deviation ``sigma_mm``: weighted coordinates, as the grid plates of seed 001);
* observations: ``observations`` (one each) and ``generate`` (``from`` x ``to`` name patterns,
  optionally only the ``nearest`` k targets), each ``{kind, from, to, at, sigma_mm |
  sigma_arcsec, settings, bias_mm | bias_arcsec}``: ``distance`` (mm), ``direction`` (arcsec;
  one orientation unknown per station), ``angle`` (arcsec; at ``at`` from ``from`` to ``to``),
  ``dx``/``dy`` (coordinate differences, mm). ``settings`` readings are averaged
  (sigma / sqrt(settings)); ``bias`` is added to every simulated reading and unknown to the
  adjustment;
* distance parameters (Brown's comparator, seed 004): every distance reads
  ``(1 + s) sqrt(d^2 - beta^2) - alpha`` with the additive constant ``constant_mm`` (alpha;
  estimated when ``estimate_constant``), the known offset ``offset_mm`` (beta) and the scale
  error ``scale_ppm`` (s, in parts per million; estimated when ``estimate_scale``: a distance
  meter's or a scale's unknown scale).

:func:`build` turns the validated config into a :class:`Network` of arrays, or raises
:class:`~sim.mc.config.ConfigError` naming the bad entry.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from sim.mc.config import ConfigError
from sim.studies.network.point_checks import COORDINATE_MAX_MM, check_points, placed_by
from sim.studies.network.validate import (
    _OBS,
    ARCSEC,
    KINDS,
    _degenerate,
    _fits,
    _keys,
    _match,
    _mm,
    _num,
    _obs_common,
    _point_name,
    _role,
    name_index,
    one_unit,
    positive_mm,
    reach,
    title,
)

__all__ = ["Network", "build", "KINDS", "ARCSEC", "COORDINATE_MAX_MM"]


@dataclass(frozen=True)
class Network:
    """Arrays of one network. Points ``(n,)``: ``names``, ``xy`` (n, 2) true coordinates in
    mm, ``role`` (0 free, 1 fixed, 2 observed). Observation rows ``(m,)``: ``kind`` (index into
    :data:`KINDS`; ``x``/``y`` are observed coordinates), point indices ``i`` (from / at),
    ``j`` (to / back-sight), ``k`` (angle fore-sight; else -1), ``sigma`` (effective: mm or
    rad), ``bias`` (mm or rad), ``oset`` (orientation set of a direction, else -1);
    ``stations`` names the orientation sets. Distance parameters ``constant_mm`` (alpha),
    ``estimate_constant``, ``offset_mm`` (beta), ``scale_ppm`` (s), ``estimate_scale``."""

    name: str
    names: tuple
    xy: np.ndarray
    role: np.ndarray
    kind: np.ndarray
    i: np.ndarray
    j: np.ndarray
    k: np.ndarray
    sigma: np.ndarray
    bias: np.ndarray
    oset: np.ndarray
    stations: tuple
    constant_mm: float = 0.0
    estimate_constant: bool = False
    offset_mm: float = 0.0
    scale_ppm: float = 0.0
    estimate_scale: bool = False
    origin_mm: tuple = (0.0, 0.0)

    @property
    def xy_mm(self) -> np.ndarray:
        """(n, 2) coordinates as the study gave them (mm): ``xy`` is taken from ``origin_mm``,
        a whole kilometre near the network's centre, so that a national grid's millions of
        metres do not cost the simulated readings their last digits."""
        return self.xy + np.asarray(self.origin_mm)

    @property
    def n(self) -> int:
        return len(self.names)

    @property
    def m(self) -> int:
        return len(self.kind)

    @property
    def q(self) -> int:
        """Globals: 2 coordinates per point, one orientation per set, the constant, the scale."""
        return 2 * self.n + len(self.stations) + 2

    @property
    def i_constant(self) -> int:
        """Index of the additive constant (mm) among the globals."""
        return 2 * self.n + len(self.stations)

    @property
    def i_scale(self) -> int:
        """Index of the scale error (ppm) among the globals."""
        return 2 * self.n + len(self.stations) + 1

    def parameter_names(self) -> list[str]:
        """Names of the globals that are not coordinates (orientations, constant, scale)."""
        return [f"orientation {s}" for s in self.stations] + ["constant", "scale"]

    def index(self, name: str) -> int:
        return self.names.index(name)

    def theta_true(self) -> np.ndarray:
        """(q,) true globals: coordinates, orientations (0), constant, scale."""
        return np.concatenate(
            [self.xy.reshape(-1), np.zeros(len(self.stations)), [self.constant_mm, self.scale_ppm]]
        )

    def free_index(self, extra_fixed: tuple = ()) -> np.ndarray:
        """Indices of the estimated globals (``extra_fixed``: point indices held fixed too)."""
        fixed = self.role == 1
        fixed[list(extra_fixed)] = True
        coords = np.flatnonzero(np.repeat(~fixed, 2))
        orient = 2 * self.n + np.arange(len(self.stations))
        const = [self.i_constant] if self.estimate_constant else []
        scale = [self.i_scale] if self.estimate_scale else []
        return np.concatenate([coords, orient, const, scale]).astype(int)


def _listed_points(cfg: dict, pts: tuple) -> None:
    """Append ``network.points`` to ``pts`` (names, xy, role codes, coordinate sigmas)."""
    _p = {"name", "x_mm", "y_mm", "x_m", "y_m", "role", "sigma_mm"}
    for a, rec in enumerate(cfg["network.points"]):
        key = f"network.points[{a}]"
        _keys(key, rec, _p, {"name"})
        one_unit(key, rec, ("x", "y"))
        r, s = _role(key, rec)
        _add(
            pts,
            _point_name(f"{key}.name", rec["name"]),
            [_mm(key, rec, "x"), _mm(key, rec, "y")],
            r,
            s,
            key,
        )


def _add(pts: tuple, name: str, xy: list, role: int, sig: float, key: str) -> None:
    for col, v in zip(pts, (name, xy, role, sig, key)):
        col.append(v)


def _grid_points(cfg: dict, pts: tuple) -> None:
    """Append the points of ``network.grids`` (row by row, named prefix + 1-based index)."""
    _g = {"prefix", "nx", "ny", "spacing_mm", "spacing_m", "origin_mm", "origin_m", "role"}
    for a, rec in enumerate(cfg["network.grids"]):
        key = f"network.grids[{a}]"
        _keys(key, rec, _g | {"sigma_mm"}, {"prefix", "nx", "ny"})
        one_unit(key, rec, ("spacing", "origin"))
        nx = _num(f"{key}.nx", rec["nx"], 1, integer=True)
        ny = _num(f"{key}.ny", rec["ny"], 1, integer=True)
        big = f"{key}.{'nx' if nx >= ny else 'ny'}"  # the larger side (ny was named nx)
        _fits(big, len(pts[0]) + nx * ny, 0, f"{nx} x {ny} points")
        h = positive_mm(key, rec, "spacing")
        reach(key, rec, "spacing", (max(nx, ny) - 1) * h)
        o = _mm(key, rec, "origin", False, [-(nx - 1) * h / 2, -(ny - 1) * h / 2])
        r, s = _role(key, rec)
        prefix, at = _point_name(f"{key}.prefix", rec["prefix"]), placed_by(key, rec, "origin")
        for b in range(ny):
            for c in range(nx):
                _add(pts, f"{prefix}{b * nx + c + 1}", [o[0] + c * h, o[1] + b * h], r, s, at)


def _random_points(cfg: dict, rng: np.random.Generator, pts: tuple):
    """Append the points of ``network.random`` (uniform in a square, from ``rng``)."""
    _r = {"prefix", "n", "half_extent_mm", "half_extent_m", "center_mm", "center_m", "role"}
    for a, rec in enumerate(cfg["network.random"]):
        key = f"network.random[{a}]"
        _keys(key, rec, _r | {"sigma_mm"}, {"prefix", "n"})
        one_unit(key, rec, ("half_extent", "center"))
        n = _num(f"{key}.n", rec["n"], 1, integer=True)
        _fits(f"{key}.n", len(pts[0]) + n, 0, f"{n} points")
        e = positive_mm(key, rec, "half_extent")
        reach(key, rec, "half_extent", 2 * e)
        c0 = _mm(key, rec, "center", False, [0.0, 0.0])
        r, s = _role(key, rec)
        prefix, at = _point_name(f"{key}.prefix", rec["prefix"]), placed_by(key, rec, "center")
        xy = rng.uniform(-e, e, (n, 2)) + np.array(c0)
        for b in range(n):
            _add(pts, f"{prefix}{b + 1}", list(xy[b]), r, s, at)


def _points(cfg: dict, rng: np.random.Generator):
    """Names, coordinates (n, 2) mm, role codes and coordinate sigmas of every point."""
    pts: tuple[list, ...] = ([], [], [], [], [])  # names, xy, roles, sigmas, the keys
    _listed_points(cfg, pts)
    _grid_points(cfg, pts)
    _random_points(cfg, rng, pts)
    names, xy = pts[0], np.array(pts[1], float)
    check_points(names, xy, pts[4])
    return names, xy, np.array(pts[2]), np.array(pts[3])


def _origin(xy: np.ndarray) -> np.ndarray:
    """The whole kilometre (mm) nearest the centre of the points' extent: 0 for a plate or a
    field network about the origin, the grid's offset for national grid coordinates."""
    return np.round((xy.min(axis=0) + xy.max(axis=0)) / 2 / 1e6) * 1e6


def _targets(xy: np.ndarray, fr: list[int], to: list[int], k: int) -> list[list[int]]:
    """For each ``from`` point its targets: every ``to`` point but itself, or (``k`` > 0) the
    ``k`` nearest of them, ties broken by the order of ``to`` -- found with a k-d tree
    (:class:`scipy.spatial.cKDTree`): the ``k + 1`` nearest bound a radius, the points within
    it are sorted exactly (the same distances, in the same order, as a sort of all of
    ``to``), so the work grows as ``len(from) k log len(to)``."""
    if not k:
        return [[t for t in to if t != s] for s in fr]
    to_a = np.asarray(to)
    rank = np.empty(len(xy), np.int64)
    rank[to_a] = np.arange(len(to_a))
    tree = cKDTree(xy[to_a])
    dk, _ = tree.query(xy[fr], k=min(k + 1, len(to_a)))
    dk = dk.reshape(len(fr), -1)[:, -1]
    near = tree.query_ball_point(xy[fr], r=dk * (1 + 1e-9) + 1e-300)
    out = []
    for s, cand in zip(fr, near):
        c = to_a[np.asarray(cand, np.int64)]
        c = c[c != s]
        d = np.hypot(*(xy[c] - xy[s]).T)
        order = np.lexsort((rank[c], d))[:k]
        out.append([int(t) for t in c[order]])
    return out


def _listed_obs(cfg: dict, names: list[str]) -> list[tuple]:
    """The rows ``(kind, i, j, k, sigma, bias)`` of ``network.observations``, one each."""
    rows: list[tuple] = []
    index = name_index(names)
    for a, rec in enumerate(cfg["network.observations"]):
        key = f"network.observations[{a}]"
        _keys(key, rec, _OBS - {"nearest"}, {"kind", "to"})
        code, sig, bias = _obs_common(key, rec)
        if code == 2:
            _keys(key, rec, _OBS, {"at", "from"})
            at, bs, fs = (_match(f"{key}.{f}", rec[f], names, index) for f in ("at", "from", "to"))
            _one_each(key, {"at": at, "from": bs, "to": fs})
            rows.append((code, at[0], bs[0], fs[0], sig, bias))
            continue
        if "from" not in rec:
            raise ConfigError(f"{key}.from", "missing")
        if "at" in rec:
            raise ConfigError(f"{key}.at", f"only an angle has 'at' (this is a {KINDS[code]})")
        fr, to = (_match(f"{key}.{f}", rec[f], names, index) for f in ("from", "to"))
        _one_each(key, {"from": fr, "to": to})
        rows.append((code, fr[0], to[0], -1, sig, bias))
    return rows


def _one_each(key: str, matched: dict) -> None:
    """One observation names one point in each of its fields (the one that matched more is
    named)."""
    for f, pts in matched.items():
        if len(pts) != 1:
            raise ConfigError(
                f"{key}.{f}",
                f"matches {len(pts)} points: one observation names one point each for "
                f"{', '.join(matched)}"
                + ("" if "at" in matched else " (use network.generate for many)"),
            )


def _generated_obs(cfg: dict, names: list[str], xy: np.ndarray, rows: list[tuple]) -> list[int]:
    """Append the rows of ``network.generate`` (every ``from`` to every, or the nearest,
    ``to``), refusing a set that would not fit the memory limit before it is made. Returns
    the end of each entry's rows (a row's entry, for a message that names its key)."""
    index = name_index(names)
    ends = []
    for a, rec in enumerate(cfg["network.generate"]):
        key = f"network.generate[{a}]"
        _keys(key, rec, _OBS - {"at", "set"}, {"kind", "from", "to"})
        code, sig, bias = _obs_common(key, rec)
        if code == 2:
            raise ConfigError(
                f"{key}.kind", "angles are declared one by one (network.observations)"
            )
        fr, to = (_match(f"{key}.{f}", rec[f], names, index) for f in ("from", "to"))
        k = _num(f"{key}.nearest", rec.get("nearest", 0), 0, integer=True)
        per = min(k, len(to)) if k else len(to)
        _fits(key, len(names), len(rows) + len(fr) * per, f"{len(fr)} x {per} observations")
        before = len(rows)
        for s, tgt in zip(fr, _targets(xy, fr, to, k)):
            rows += [(code, s, t, -1, sig, bias) for t in tgt]
        if len(rows) == before:
            raise ConfigError(key, "generates no observation: no 'to' point other than 'from'")
        ends.append(len(rows))
    return ends


def _orientation_sets(cfg: dict, names, kind, i) -> tuple[np.ndarray, tuple[str, ...]]:
    """Per row its orientation unknown (-1 for a non-direction) and the stations' set names
    (``A``, or ``A/2`` for a second set at A)."""
    n_single = len(cfg["network.observations"])
    label = [str(r.get("set", "")) for r in cfg["network.observations"]]
    label += [""] * (len(kind) - n_single)
    key = [f"{names[a]}/{lb}" if lb else names[a] for a, lb in zip(i, label)]
    stations = tuple(dict.fromkeys(s for s, c in zip(key, kind) if c == 1))
    at = {s: b for b, s in enumerate(stations)}
    return np.array([at[s] if c == 1 else -1 for s, c in zip(key, kind)], int), stations


def _check_offset(beta: float, names, xy, kind, i, j) -> None:
    """Brown's offset must be shorter than every distance it is taken from."""
    if not beta or not np.any(kind == 0):
        return
    rows_d = np.flatnonzero(kind == 0)
    d = np.hypot(*(xy[j[rows_d]] - xy[i[rows_d]]).T)
    if d.min() <= beta * (1 + 1e-6):
        r = rows_d[int(np.argmin(d))]
        raise ConfigError(
            "network.offset_mm",
            f"the offset {beta:g} mm is not shorter than the distance from "
            f"{names[i[r]]!r} to {names[j[r]]!r} ({d.min():.6g} mm)",
        )


def _source(cfg: dict, ends: list[int], r: int) -> str:
    """The key that declares row ``r``: ``network.observations[a]`` (listed first), else
    ``network.generate[a]`` (``ends``: where each entry's rows end)."""
    n = len(cfg["network.observations"])
    if r < n:
        return f"network.observations[{r}]"
    return f"network.generate[{int(np.searchsorted(ends, r, side='right'))}]"


def _check_extent(cfg: dict, names, xy, kind, i, j, bias, ends) -> None:
    """A length's bias (a distance's, a coordinate difference's) is shorter than the
    network's extent (its points' bounding-box diagonal): a reading off by more describes no
    geometry of this network (``bias_mm = 1000`` on the README's 400 x 300 mm network ran,
    its Monte-Carlo sigma 3.4 times the analytic one)."""
    rows = np.flatnonzero(np.isin(kind, (0, 3, 4)))
    if not rows.size:
        return
    ext = float(np.hypot(*np.ptp(xy, axis=0)))
    r = int(rows[np.argmax(np.abs(bias[rows]))])
    if abs(bias[r]) >= ext:
        raise ConfigError(
            f"{_source(cfg, ends, r)}.bias_mm",
            f"{bias[r]:g} mm on the {KINDS[int(kind[r])]} from {names[i[r]]!r} to "
            f"{names[j[r]]!r} is not shorter than the network's extent ({ext:.6g} mm, its "
            "points' bounding-box diagonal): a reading so far off describes no geometry of "
            "this network",
        )


def _check_readings(cfg: dict, beta: float, names, xy, kind, i, j, bias, ends) -> None:
    """Every distance reads a positive length: ``(1 + s) sqrt(d^2 - beta^2) - alpha > 0``,
    and with its own ``bias_mm`` added too (named by the key that declares it)."""
    rows_d = np.flatnonzero(kind == 0)
    if not rows_d.size:
        return
    d = np.hypot(*(xy[j[rows_d]] - xy[i[rows_d]]).T)
    f = 1.0 + 1e-6 * cfg["network.scale_ppm"]
    read = f * np.sqrt(np.maximum(d * d - beta * beta, 0.0)) - cfg["network.constant_mm"]
    biased = read + bias[rows_d]
    if read.min() > 0 and biased.min() <= 0:
        r = rows_d[int(np.argmin(biased))]
        raise ConfigError(
            f"{_source(cfg, ends, int(r))}.bias_mm",
            f"the distance from {names[i[r]]!r} to {names[j[r]]!r} would read "
            f"{biased.min():.6g} mm with its bias_mm of {bias[r]:g}: a reading is a "
            "positive length",
        )
    if read.min() <= 0:
        r = rows_d[int(np.argmin(read))]
        raise ConfigError(
            "network.constant_mm",
            f"the distance from {names[i[r]]!r} to {names[j[r]]!r} would read "
            f"{read.min():.6g} mm: a reading is a positive length (constant_mm is subtracted)",
        )


def build(cfg: dict, rng: np.random.Generator | None = None) -> Network:
    """The :class:`Network` of a validated study config (``rng``: the layout stream; by
    default ``network.layout_seed``'s, never the run's ``seed``: a sweep's cells and
    replicates, validated at the study's seed and run at their own, each drew another layout
    of its random points, so a sweep over a sigma compared networks of other geometries)."""
    if rng is None:
        seed = cfg.get("network.layout_seed", 1)
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(99,)))
    names, xy, role, csig = _points(cfg, rng)
    origin = _origin(xy)
    xy = xy - origin
    rows = _listed_obs(cfg, names)
    ends = _generated_obs(cfg, names, xy, rows)
    for a in np.flatnonzero(role == 2):
        rows += [(5, a, -1, -1, csig[a], 0.0), (6, a, -1, -1, csig[a], 0.0)]
    if not rows:
        raise ConfigError("network.observations", "the network has no observations")
    kind, i, j, kk, sig, bias = (np.array(c) for c in zip(*rows))
    _degenerate(names, xy, kind, i, j, kk)
    oset, stations = _orientation_sets(cfg, names, kind, i)
    beta = cfg["network.offset_mm"]
    _check_offset(beta, names, xy, kind, i, j)
    _check_readings(cfg, beta, names, xy, kind, i, j, bias.astype(float), ends)
    _check_extent(cfg, names, xy, kind, i, j, bias.astype(float), ends)
    return Network(
        title("network.name", cfg["network.name"]),
        tuple(names),
        xy,
        role,
        kind.astype(int),
        i.astype(int),
        j.astype(int),
        kk.astype(int),
        sig.astype(float),
        bias.astype(float),
        oset,
        stations,
        cfg["network.constant_mm"],
        cfg["network.estimate_constant"],
        beta,
        cfg["network.scale_ppm"],
        cfg["network.estimate_scale"],
        (float(origin[0]), float(origin[1])),
    )
