"""Write a network as GNU Gama's ``gama-local`` XML input (2.x), and read one into a study.

Export (``network.xml``, written by every network run when the network has that form):
``<network axes-xy="ne">`` (left-handed angles, gama-local's default: x north, y east,
bearings clockwise from x, as this suite's bearings from +x towards +y; a network imported from
a gama-local file is written in that file's ``axes-xy`` and ``angles``, its coordinates as
read, directions and angles negated where the angles run against the frame) with
``<parameters sigma-apr="1" sigma-act="apriori"/>`` (a precision study: the stdevs are the
observations' sigmas; sigma-apr a power of ten where gama-local would drop a weak orientation:
:func:`_sigma_apr`); points in metres, ``fix="xy"`` (fixed), ``adj="xy"`` (free or
observed), ``adj="XY"`` on the points of an inner datum; directions grouped one ``<obs>`` per
orientation set, angles and directions in gon with stdevs in cc, distances with stdevs in mm;
observed coordinates as ``<coordinates>`` with a diagonal ``<cov-mat>`` (mm^2); ``dx``/``dy``
pairs as ``<vectors>`` with every height fixed at 0 (``fix="z"``: the ``dz`` rows carry no
unknown, so gama-local counts one more degree of freedom per vector). Brown's known offset
beta, a known additive constant and a known scale error become a plain distance with the
equivalent stdev ``sigma s / ((1 + scale) d)`` (``s = sqrt(d^2 - beta^2)``): the same row of
the design, the same precision. ``val`` is the error-free value. Refused with one line
(gama-local cannot express them): an estimated additive constant or scale, observation
biases, a ``dx`` without its ``dy``, a ``dy`` whose variance is at or below 1e-8 of every
``dx``'s (:func:`_least_first`). ``datum.kind = "constraints"`` is written as the free network
in the inner datum over all its points (:func:`export` says so). Import:
:mod:`sim.studies.network.gama_read` (``network.gama_xml``; once a content: ``gama_cache``)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from sim.mc.config import ConfigError, given
from sim.mc.storage import atomic_path
from sim.studies.network.definition import Network, build
from sim.studies.network.gama_cache import gama_digest, read_gama
from sim.studies.network.gama_frames import NE, consistent
from sim.studies.network.gama_read import CC, MAX_BYTES, NS
from sim.studies.network.gama_sets import one_target_set
from sim.studies.network.gama_vocab import shifted
from sim.studies.network.linearity import row_key
from sim.studies.network.model import computed, defect_basis
from sim.studies.network.validate import hits, name_index

__all__ = ["read_gama", "write_gama", "merge_gama", "export", "gama_digest", "import_note"]

_GON = math.pi / 200


def import_note(cfg: dict) -> str:
    """The sentence the report gives about ``network.gama_xml`` (its convention), or ``""``."""
    path = cfg.get("network.gama_xml")
    if not path:
        return ""
    return f"{Path(path).name}: {read_gama(path, sha256=cfg.get('network.gama_sha256'))['note']}"


def merge_gama(cfg: dict) -> dict:
    """``cfg`` with the network read from ``network.gama_xml`` (if given)."""
    path = cfg.get("network.gama_xml")
    if not path:
        return cfg
    for k in (
        "network.points",
        "network.grids",
        "network.random",
        "network.observations",
        "network.generate",
    ):
        if cfg[k]:
            raise ConfigError(
                k, "give the network either in the study file or in network.gama_xml, not both"
            )
    rec = read_gama(path, sha256=cfg.get("network.gama_sha256"))
    out = {
        **cfg,
        "network.points": rec["network.points"],
        "network.observations": rec["network.observations"],
        "network.gama_frame": rec["frame"],  # the export writes the frame it was read in
    }
    if rec["datum.points"] and not cfg["datum.points"]:
        out["datum.points"] = rec["datum.points"]
    # points held: fixed, or their coordinates observed (weighted)
    fixed = sum(p.get("role") == "fixed" for p in rec["network.points"])
    seen = sum(p.get("role") == "observed" for p in rec["network.points"])
    if rec["datum.points"] and cfg["datum.kind"] == "fixed" and _defect_left(out, fixed + seen):
        # adj="XY" points: gama-local removes the defect its fixed points leave over them, as
        # the suite's own export of an inner datum writes it (its round trip), so the study
        # does too; where they leave none, the datum stays fixed, as there. A fixed datum the
        # study asked for (the file, --set, a sweep cell) is refused: it would not be the one run
        if given(cfg, "datum.kind"):
            raise ConfigError(
                "datum.kind",
                f'"fixed" cannot hold: {Path(path).name} has {fixed} fixed '
                f"point{'' if fixed == 1 else 's'}{' and 1 observed' if seen else ''} (a fixed "
                "datum needs two or more fixed or observed points, or one and <vectors>) and "
                'adj="XY" points, which gama-local adjusts in the inner datum: set datum.kind '
                '= "inner" (or leave it out: the default falls back to it)',
            )
        out["datum.kind"] = "inner"
    return out


def _defect_left(full: dict, held: int) -> bool:
    """Whether the file's fixed points leave a defect (``held``: points fixed or observed):
    with none, the translation; with one, the rotation unless ``<vectors>`` hold it, which
    the design decides (as in gama-local: it was inner, refused, "nothing to constrain")."""
    if held >= 2:
        return False
    if held == 0 or not any(o["kind"] in ("dx", "dy") for o in full["network.observations"]):
        return True
    net = build(full)
    return defect_basis(net, net.free_index()).shape[1] > 0


def _fmt(x: float) -> str:
    return repr(float(x))


def _metres(x_mm: float) -> str:
    """A coordinate in mm written in metres: its shortest digits with the decimal point moved
    by three places (-256034.379 mm is ``-256.034379``, where ``repr(x / 1000)`` wrote
    ``-256.03437900000003``), so gama-local reads the metres the study meant and the import
    reads back the same double (:meth:`sim.studies.network.gama_vocab._File.mm`)."""
    d = shifted(repr(float(x_mm) + 0.0), -3)  # -0.0 written 0.0
    if not -30 < d.adjusted() < 30:
        return str(d)  # 1.5E-303: gama-local reads the exponent
    t = format(d, "f")  # the shortest digits, written as repr writes a float: 250.0
    t = t.rstrip("0") if "." in t else t + "."
    return t + "0" if t.endswith(".") else t


def _refuse(net: Network) -> None:
    if np.any(net.bias != 0):
        raise ConfigError(
            "network.observations",
            "gama-local has no observation bias: export a network without bias_*",
        )
    if net.estimate_constant:
        raise ConfigError(
            "network.estimate_constant", "gama-local has no additive-constant unknown"
        )
    if net.estimate_scale:
        raise ConfigError("network.estimate_scale", "gama-local has no scale unknown")
    if why := one_target_set(net):  # a set gama-local leaves out: other degrees of freedom
        raise ConfigError("network.observations", why)


def _vector_pairs(net: Network) -> list[tuple[int, int]]:
    """Rows ``(dx, dy)`` of each vector; a dx without its dy (or the reverse) is refused."""
    dx = {}
    for r in np.flatnonzero(net.kind == 3):
        dx.setdefault((int(net.i[r]), int(net.j[r])), []).append(int(r))
    pairs = []
    for r in np.flatnonzero(net.kind == 4):
        key = (int(net.i[r]), int(net.j[r]))
        if not dx.get(key):
            raise ConfigError(
                "network.observations",
                f"a dy from {net.names[key[0]]!r} to {net.names[key[1]]!r} without its dx: "
                "a gama-local vector has both",
            )
        pairs.append((dx[key].pop(0), int(r)))
    left = [k for k, v in dx.items() if v]
    if left:
        a, b = left[0]
        raise ConfigError(
            "network.observations",
            f"a dx from {net.names[a]!r} to {net.names[b]!r} without its dy: "
            "a gama-local vector has both",
        )
    return pairs


def _expressible(net: Network, pairs: list) -> None:
    """A vector's dx comes first in its ``<vec>``: a dy whose variance is at or below 1e-8
    of the least dx variance fails gama-local's pivot tolerance (:func:`_least_first`)."""
    if not pairs:
        return
    least = min(float(net.sigma[rx]) for rx, _ in pairs)
    for rx, ry in pairs:
        if net.sigma[ry] ** 2 <= 1e-8 * least**2:
            raise ConfigError(
                "network.observations",
                f"the dy from {net.names[net.i[ry]]!r} to {net.names[net.j[ry]]!r} "
                f"(sigma {net.sigma[ry]:g} mm) is under 1e-4 of every dx's sigma (least "
                f"{least:g} mm): gama-local refuses such a vector covariance as not "
                "positive definite",
            )


def _distance_sigma(net: Network, r: int) -> float:
    """The stdev of a plain distance with the same design row as row ``r`` (known offset,
    constant and scale folded in)."""
    d = float(np.hypot(*(net.xy[net.j[r]] - net.xy[net.i[r]])))
    s = math.sqrt(max(d * d - net.offset_mm**2, 0.0))
    return float(net.sigma[r]) * s / ((1 + 1e-6 * net.scale_ppm) * d)


def _obs_sets(net: Network, po, val: np.ndarray) -> None:
    """One ``<obs>`` per station and orientation set: the station's first ``<obs>`` holds its
    distances and angles and its first direction set."""
    lin = np.flatnonzero(net.kind <= 2)
    # each station's rows in their order, grouped once (a mask per station was n x m: 50 s
    # of a 50,000-point network's export)
    srt = lin[np.argsort(net.i[lin], kind="stable")]
    cut = np.flatnonzero(np.diff(net.i[srt])) + 1
    by = {int(net.i[g[0]]): g for g in np.split(srt, cut) if g.size}
    for a in dict.fromkeys(int(x) for x in net.i[lin]):
        rows = by[a]
        sets = list(dict.fromkeys(int(net.oset[r]) for r in rows if net.kind[r] == 1))
        dirs = [[r for r in rows if net.kind[r] == 1 and net.oset[r] == s] for s in sets] or [[]]
        groups = [dirs[0] + [r for r in rows if net.kind[r] != 1]] + dirs[1:]
        for g in groups:
            if not g:
                continue
            o = ET.SubElement(po, "obs", {"from": net.names[a]})
            lone = [r for r in g if net.kind[r] == 1]
            lone = tuple(lone) if len(lone) == 1 else ()
            for r in _least_first(g, [_variance(net, int(r)) for r in g], lone):
                _one(net, o, int(r), val[r])


def _least_first(items: list, var: list, passive: tuple = ()) -> list:
    """``items`` as they are, or in ascending variance when gama-local would refuse them: it
    factorises each cluster's covariance with a pivot tolerance of 1e-8 times its first
    variance, so a cluster whose first variance is over 1e8 times a later one is "not
    positive definite" (a direction of 1000 arcsec before one of 0.05), when it reads the
    file and again over the observations it adjusts (without ``passive`` ones: the lone
    direction of a set, which its orientation absorbs). In ascending order the first of any
    part is its least, and every pivot passes."""
    active = [v for it, v in zip(items, var) if it not in passive]
    if _passes(var) and (not active or _passes(active)):
        return items
    return [items[b] for b in np.argsort(var, kind="stable")]


def _passes(var: list) -> bool:
    """gama-local's pivot test of a diagonal covariance: every variance over 1e-8 the first."""
    return all(v > 1e-8 * var[0] for v in var[1:])


def _variance(net: Network, r: int) -> float:
    """The variance row ``r`` is exported with (mm^2 or cc^2)."""
    return _distance_sigma(net, r) ** 2 if net.kind[r] == 0 else (net.sigma[r] / CC) ** 2


def _one(net: Network, o, r: int, v: float) -> None:
    if net.kind[r] == 0:
        ET.SubElement(
            o,
            "distance",
            {
                "to": net.names[net.j[r]],
                "val": _fmt(np.hypot(*(net.xy[net.j[r]] - net.xy[net.i[r]])) / 1000),
                "stdev": _fmt(_distance_sigma(net, r)),
            },
        )
    elif net.kind[r] == 1:
        ET.SubElement(
            o,
            "direction",
            {
                "to": net.names[net.j[r]],
                "val": _fmt(v / _GON % 400),
                "stdev": _fmt(net.sigma[r] / CC),
            },
        )
    else:
        ET.SubElement(
            o,
            "angle",
            {
                "bs": net.names[net.j[r]],
                "fs": net.names[net.k[r]],
                "val": _fmt(v / _GON % 400),
                "stdev": _fmt(net.sigma[r] / CC),
            },
        )


def _points(net: Network, po: ET.Element, inner: set[int], pairs: bool) -> None:
    """One ``<point>`` per point (m): fixed ones ``fix``, estimated ones ``adj`` (``XY`` in
    the inner datum); with coordinate-difference vectors every point also gets z = 0 (fixed)."""
    xy = net.xy_mm  # once: the property makes a new (n, 2) array at each call
    for a, nm in enumerate(net.names):
        attr = {"id": nm, "x": _metres(xy[a, 0]), "y": _metres(xy[a, 1])}
        if net.role[a] == 1:
            attr["fix"] = "xyz" if pairs else "xy"
        else:
            attr["adj"] = "XY" if a in inner else "xy"
            if pairs:
                attr["fix"] = "z"
        if pairs:
            attr["z"] = "0"
        ET.SubElement(po, "point", attr)


def _coordinates(net: Network, po: ET.Element) -> None:
    """The observed coordinates (m) of the points with that role, with their diagonal
    covariance matrix (mm^2)."""
    obs_pts = np.flatnonzero(net.role == 2)
    if not obs_pts.size:
        return
    sig = {int(a): s for a, s in zip(net.i[net.kind == 5], net.sigma[net.kind == 5])}
    obs_pts = _least_first(list(obs_pts), [sig[int(a)] ** 2 for a in obs_pts])
    c = ET.SubElement(po, "coordinates")
    xy = net.xy_mm
    for a in obs_pts:
        attr = {"id": net.names[a], "x": _metres(xy[a, 0]), "y": _metres(xy[a, 1])}
        ET.SubElement(c, "point", attr)
    cm = ET.SubElement(c, "cov-mat", {"dim": str(2 * len(obs_pts)), "band": "0"})
    cm.text = " ".join(_fmt(sig[int(a)] ** 2) for a in obs_pts for _ in (0, 1))


def _vectors(net: Network, po: ET.Element, pairs: list, val: np.ndarray) -> None:
    """The coordinate-difference pairs as 3-D ``<vec>`` (m, dz = 0) with their diagonal
    covariance matrix (mm^2; the dz variance 1, or, where gama-local would refuse that
    cluster (:func:`_least_first`), the dx's, with the vector of least dx variance first: a
    dz between fixed heights changes nothing but a degree of freedom)."""
    if not pairs:
        return
    var = [float(net.sigma[r]) ** 2 for rx, ry in pairs for r in (rx, ry)]
    dz = [1.0] * len(pairs)
    if not _passes([x for a in range(len(pairs)) for x in (*var[2 * a : 2 * a + 2], 1.0)]):
        b = int(np.argmin([net.sigma[rx] for rx, _ in pairs]))
        pairs = [pairs[b]] + pairs[:b] + pairs[b + 1 :]
        dz = [float(net.sigma[rx]) ** 2 for rx, _ in pairs]
    v = ET.SubElement(po, "vectors")
    for rx, ry in pairs:
        ET.SubElement(
            v,
            "vec",
            {
                "from": net.names[net.i[rx]],
                "to": net.names[net.j[rx]],
                "dx": _fmt(val[rx] / 1000),
                "dy": _fmt(val[ry] / 1000),
                "dz": "0.0",
            },
        )
    cm = ET.SubElement(v, "cov-mat", {"dim": str(3 * len(pairs)), "band": "0"})
    cm.text = " ".join(
        f"{_fmt(net.sigma[rx] ** 2)} {_fmt(net.sigma[ry] ** 2)} {_fmt(z)}"
        for (rx, ry), z in zip(pairs, dz)
    )


def _sigma_apr(net: Network) -> str:
    """``sigma-apr``: 1, or a power of ten lifting the set orientations' weights (sigma-apr^2 /
    stdev^2, cc) over gama-local's envelope pivot 1.5e-8, under which it takes the orientation
    for a dependence and drops its station (directions of 1e4 arcsec: "No unknowns have been
    defined"); a priori it scales every weight alike, no covariance."""
    d = net.kind == 1
    w = np.bincount(net.oset[d], (CC / net.sigma[d]) ** 2) if d.any() else np.zeros(0)
    least = float(w[np.bincount(net.oset[d]) > 1].min(initial=1.0)) if d.any() else 1.0
    return "1" if least >= 1e-6 else f"1e{math.ceil(math.log10(1e-4 / least) / 2)}"


def write_gama(net: Network, path: str | Path, inner: tuple | list = (), frame: tuple = NE) -> Path:
    """Write ``net`` as ``gama-local`` XML (see the module doc for the mapping and what is
    refused); ``inner``: indices of the points of an inner datum (``adj="XY"``); ``frame``:
    ``(axes-xy, angles)``, the coordinates' frame (as read from a gama-local file): the
    directions and angles change sign where the angles run against the frame."""
    _refuse(net)
    pairs = _vector_pairs(net)
    _expressible(net, pairs)
    val = computed(net, net.theta_true()[None])[0]
    if not consistent(*frame):  # from +x towards -y: an angle's or direction's value negated
        val = np.where(np.isin(net.kind, (1, 2)), -val, val)
    root = ET.Element("gama-local", xmlns=NS)
    nw = ET.SubElement(root, "network", {"axes-xy": frame[0], "angles": frame[1]})
    ET.SubElement(nw, "description").text = net.name
    ET.SubElement(nw, "parameters", {"sigma-apr": _sigma_apr(net), "sigma-act": "apriori"})
    po = ET.SubElement(nw, "points-observations")
    _points(net, po, {int(a) for a in inner}, bool(pairs))
    _obs_sets(net, po, val)
    _coordinates(net, po)
    _vectors(net, po, pairs, val)
    ET.indent(root)
    path = Path(path)
    # UTF-8, as an XML file without an encoding declaration is read, whatever the locale (a
    # point named "É1" under LC_ALL=C without UTF-8 mode: UnicodeEncodeError after every trial)
    text = '<?xml version="1.0" ?>\n' + ET.tostring(root, encoding="unicode") + "\n"
    with atomic_path(path) as tmp:  # as every output: a link under this name is replaced,
        tmp.write_text(text, encoding="utf-8")  # never written through
    return path


def inner_points(net: Network, cfg: dict) -> list[int]:
    """Indices of the estimated points of ``datum.points`` (default: all)."""
    index = name_index(net.names)
    sel = {a for p in cfg["datum.points"] or ["*"] for a in hits(p, net.names, index)}
    return [a for a in range(net.n) if net.role[a] != 1 and a in sel]


def _keyed(net: Network, cfg: dict) -> None:
    """Refuse what gama-local cannot take, naming the key of ``cfg`` that declares it (it
    named ``network.observations`` for a bias of ``network.generate`` and ``network.points``
    for a grid's points): a bias (:func:`sim.studies.network.linearity.row_key`); a point
    name with a run of spaces, which gama-local's PointID reads as one space ("A  B" as
    "A B"): a grid's or a random set's prefix, or the point's record."""
    if np.any(net.bias != 0):
        raise ConfigError(
            row_key(cfg, int(np.flatnonzero(net.bias)[0])),
            "gama-local has no observation bias: export a network without bias_*",
        )
    nm = next((nm for nm in net.names if "  " in nm), None)
    if nm is None:
        return
    key = "network.points"
    for a, rec in enumerate(cfg.get("network.points") or []):
        key = f"network.points[{a}].name" if rec.get("name") == nm else key
    for src in ("network.grids", "network.random"):
        for a, rec in enumerate(cfg.get(src) or []):
            pre = str(rec.get("prefix", ""))
            key = f"{src}[{a}].prefix" if nm[len(pre) :].isdigit() and nm.startswith(pre) else key
    raise ConfigError(
        key,
        f"point {nm!r}: gama-local reads a run of spaces in an id as one space "
        f"({' '.join(nm.split())!r}): name the point with single spaces",
    )


def export(net: Network, cfg: dict, path: str | Path) -> str:
    """Write ``network.xml`` in the datum of ``cfg``; returns the sentence for the summary
    (the file name, what was changed to say it in gama-local, or why it was not written)."""
    kind = cfg["datum.kind"]
    frame = tuple(cfg.get("network.gama_frame", NE))  # an imported file's frame, else ne
    try:
        _keyed(net, cfg)
        pts = [a for a in range(net.n) if net.role[a] != 1]
        inner = () if kind == "fixed" else inner_points(net, cfg) if kind == "inner" else pts
        write_gama(net, path, inner, frame)
    except ConfigError as e:
        return f"not exported: {e}"
    size = Path(path).stat().st_size  # over the reader's limit: said (a 50,000-point network)
    big = f" ({size / 2**20:.3g} MiB: over the {MAX_BYTES / 2**20:g} MiB network.gama_xml reads)"
    name = Path(path).name + big * (size > MAX_BYTES)
    if kind == "inner":
        return f'{name} (inner datum: adj="XY" on the datum points)'
    if kind == "fixed":
        return name
    return (
        f"{name}: datum.kind = constraints has no gama-local form; written as the "
        "free network in the inner datum over all its points (this study's precision moved "
        "by an S-transformation)"
    )
