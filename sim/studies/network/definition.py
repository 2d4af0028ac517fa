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

import fnmatch
import math
from dataclasses import dataclass

import numpy as np

from sim.mc.config import ConfigError

__all__ = ["Network", "build", "KINDS", "ARCSEC"]

#: observation kinds, in the order of their integer codes
KINDS = ("distance", "direction", "angle", "dx", "dy", "x", "y")
ARCSEC = math.pi / (180 * 3600)
ROLES = ("free", "fixed", "observed")
_ANGULAR = (1, 2)
MAX_POINTS = 2000
MAX_OBS = 20000
#: accepted ranges of the standard deviations: the weights 1 / sigma^2 stay far from
#: overflow and underflow, and the normal equations within double precision
SIGMA_RANGE = {"mm": (1e-9, 1e9), "arcsec": (1e-9, 1e6)}


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


def _num(key: str, v, lo: float | None = None, lo_open: bool = False, integer: bool = False):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ConfigError(key, f"must be a finite number (got {v!r})")
    if integer and not float(v).is_integer():
        raise ConfigError(key, f"must be an integer (got {v!r})")
    if lo is not None and (v <= lo if lo_open else v < lo):
        raise ConfigError(key, f"must be {'>' if lo_open else '>='} {lo:g} (got {v!r})")
    return int(v) if integer else float(v)


def _text(key: str, v) -> str:
    if not isinstance(v, str) or not v.strip():
        raise ConfigError(key, f"must be a non-empty name (got {v!r})")
    return v


def _keys(key: str, rec: dict, allowed: set, required: set) -> None:
    bad = set(rec) - allowed
    if bad:
        raise ConfigError(f"{key}.{sorted(bad)[0]}", "unknown field")
    miss = required - set(rec)
    if miss:
        raise ConfigError(f"{key}.{sorted(miss)[0]}", "missing")


def _role(key: str, rec: dict) -> tuple[int, float]:
    role = rec.get("role", "free")
    if role not in ROLES:
        raise ConfigError(f"{key}.role", f"must be one of {', '.join(ROLES)} (got {role!r})")
    sig = 0.0
    if role == "observed":
        if "sigma_mm" not in rec:
            raise ConfigError(f"{key}.sigma_mm", "an observed point needs its coordinate sigma")
        sig = _num(f"{key}.sigma_mm", rec["sigma_mm"], 0.0, lo_open=True)
        lo, hi = SIGMA_RANGE["mm"]
        if not lo <= sig <= hi:
            raise ConfigError(
                f"{key}.sigma_mm",
                f"{sig:g} is outside [{lo:g}, {hi:g}] mm: its weight would over- or underflow",
            )
    elif "sigma_mm" in rec:
        raise ConfigError(f"{key}.sigma_mm", f"only an observed point has a sigma (role {role})")
    return ROLES.index(role), sig


def _mm(key: str, rec: dict, field: str, required: bool = True, default=None):
    """``rec``'s ``field`` in mm, given as ``field_mm`` or as ``field_m`` (metres, for field
    networks), not both; a pair ``[x, y]`` when the default is one."""
    a, b = f"{field}_mm", f"{field}_m"
    if a in rec and b in rec:
        raise ConfigError(f"{key}.{b}", f"give {a} or {b}, not both")
    name, f = (b, 1000.0) if b in rec else (a, 1.0)
    if name not in rec:
        if required:
            raise ConfigError(f"{key}.{a}", f"missing (or give {b} in metres)")
        return default
    v = rec[name]
    if isinstance(default, list):
        if not (isinstance(v, list) and len(v) == 2):
            raise ConfigError(f"{key}.{name}", "must be [x, y]")
        return [_num(f"{key}.{name}", c) * f for c in v]
    return _num(f"{key}.{name}", v) * f


def _points(cfg: dict, rng: np.random.Generator):
    names, xy, role, sig = [], [], [], []
    _p = {"name", "x_mm", "y_mm", "x_m", "y_m", "role", "sigma_mm"}
    for a, rec in enumerate(cfg["network.points"]):
        key = f"network.points[{a}]"
        _keys(key, rec, _p, {"name"})
        r, s = _role(key, rec)
        names.append(_text(f"{key}.name", rec["name"]))
        xy.append([_mm(key, rec, "x"), _mm(key, rec, "y")])
        role.append(r)
        sig.append(s)
    _g = {"prefix", "nx", "ny", "spacing_mm", "spacing_m", "origin_mm", "origin_m", "role"}
    for a, rec in enumerate(cfg["network.grids"]):
        key = f"network.grids[{a}]"
        _keys(key, rec, _g | {"sigma_mm"}, {"prefix", "nx", "ny"})
        nx = _num(f"{key}.nx", rec["nx"], 1, integer=True)
        ny = _num(f"{key}.ny", rec["ny"], 1, integer=True)
        if nx * ny > MAX_POINTS:
            raise ConfigError(f"{key}.nx", f"{nx} x {ny} points is over the limit of {MAX_POINTS}")
        h = _mm(key, rec, "spacing")
        if h <= 0:
            raise ConfigError(f"{key}.spacing_mm", f"must be > 0 (got {h:g} mm)")
        o = _mm(key, rec, "origin", False, [-(nx - 1) * h / 2, -(ny - 1) * h / 2])
        r, s = _role(key, rec)
        prefix = _text(f"{key}.prefix", rec["prefix"])
        for b in range(ny):
            for c in range(nx):
                names.append(f"{prefix}{b * nx + c + 1}")
                xy.append([o[0] + c * h, o[1] + b * h])
                role.append(r)
                sig.append(s)
    _r = {"prefix", "n", "half_extent_mm", "half_extent_m", "center_mm", "center_m", "role"}
    for a, rec in enumerate(cfg["network.random"]):
        key = f"network.random[{a}]"
        _keys(key, rec, _r | {"sigma_mm"}, {"prefix", "n"})
        n = _num(f"{key}.n", rec["n"], 1, integer=True)
        if n > MAX_POINTS:
            raise ConfigError(f"{key}.n", f"{n} points is over the limit of {MAX_POINTS}")
        e = _mm(key, rec, "half_extent")
        if e <= 0:
            raise ConfigError(f"{key}.half_extent_mm", f"must be > 0 (got {e:g} mm)")
        c0 = _mm(key, rec, "center", False, [0.0, 0.0])
        r, s = _role(key, rec)
        prefix = _text(f"{key}.prefix", rec["prefix"])
        pts = rng.uniform(-e, e, (n, 2)) + np.array(c0)
        for b in range(n):
            names.append(f"{prefix}{b + 1}")
            xy.append(list(pts[b]))
            role.append(r)
            sig.append(s)
    if len(names) > MAX_POINTS:
        raise ConfigError(
            "network.points", f"{len(names)} points is over the limit of {MAX_POINTS}"
        )
    if len(names) < 2:
        raise ConfigError("network.points", "a network needs at least two points")
    dup = sorted({x for x in names if names.count(x) > 1})
    if dup:
        raise ConfigError("network.points", f"duplicate point name {dup[0]!r}")
    xy = np.array(xy, float)
    scale = np.abs(xy).max()
    if scale > 1e9:
        raise ConfigError(
            "network.points",
            f"coordinates up to {scale:.3g} mm: over 1000 km, "
            "out of range for double-precision adjustment at the um level",
        )
    return names, xy, np.array(role), np.array(sig)


def _match(key: str, pats, names: list[str]) -> list[int]:
    pats = [pats] if isinstance(pats, str) else pats
    if not isinstance(pats, list) or not pats:
        raise ConfigError(key, "must be a point name, a pattern or a list of them")
    out: list[int] = []
    for p in pats:
        _text(key, p)
        hit = [a for a, nm in enumerate(names) if fnmatch.fnmatchcase(nm, p)]
        if not hit:
            raise ConfigError(key, f"no point named {p!r}")
        out += [h for h in hit if h not in out]
    return out


_OBS = {
    "kind",
    "from",
    "to",
    "at",
    "sigma_mm",
    "sigma_arcsec",
    "settings",
    "bias_mm",
    "bias_arcsec",
    "nearest",
    "set",
}


def _obs_common(key: str, rec: dict) -> tuple[int, float, float]:
    kind = rec.get("kind")
    if kind not in KINDS[:5]:
        raise ConfigError(f"{key}.kind", f"must be one of {', '.join(KINDS[:5])} (got {kind!r})")
    code = KINDS.index(kind)
    unit, other = ("arcsec", "mm") if code in _ANGULAR else ("mm", "arcsec")
    if f"sigma_{other}" in rec or f"bias_{other}" in rec:
        raise ConfigError(f"{key}.sigma_{other}", f"a {kind} takes sigma_{unit} and bias_{unit}")
    if f"sigma_{unit}" not in rec:
        raise ConfigError(f"{key}.sigma_{unit}", "missing")
    sig = _num(f"{key}.sigma_{unit}", rec[f"sigma_{unit}"], 0.0, lo_open=True)
    lo, hi = SIGMA_RANGE[unit]
    if not lo <= sig <= hi:
        raise ConfigError(
            f"{key}.sigma_{unit}",
            f"{sig:g} is outside [{lo:g}, {hi:g}] {unit}: its weight would over- or underflow",
        )
    if "set" in rec and code != 1:
        raise ConfigError(f"{key}.set", f"only a direction has an orientation set (a {kind})")
    if "set" in rec and not isinstance(rec["set"], str):
        raise ConfigError(f"{key}.set", f"must be a name (got {rec['set']!r})")
    settings = _num(f"{key}.settings", rec.get("settings", 1), 1, integer=True)
    bias = _num(f"{key}.bias_{unit}", rec.get(f"bias_{unit}", 0.0))
    f = ARCSEC if code in _ANGULAR else 1.0
    return code, sig * f / math.sqrt(settings), bias * f


def _degenerate(names, xy, kind, i, j, k) -> None:
    """Refuse an observation whose geometry is undefined: a sight from a point to itself or
    to a point at the same place, an angle whose back- or fore-sight is its station or whose
    two sights coincide (names the observation by its points)."""
    span = max(float(np.ptp(xy, axis=0).max()), 1e-300)
    for code, a, b, c in zip(kind, i, j, k):
        if code >= 5:
            continue
        what = f"a {KINDS[code]} from {names[a]!r} to {names[b]!r}"
        if code == 2:
            what = f"an angle at {names[a]!r} from {names[b]!r} to {names[c]!r}"
            if c == a or b == a:
                raise ConfigError("network.observations", f"{what}: a sight to its own station")
            if b == c:
                raise ConfigError("network.observations", f"{what}: the two sights are one")
        if a == b:
            raise ConfigError("network.observations", f"{what}: a sight to itself")
        for t in (b, c) if code == 2 else (b,):
            if code in (0, 1, 2) and np.hypot(*(xy[t] - xy[a])) <= 1e-12 * span:
                raise ConfigError(
                    "network.points",
                    f"points {names[a]!r} and {names[t]!r} coincide: {what} is undefined",
                )


def build(cfg: dict, rng: np.random.Generator | None = None) -> Network:
    """The :class:`Network` of a validated study config (``rng``: the layout stream)."""
    if rng is None:
        rng = np.random.default_rng(np.random.SeedSequence(cfg["seed"], spawn_key=(99,)))
    names, xy, role, csig = _points(cfg, rng)
    rows: list[tuple] = []  # (kind, i, j, k, sigma, bias)
    for a, rec in enumerate(cfg["network.observations"]):
        key = f"network.observations[{a}]"
        _keys(key, rec, _OBS - {"nearest"}, {"kind", "to"})
        code, sig, bias = _obs_common(key, rec)
        if code == 2:
            _keys(key, rec, _OBS, {"at", "from"})
            at, bs, fs = (_match(f"{key}.{f}", rec[f], names) for f in ("at", "from", "to"))
            if len(at) != 1 or len(bs) != 1 or len(fs) != 1:
                raise ConfigError(f"{key}.at", "an angle names one point each for at, from, to")
            rows.append((code, at[0], bs[0], fs[0], sig, bias))
            continue
        if "from" not in rec:
            raise ConfigError(f"{key}.from", "missing")
        if "at" in rec:
            raise ConfigError(f"{key}.at", f"only an angle has 'at' (this is a {KINDS[code]})")
        fr, to = (_match(f"{key}.{f}", rec[f], names) for f in ("from", "to"))
        if len(fr) != 1 or len(to) != 1:
            raise ConfigError(
                f"{key}.to",
                "one observation names one point each for from and "
                "to (use network.generate for many)",
            )
        rows.append((code, fr[0], to[0], -1, sig, bias))
    for a, rec in enumerate(cfg["network.generate"]):
        key = f"network.generate[{a}]"
        _keys(key, rec, _OBS - {"at", "set"}, {"kind", "from", "to"})
        code, sig, bias = _obs_common(key, rec)
        if code == 2:
            raise ConfigError(
                f"{key}.kind", "angles are declared one by one (network.observations)"
            )
        fr, to = (_match(f"{key}.{f}", rec[f], names) for f in ("from", "to"))
        k = _num(f"{key}.nearest", rec.get("nearest", 0), 0, integer=True)
        if len(rows) + len(fr) * len(to) > 4 * MAX_OBS:
            raise ConfigError(
                key, f"{len(fr)} x {len(to)} observations is over the limit of {MAX_OBS}"
            )
        for s in fr:
            tgt = [t for t in to if t != s]
            if k:
                d = np.hypot(*(xy[tgt] - xy[s]).T)
                tgt = [tgt[b] for b in np.argsort(d, kind="stable")[:k]]
            rows += [(code, s, t, -1, sig, bias) for t in tgt]
    for a in np.flatnonzero(role == 2):
        rows += [(5, a, -1, -1, csig[a], 0.0), (6, a, -1, -1, csig[a], 0.0)]
    if not rows:
        raise ConfigError("network.observations", "the network has no observations")
    if len(rows) > MAX_OBS:
        raise ConfigError(
            "network.generate", f"{len(rows)} observations is over the limit of {MAX_OBS}"
        )
    kind, i, j, kk, sig, bias = (np.array(c) for c in zip(*rows))
    _degenerate(names, xy, kind, i, j, kk)
    n_single = len(cfg["network.observations"])
    label = [str(r.get("set", "")) for r in cfg["network.observations"]]
    label += [""] * (len(rows) - n_single)
    key = [f"{names[a]}/{lb}" if lb else names[a] for a, lb in zip(i, label)]
    stations = tuple(dict.fromkeys(s for s, c in zip(key, kind) if c == 1))
    oset = np.array([stations.index(s) if c == 1 else -1 for s, c in zip(key, kind)], int)
    beta = cfg["network.offset_mm"]
    if beta and np.any(kind == 0):
        rows_d = np.flatnonzero(kind == 0)
        d = np.hypot(*(xy[j[rows_d]] - xy[i[rows_d]]).T)
        if d.min() <= beta * (1 + 1e-6):
            r = rows_d[int(np.argmin(d))]
            raise ConfigError(
                "network.offset_mm",
                f"the offset {beta:g} mm is not shorter than the distance from "
                f"{names[i[r]]!r} to {names[j[r]]!r} ({d.min():.6g} mm)",
            )
    return Network(
        cfg["network.name"],
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
    )
