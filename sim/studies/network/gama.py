"""Read and write a network in the XML input format of GNU Gama's ``gama-local``.

Supported (2-D, ``axes-xy = "ne"``: x north, y east, bearings clockwise from x -- the same
convention as this suite's x, y and bearings from +x towards +y):

* ``<point id x y fix="xy">`` (fixed), ``adj="xy"`` (free), ``adj="XY"`` (free and a datum
  point of the inner constraints); coordinates in metres, here mm;
* ``<obs from>`` sets of ``<direction to val stdev>`` (one orientation per set),
  ``<distance to val stdev>`` (stdev mm) and ``<angle bs fs val stdev>``; angles in gon with
  stdev in centesimal seconds (``angles = "400"``, the default) or in degrees with stdev in
  arcseconds (``angles = "360"``, decimal degrees only);
* ``<coordinates>`` with ``<point id x y>`` and a diagonal ``<cov-mat>`` (mm^2): observed
  coordinates (role ``observed``; the x and y variances must be equal);
* defaults ``distance-stdev``, ``direction-stdev``, ``angle-stdev`` of
  ``<points-observations>``.

Not supported (refused with a message): heights, slope distances, zenith angles, azimuths,
vectors, height differences, correlated covariance blocks, other axes orientations. On import
the observed values (``val``) are not used: the simulation draws readings from the points'
coordinates, which every point must therefore have. On export, ``val`` is the error-free value,
and settings are folded into the standard deviation; biases, the additive constant, the
offset, the scale of distances and coordinate differences have no ``gama-local`` form and
are refused.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from sim.mc.config import ConfigError
from sim.studies.network.definition import ARCSEC, KINDS, Network
from sim.studies.network.model import computed

__all__ = ["read_gama", "write_gama", "merge_gama"]

NS = "http://www.gnu.org/software/gama/gama-local"
CC = math.pi / 200 / 10000  # one centesimal second in rad
_UNSUPPORTED = (
    "s-distance",
    "z-angle",
    "azimuth",
    "vectors",
    "height-differences",
    "dh",
    "vec",
    "h-diff",
)


def _tag(e) -> str:
    return e.tag.split("}", 1)[-1]


def _f(key: str, e, attr: str, default: float | None = None) -> float:
    v = e.get(attr)
    if v is None:
        if default is None:
            raise ConfigError(key, f"<{_tag(e)}> lacks the attribute {attr!r}")
        return default
    try:
        x = float(v)
    except ValueError:
        raise ConfigError(key, f"<{_tag(e)} {attr}={v!r}> is not a number") from None
    if not math.isfinite(x):
        raise ConfigError(key, f"<{_tag(e)} {attr}={v!r}> is not finite")
    return x


def read_gama(path: str | Path, key: str = "network.gama_xml") -> dict:
    """Points and observations of a ``gama-local`` XML file as study records:
    ``{"network.points": [...], "network.observations": [...], "datum.points": [...]}``."""
    try:
        root = ET.parse(path).getroot()
    except OSError as e:
        raise ConfigError(key, f"cannot read {path}: {e.strerror}") from None
    except (ET.ParseError, UnicodeDecodeError) as e:
        raise ConfigError(key, f"{path} is not XML: {e}") from None
    if _tag(root) != "gama-local":
        raise ConfigError(key, f"{path}: the root element is <{_tag(root)}>, not <gama-local>")
    net = next((e for e in root if _tag(e) == "network"), None)
    if net is None:
        raise ConfigError(key, f"{path}: no <network> element")
    if net.get("axes-xy", "ne") != "ne":
        raise ConfigError(key, f"{path}: axes-xy={net.get('axes-xy')!r}; only 'ne' is supported")
    deg = net.get("angles", "400") == "360"
    unit, sunit = (math.pi / 180, ARCSEC) if deg else (math.pi / 200, CC)
    po = next((e for e in net if _tag(e) == "points-observations"), None)
    if po is None:
        raise ConfigError(key, f"{path}: no <points-observations> element")
    dstd = {k: po.get(f"{k}-stdev") for k in ("distance", "direction", "angle")}
    points, obs, datum_pts, coords = {}, [], [], []
    for e in po.iter():
        t = _tag(e)
        if t in _UNSUPPORTED:
            raise ConfigError(key, f"{path}: <{t}> is not supported (2-D networks only)")
    for e in po:
        t = _tag(e)
        if t == "point":
            pid = e.get("id")
            if not pid:
                raise ConfigError(key, f"{path}: a <point> without id")
            if e.get("x") is None or e.get("y") is None:
                raise ConfigError(
                    key,
                    f"{path}: point {pid!r} has no coordinates; the "
                    "simulation needs every point's coordinates",
                )
            fix, adj = e.get("fix", ""), e.get("adj", "")
            role = "fixed" if fix.lower() == "xy" else "free"
            if role == "free" and adj.lower() != "xy":
                raise ConfigError(
                    key, f'{path}: point {pid!r}: only fix="xy" or adj="xy"/"XY" is supported'
                )
            if adj == "XY":
                datum_pts.append(pid)
            points[pid] = {
                "name": pid,
                "x_mm": _f(key, e, "x") * 1000,
                "y_mm": _f(key, e, "y") * 1000,
                "role": role,
            }
        elif t == "obs":
            st = e.get("from")
            for o in e:
                ot = _tag(o)
                if ot == "direction":
                    s = _f(key, o, "stdev", _default(key, dstd["direction"]))
                    obs.append(
                        {
                            "kind": "direction",
                            "from": st,
                            "to": o.get("to"),
                            "sigma_arcsec": s * sunit / ARCSEC,
                        }
                    )
                elif ot == "distance":
                    s = _f(key, o, "stdev", _default(key, dstd["distance"]))
                    obs.append(
                        {
                            "kind": "distance",
                            "from": o.get("from", st),
                            "to": o.get("to"),
                            "sigma_mm": s,
                        }
                    )
                elif ot == "angle":
                    s = _f(key, o, "stdev", _default(key, dstd["angle"]))
                    obs.append(
                        {
                            "kind": "angle",
                            "at": o.get("from", st),
                            "from": o.get("bs"),
                            "to": o.get("fs"),
                            "sigma_arcsec": s * sunit / ARCSEC,
                        }
                    )
                elif ot != "cov-mat":
                    raise ConfigError(key, f"{path}: <{ot}> in <obs> is not supported")
        elif t == "coordinates":
            pts = [o for o in e if _tag(o) == "point"]
            cm = next((o for o in e if _tag(o) == "cov-mat"), None)
            if cm is None:
                raise ConfigError(key, f"{path}: <coordinates> needs a <cov-mat>")
            if int(_f(key, cm, "band", 0)) != 0:
                raise ConfigError(key, f'{path}: only a diagonal <cov-mat band="0"> is supported')
            var = [float(v) for v in (cm.text or "").split()]
            if len(var) != 2 * len(pts):
                raise ConfigError(
                    key, f"{path}: <cov-mat> has {len(var)} variances for {len(pts)} points"
                )
            for a, p in enumerate(pts):
                vx, vy = var[2 * a], var[2 * a + 1]
                if not (vx > 0 and math.isclose(vx, vy, rel_tol=1e-9)):
                    raise ConfigError(
                        key,
                        f"{path}: point {p.get('id')!r}: observed x and y "
                        "need one positive variance",
                    )
                coords.append((p.get("id"), math.sqrt(vx)))
        elif t not in ("description",):
            raise ConfigError(key, f"{path}: <{t}> is not supported")
    for pid, s in coords:
        if pid not in points:
            raise ConfigError(key, f"{path}: observed coordinates of unknown point {pid!r}")
        points[pid].update(role="observed", sigma_mm=s)
    return {
        "network.points": list(points.values()),
        "network.observations": obs,
        "datum.points": datum_pts,
    }


def _default(key: str, v) -> float | None:
    return None if v is None else float(v)


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
    rec = read_gama(path)
    out = {
        **cfg,
        "network.points": rec["network.points"],
        "network.observations": rec["network.observations"],
    }
    if rec["datum.points"] and not cfg["datum.points"]:
        out["datum.points"] = rec["datum.points"]
    return out


def _fmt(x: float) -> str:
    return repr(float(x))


def write_gama(net: Network, path: str | Path) -> Path:
    """Write ``net`` as ``gama-local`` XML (see the module doc for what is refused)."""
    if np.any(net.bias != 0):
        raise ConfigError(
            "network.observations",
            "gama-local has no observation bias: export a network without bias_*",
        )
    if net.constant_mm or net.estimate_constant or net.offset_mm:
        raise ConfigError(
            "network.constant_mm", "gama-local has no additive constant or offset of distances"
        )
    if net.scale_ppm or net.estimate_scale:
        raise ConfigError("network.scale_ppm", "gama-local has no scale parameter of distances")
    if np.any((net.kind == 3) | (net.kind == 4)):
        raise ConfigError(
            "network.observations", "gama-local has no 2-D coordinate differences (dx, dy)"
        )
    val = computed(net, net.theta_true()[None])[0]
    root = ET.Element("gama-local", xmlns=NS)
    nw = ET.SubElement(root, "network", {"axes-xy": "ne", "angles": "400"})
    ET.SubElement(nw, "description").text = net.name
    po = ET.SubElement(nw, "points-observations")
    for a, nm in enumerate(net.names):
        attr = {"id": nm, "x": _fmt(net.xy[a, 0] / 1000), "y": _fmt(net.xy[a, 1] / 1000)}
        attr.update({"fix": "xy"} if net.role[a] == 1 else {"adj": "xy"})
        ET.SubElement(po, "point", attr)
    for a in dict.fromkeys(net.i[net.kind <= 2]):
        o = ET.SubElement(po, "obs", {"from": net.names[a]})
        for r in np.flatnonzero((net.i == a) & (net.kind <= 2)):
            kd = KINDS[net.kind[r]]
            if kd == "distance":
                ET.SubElement(
                    o,
                    "distance",
                    {
                        "to": net.names[net.j[r]],
                        "val": _fmt(val[r] / 1000),
                        "stdev": _fmt(net.sigma[r]),
                    },
                )
            elif kd == "direction":
                ET.SubElement(
                    o,
                    "direction",
                    {
                        "to": net.names[net.j[r]],
                        "val": _fmt(val[r] / (math.pi / 200) % 400),
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
                        "val": _fmt(val[r] / (math.pi / 200)),
                        "stdev": _fmt(net.sigma[r] / CC),
                    },
                )
    obs_pts = np.flatnonzero(net.role == 2)
    if obs_pts.size:
        c = ET.SubElement(po, "coordinates")
        for a in obs_pts:
            ET.SubElement(
                c,
                "point",
                {
                    "id": net.names[a],
                    "x": _fmt(net.xy[a, 0] / 1000),
                    "y": _fmt(net.xy[a, 1] / 1000),
                },
            )
        sig = {int(a): s for a, s in zip(net.i[net.kind == 5], net.sigma[net.kind == 5])}
        cm = ET.SubElement(c, "cov-mat", {"dim": str(2 * obs_pts.size), "band": "0"})
        cm.text = " ".join(_fmt(sig[int(a)] ** 2) for a in obs_pts for _ in (0, 1))
    ET.indent(root)
    path = Path(path)
    path.write_text('<?xml version="1.0" ?>\n' + ET.tostring(root, encoding="unicode") + "\n")
    return path
