"""Validation of a network's declaration, field by field: numbers, names, roles, units and
sigmas of points and observations (weights that would over- or underflow are refused), name
patterns, the memory a network of this size needs (by the per-point and per-observation
estimate, against ``SIM_MAX_MEMORY_GB``), and degenerate observations (a sight to its own
station, to a point at the same place). Each refusal is a one-line
:class:`~sim.mc.config.ConfigError` naming the key or the observation by its points;
:func:`sim.studies.network.definition.build` calls these while it builds the arrays."""

from __future__ import annotations

import fnmatch
import math

import numpy as np

from sim.mc.config import ConfigError, did_you_mean
from sim.mc.limit_error import LimitError
from sim.mc.lookalike import differs, skeleton
from sim.mc.memory_limit import memory_limit_gb
from sim.mc.message_text import near_keys
from sim.mc.network_size import network_counts, network_estimate, state_bytes
from sim.room import short_room

__all__ = ["KINDS", "ARCSEC", "ROLES", "SIGMA_RANGE", "MAX_NAME", "MAX_TITLE", "title"]

#: observation kinds, in the order of their integer codes
KINDS = ("distance", "direction", "angle", "dx", "dy", "x", "y")
ARCSEC = math.pi / (180 * 3600)
ROLES = ("free", "fixed", "observed")
_ANGULAR = (1, 2)
#: accepted ranges of the standard deviations: the weights 1 / sigma^2 stay far from
#: overflow and underflow, and the normal equations within double precision; an angle's at
#: most 1e5 arcsec (27.8 degrees, a reading off by pi once in 1e10), see :data:`WRAPS`
SIGMA_RANGE = {"mm": (1e-9, 1e9), "arcsec": (1e-9, 1e5)}
#: why an angle's sigma stops at 1e5 arcsec: a direction of sigma 1e6 arcsec (277
#: degrees, within the weights' range) drew readings that wrap around the circle, so the
#: global test's false-alarm self-check failed (0 of 400 trials) and the orientations' Monte
#: Carlo sigma disagreed with the analytic one: a Gaussian angle that spread is no reading
WRAPS = "an angle that large wraps around the circle (at most 27.8 degrees)"
#: observations a point beyond which they set a network's size (``nearest = 4``: 4 a point)
MANY_SIGHTS = 50
#: the largest bias: a constant offset does not spread, so an angle's may pass 27.8 degrees
BIAS_BOUND = {"mm": 1e9, "arcsec": 1e6}


def _memory_limit() -> float:
    """The memory limit in bytes (``--max-memory-gb``, ``SIM_MAX_MEMORY_GB``, the default)."""
    return memory_limit_gb() * 2**30


def fits_estimate(cfg: dict) -> None:
    """Refuse, before the network is built and its normals factorised (minutes and most of
    the memory of a large one), a run whose estimate (:func:`sim.mc.network_size.
    network_estimate`, the memory ``sim check`` shows) is over the memory limit or what
    ``ulimit -v`` or ``-d`` leaves (:func:`sim.room.short_room`), naming the key that declares the network's size (``network.gama_xml`` and its file, else
    ``network.generate``, ``network.grids``, ``network.random`` or ``network.points``). The
    estimate was applied after the load: a 90,000-point network under
    ``SIM_MAX_MEMORY_GB=2`` was built and factorised (two minutes, 1.35 GiB), then refused;
    so a 50,000-point grid under ``ulimit -v 1300000``, or it failed on a MemoryError."""
    if not _counts_typed(cfg):
        return  # a count as text ("3000"), below 1, not whole: the build names its field
    try:
        need, k = network_estimate(cfg)[3], network_counts(cfg)
    except (TypeError, ValueError, KeyError, OverflowError, ZeroDivisionError, OSError):
        return  # the build names what is wrong
    lim = _memory_limit()
    short = short_room(need) if need <= lim else ""
    if need <= lim and not short:
        return
    gama = cfg.get("network.gama_xml")
    key = "network.gama_xml" if gama else _size_key(cfg, k.points, k.rows)
    what = f"a network of about {k.points:,.0f} points and {k.rows:,.0f} observations"
    if gama:  # its elements counted, not read (sim.mc.gama_count)
        what = f"{gama}: a gama-local file of {k.points:,.0f} points and {k.rows:,.0f} observations"
    over = (
        f"and {short}: raise {short.split(' (', 1)[0]} or use fewer points or observations"
        if short
        else f"over the {lim / 2**30:g} GiB memory limit (--max-memory-gb or "
        "SIM_MAX_MEMORY_GB): use fewer points or observations"
    )
    raise LimitError(
        key,
        f"{what} ({k.unknowns:,.0f} unknowns) needs about "
        f"{need / 2**30:.3g} GiB with chunks of {min(cfg['chunk'], cfg['trials'])} trials "
        f"(estimate), {over}",
    )


def _counts_typed(cfg: dict) -> bool:
    """Whether every grid's ``nx``, ``ny`` and random set's ``n`` is a whole number of at least
    1, as the build takes it: the estimate counted ``nx = "3000"`` as 3000 and
    :func:`_size_key` multiplied the text, a TypeError traceback (exit 3); a grid of -3000 x
    -3000 was refused as "a network of about 9,000,000 points", as was one of 3000.5 x 3000.
    The build names such a field ("must be a finite number", "must be >= 1")."""
    for key, fields in (("network.grids", ("nx", "ny")), ("network.random", ("n",))):
        for rec in cfg.get(key) or []:
            for f in fields if isinstance(rec, dict) else ():
                v = rec.get(f, 1)
                if isinstance(v, bool) or not isinstance(v, (int, float)):
                    return False
                if not (math.isfinite(v) and v >= 1 and float(v).is_integer()):
                    return False
    return True


def _size_key(cfg: dict, points: float, rows: float = 0.0) -> str:
    """The key that sets a declared network's size: the observations when over :data:`MANY_SIGHTS`
    a point (every point to every point, no ``nearest``: 3,000 points and 9,000,000 distances
    were blamed on ``network.grids``), else the grids or random points that hold most of its
    points (a grid of 5 x 900,000,000 points was blamed on ``network.generate``, its sights to
    the nearest points), else the sights generated, else the points listed."""
    if rows > MANY_SIGHTS * points:  # the sights, generated (or listed, when they are most)
        listed = len(cfg.get("network.observations") or [])
        return "network.generate" if rows - listed > listed else "network.observations"
    held = {
        "network.grids": sum(
            g.get("nx", 0) * g.get("ny", 0) for g in cfg.get("network.grids") or []
        ),
        "network.random": sum(r.get("n", 0) for r in cfg.get("network.random") or []),
    }
    key, most = max(held.items(), key=lambda kv: kv[1])
    if most > points / 2:
        return key
    return "network.generate" if cfg.get("network.generate") else "network.points"


def _fits(key: str, points: float, obs: float, what: str) -> None:
    """Refuse (naming ``key``) a network whose points and observations do not fit the memory
    limit (``SIM_MAX_MEMORY_GB``, default 8 GiB) by the bytes of its state on the sparse path
    (:func:`sim.mc.network_size.state_bytes`, every kind taken as non-linear), before the
    arrays are built: the order of magnitude that bounds a network by memory instead of by
    counts. The run's estimate counts the same and more, so ``sim check`` never shows less
    than this refusal states (it showed 0.22 GiB of a network refused for 0.52 GiB)."""
    need = state_bytes(points, obs)
    lim = _memory_limit()
    if not need <= lim:
        raise ConfigError(
            key,
            f"{what} need about {need / 2**30:.3g} GiB, over the {lim / 2**30:g} GiB memory "
            "limit (--max-memory-gb or SIM_MAX_MEMORY_GB)",
        )


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


#: most readings averaged into one observation (``settings``)
MAX_SETTINGS = 1_000_000
#: longest point name or grid/random prefix (a gama-local id, a table cell, a figure label)
MAX_NAME = 64
#: longest network name (the report's title)
MAX_TITLE = 200


def _point_name(key: str, v) -> str:
    """A point name (or the prefix of generated names): printable on one line, no leading or
    trailing space, none of the pattern characters ``* ? [ ]`` that ``from``/``to`` and the
    datum keys match names with, at most :data:`MAX_NAME` characters."""
    _text(key, v)
    if v != v.strip() or not v.isprintable():
        raise ConfigError(
            key, f"{v!r}: a point name is printable on one line, without leading or trailing space"
        )
    if set(v) & set("*?[]"):
        raise ConfigError(
            key,
            f"{v!r}: a point name has no pattern character (* ? [ ]): names are matched by them",
        )
    if len(v) > MAX_NAME:
        raise ConfigError(key, f"{v[:20]!r}...: over {MAX_NAME} characters")
    return v


def title(key: str, v) -> str:
    """The network's name: a non-empty title on one line of at most :data:`MAX_TITLE`."""
    _text(key, v)
    if not v.isprintable():
        raise ConfigError(key, f"{v[:40]!r}: must be printable on one line")
    if len(v) > MAX_TITLE:
        raise ConfigError(key, f"{v[:20]!r}...: over {MAX_TITLE} characters")
    return v


def _keys(key: str, rec: dict, allowed: set, required: set) -> None:
    bad = set(rec) - allowed
    if bad:  # Name, x-mm, "name ": a guess as for an unknown key (it was "unknown field" alone)
        near = did_you_mean(sorted(bad)[0], dict.fromkeys(sorted(allowed)))
        hint = near_keys(sorted(bad)[0], near)  # sigma_um: its value is in mm, convert it
        raise ConfigError(f"{key}.{sorted(bad)[0]}", f"unknown field{hint}")
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


def one_unit(key: str, rec: dict, fields: tuple[str, str]) -> None:
    """Refuse a record whose lengths mix metres and millimetres (``x_m`` with ``y_mm``, say):
    a point typed with one key of each would silently be a thousand times off in one axis."""
    for f in fields:
        if f"{f}_mm" in rec and f"{f}_m" in rec:
            raise ConfigError(f"{key}.{f}_m", f"give {f}_mm or {f}_m, not both")
    m = [f"{f}_m" for f in fields if f"{f}_m" in rec]
    mm = [f"{f}_mm" for f in fields if f"{f}_mm" in rec]
    if m and mm:
        raise ConfigError(
            f"{key}.{m[0]}", f"in metres while {mm[0]} is in millimetres: give both in one unit"
        )


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
        return [_in_mm(f"{key}.{name}", _num(f"{key}.{name}", c), f) for c in v]
    return _in_mm(f"{key}.{name}", _num(f"{key}.{name}", v), f)


def _in_mm(key: str, v: float, f: float) -> float:
    """``v`` times ``f`` (metres to mm), refused (naming ``key``) when that is no double."""
    if not math.isfinite(v * f):  # x_m = 1e306: "the network spans inf km"
        raise ConfigError(key, f"{v:g} m is beyond the largest 64-bit float in millimetres")
    return v * f


def reach(key: str, rec: dict, field: str, far: float) -> None:
    """Refuse (naming ``field`` as written) a grid or random set whose extent ``far`` (mm)
    is no finite double: a grid's spacing near the largest double made its points inf - inf
    = NaN, which passed every check to an SVD that "did not converge"; a random set's half
    extent, NumPy's "OverflowError: high - low range exceeds valid bounds"."""
    if not math.isfinite(far):
        name, unit = (f"{field}_m", "m") if f"{field}_m" in rec else (f"{field}_mm", "mm")
        raise ConfigError(
            f"{key}.{name}", f"{rec[name]:g} {unit} puts points beyond the largest 64-bit float"
        )


def positive_mm(key: str, rec: dict, field: str) -> float:
    """``rec``'s required length ``field`` in mm (as :func:`_mm`), refused unless > 0 naming
    the key as written and its value in the unit written (``spacing_m = -25`` was refused
    as ``spacing_mm: ... (got -25000 mm)``, a key the file does not have)."""
    v = _mm(key, rec, field)
    if v <= 0:
        name, unit = (f"{field}_m", "m") if f"{field}_m" in rec else (f"{field}_mm", "mm")
        raise ConfigError(f"{key}.{name}", f"must be > 0 (got {rec[name]:g} {unit})")
    return v


def distinct_looks(key: str, names) -> None:
    """Refuse two point names that look the same (doors24c): ``A`` and Cyrillic ``А``, a
    precomposed ``É`` and ``E`` + U+0301, ``P1`` and full-width ``Ｐ1`` were two points
    that every table, figure and exported file then printed alike -- one point split in two,
    silently, where an observation or a pattern named the other."""
    seen: dict[str, str] = {}
    for nm in names:
        other = seen.setdefault(skeleton(nm), nm)
        if other != nm:
            raise ConfigError(
                key,
                f"point names {other!r} and {nm!r} look the same ({differs(other, nm)}): "
                "name them apart, or write both alike",
            )


def looks_like(p: str, names) -> str:
    """`` (the network has 'А', ...)`` for a name not found that looks like a point's."""
    sk = skeleton(p)
    hit = next((nm for nm in names if skeleton(nm) == sk), None)
    return "" if hit is None else f" (a point {hit!r} looks the same: {differs(hit, p)} here)"


def name_index(names) -> dict[str, int]:
    """``{name: index}`` of a network's point names (unique), for :func:`hits`."""
    return {nm: a for a, nm in enumerate(names)}


def hits(p: str, names, index: dict[str, int]) -> list[int]:
    """Indices of the ``names`` the pattern ``p`` matches (``fnmatch.fnmatchcase``). A plain
    name (names hold none of ``*?[``) is looked up in ``index`` (:func:`name_index`), not
    matched against every name: a gama-local file lists thousands of points and observations
    by name (5,041 ``adj="XY"`` points, n^2 matches, took minutes to load)."""
    if not any(c in p for c in "*?["):
        a = index.get(p)
        return [] if a is None else [a]
    return [a for a, nm in enumerate(names) if fnmatch.fnmatchcase(nm, p)]


def select(key: str, pats, names, index: dict[str, int], what: str = "no point named") -> list[int]:
    """Indices matched by any of ``pats``, each once, in the order matched; a pattern that
    matches nothing, or one listed twice (``["A", "A", "C"]``: a typo for ``B``, whose sights
    were silently left out), is refused naming ``key``."""
    out: list[int] = []
    seen: set[int] = set()
    twice = [p for i, p in enumerate(pats) if isinstance(p, str) and p in pats[:i]]
    if twice:
        raise ConfigError(key, f"{twice[0]!r} is listed twice")
    for p in pats:
        hit = hits(p, names, index)
        if not hit:
            raise ConfigError(key, f"{what} {p!r}{looks_like(p, names)}")
        out += [h for h in hit if h not in seen]
        seen.update(hit)
    return out


def _match(key: str, pats, names: list[str], index: dict[str, int]) -> list[int]:
    pats = [pats] if isinstance(pats, str) else pats
    if not isinstance(pats, list) or not pats:
        raise ConfigError(key, "must be a point name, a pattern or a list of them")
    for p in pats:
        _text(key, p)
    return select(key, pats, names, index)


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
    wrong = [f for f in (f"sigma_{other}", f"bias_{other}") if f in rec]
    if wrong:  # the field given (an angle's bias_mm was named its sigma_mm)
        a = "an" if kind[0] in "aeiou" else "a"
        raise ConfigError(f"{key}.{wrong[0]}", f"{a} {kind} takes sigma_{unit} and bias_{unit}")
    if f"sigma_{unit}" not in rec:
        raise ConfigError(f"{key}.sigma_{unit}", "missing")
    sig = _num(f"{key}.sigma_{unit}", rec[f"sigma_{unit}"], 0.0, lo_open=True)
    lo, hi = SIGMA_RANGE[unit]
    if not lo <= sig <= hi:
        why = WRAPS if unit == "arcsec" and sig > hi else "its weight would over- or underflow"
        raise ConfigError(
            f"{key}.sigma_{unit}", f"{sig:g} is outside [{lo:g}, {hi:g}] {unit}: {why}"
        )
    if "set" in rec and code != 1:
        raise ConfigError(f"{key}.set", f"only a direction has an orientation set (a {kind})")
    if "set" in rec:
        _point_name(f"{key}.set", rec["set"])
    settings = _num(f"{key}.settings", rec.get("settings", 1), 1, integer=True)
    if not settings <= MAX_SETTINGS:
        raise ConfigError(
            f"{key}.settings",
            f"{int(settings):,} readings of sigma {sig:g} {unit}: over {MAX_SETTINGS:,}",
        )
    if not lo <= sig / math.sqrt(settings):  # (said "over 1,000,000 or ..." of 1,000,000)
        raise ConfigError(
            f"{key}.settings",
            f"{int(settings):,} readings of sigma {sig:g} {unit} average to sigma "
            f"{sig / math.sqrt(settings):.3g} {unit}, under {lo:g} {unit}: its weight would "
            "overflow",
        )
    bias = _num(f"{key}.bias_{unit}", rec.get(f"bias_{unit}", 0.0))
    hi = BIAS_BOUND[unit]
    if not abs(bias) <= hi:
        raise ConfigError(f"{key}.bias_{unit}", f"{bias:g} is outside [-{hi:g}, {hi:g}] {unit}")
    f = ARCSEC if code in _ANGULAR else 1.0
    return code, sig * f / math.sqrt(settings), bias * f


def _degenerate(names, xy, kind, i, j, k) -> None:
    """Refuse an observation whose geometry is undefined: a sight from a point to itself or
    to a point at the same place, an angle whose back- or fore-sight is its station or whose
    two sights coincide (names the first such observation by its points). Vectorised over
    the rows (a network of 100,000 rows checks in milliseconds); :func:`_refuse` words it."""
    span = max(float(np.ptp(xy, axis=0).max()), 1e-300)
    geo, ang = kind < 5, kind == 2
    jb, kb = np.where(j >= 0, j, i), np.where(k >= 0, k, i)
    near_j = np.hypot(*(xy[jb] - xy[i]).T) <= 1e-12 * span
    near_k = np.hypot(*(xy[kb] - xy[i]).T) <= 1e-12 * span
    bad = geo & (i == j)
    bad |= ang & ((k == i) | (j == k))
    bad |= np.isin(kind, (0, 1, 2)) & near_j
    bad |= ang & near_k
    for r in np.flatnonzero(bad)[:1]:
        _refuse(names, xy, span, int(kind[r]), int(i[r]), int(j[r]), int(k[r]))


def _refuse(names, xy, span: float, code: int, a: int, b: int, c: int) -> None:
    """The one-line refusal of the degenerate observation ``code`` at ``a``, ``b``, ``c``."""
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
