"""Read a network from GNU Gama's ``gama-local`` XML input (version 2.x), defensively.

Every element and attribute is checked against ``gama-local``'s own vocabulary (its schema
``gama-local.xsd`` and its parser): an unknown element, attribute or value, a garbage number,
a point declared twice with different coordinates, ... is one :class:`ConfigError` line that
names the file, the element and the attribute. Only a regular file of at most
:data:`MAX_BYTES` is read (a FIFO or a device is refused before it is opened).

What maps to what (2-D, ``axes-xy = "ne"``, left-handed angles: x north, y east, bearings
clockwise from x -- this suite's x, y and bearings from +x towards +y). Every frame
``gama-local`` reads is read (``axes-xy``: ne, es, sw, wn and the right-handed en, nw, se, ws;
``angles``: left- or right-handed), its coordinates as they are: the suite's bearings run from
+x towards +y, which is the file's convention when frame and angles have the same handedness;
when they do not, each direction and angle of the file is the suite's with its sign changed,
a change of sign of its design row (and of the orientation unknown) that leaves the normals,
hence every covariance, unchanged. Covariances are in the file's frame (``note`` names it;
tests/test_gama27.py compares all 16 combinations with ``gama-local``).

* ``<point id x y fix="xy">`` -> role ``fixed``; ``adj="xy"`` -> ``free``; ``adj="XY"`` ->
  free and a datum point of the inner constraints (``datum.points``); metres -> mm. A ``z``
  is allowed only fixed (``fix="z"``, ``"xyz"``, ...): height unknowns are refused.
* each ``<obs from>`` is one station set: its ``<direction>`` elements share one orientation
  unknown (a second ``<obs>`` at the same station is a second set, ``set = "2"``);
  ``<distance>`` (stdev mm) and ``<angle bs fs>``.
* angle units as ``gama-local`` reads them, per value: a decimal ``val`` is in gon with its
  stdev in centesimal seconds (cc); a ``d-m-s`` value (``57-32-28.4``) is in degrees with its
  stdev in arcseconds. The default stdevs of ``<points-observations>`` follow the same rule,
  and ``distance-stdev = "a b c"`` is ``a + b D^c`` mm with D the observed distance in km.
* a ``<cov-mat>`` in ``<obs>``, ``<coordinates>`` or ``<vectors>`` gives the variances (mm^2,
  cc^2 or arcsec^2); a non-zero covariance (correlated observations) is refused.
* ``<coordinates>``: observed coordinates (role ``observed``; x and y variances equal);
  ``<vectors>``: ``dx`` and ``dy`` observations (their ``dz`` needs fixed heights and is
  dropped).
* ``<parameters>`` is read and checked; the study always uses the a-priori standard
  deviations (a pre-analysis has no residuals), and :func:`read_gama` says so in ``note``
  when the file asks for ``sigma-act = "aposteriori"`` (``gama-local``'s default).

Refused with one line: heights and 3-D data (``z-angle``, ``s-distance``,
``height-differences``, free heights), azimuths, an ``axes-xy`` or ``angles`` outside
``gama-local``'s vocabulary, correlated covariance blocks. The observed values (``val``) are
checked as numbers but not used otherwise: the simulation draws readings from the points'
coordinates, which every point must therefore have.
"""

from __future__ import annotations

import hashlib
import math
import xml.etree.ElementTree as ET
from pathlib import Path

from sim.mc.config import ConfigError
from sim.studies.network import gama_vocab as vocab
from sim.studies.network.definition import ARCSEC, COORDINATE_MAX_MM
from sim.studies.network.gama_encoding import (
    EncodingProblem,
    bom_note,
    gama_text,
    undecodable,
    utf8_note,
)
from sim.studies.network.gama_frames import NE, frame_note
from sim.studies.network.gama_prolog import default_declared, entity_declared, raw_name_problem
from sim.studies.network.gama_sets import one_target
from sim.studies.network.gama_stdev import default_stdevs, distance_default, sigma, variances
from sim.studies.network.gama_terms import check_terms
from sim.studies.network.gama_vocab import CC, MAX_BYTES, NS, _File, _tag, read_bytes, ws
from sim.studies.network.validate import looks_like

__all__ = ["read_gama", "read_bytes", "MAX_BYTES", "CC", "NS"]


def _xy(f: _File, e) -> tuple[float, float]:
    """The coordinates (mm) of a ``<point>`` (also one in ``<coordinates>``), in range."""
    xy = (f.mm(e, "x"), f.mm(e, "y"))
    for ax, v in zip("xy", xy):
        if not abs(v) <= COORDINATE_MAX_MM:  # no coordinate on the earth, by the element
            raise f.err(e, f"{v / 1000:g} m: over 100,000 km, out of range", ax)
    return xy


def _point(f: _File, e, points: dict, datum: dict, moved: list) -> None:
    """A ``<point>``: its coordinates (mm), role and datum. Given again after observed
    coordinates moved it (``moved``), it is the last given, as in ``gama-local``: the point
    goes back to it, compared with its first ``<point>`` (it was refused as "declared twice
    with different coordinates" when both ``<point>`` elements gave the same)."""
    pid = f.name(e, "id")
    fix, adj = ws(e.get("fix", "")), ws(e.get("adj", ""))
    if "z" in adj.lower():
        raise f.err(e, f"adj={adj!r}: height unknowns are not supported (2-D networks)", "adj")
    if fix and adj and "xy" in fix.lower() and "xy" in adj.lower():
        raise f.err(  # (gama-local: fix wins; a point both is likely a slip of the file)
            e,
            f"point {pid!r} is both fixed and adjusted in xy (gama-local holds it fixed): "
            "give it one of fix and adj",
            "fix",
        )
    rec = points.setdefault(pid, {"name": pid})
    if e.get("x") is not None or e.get("y") is not None:
        xy = _xy(f, e)
        first = next((m[2] for m in moved if m[0] == pid), None)  # before <coordinates>
        if "x_mm" in rec and (first or (rec["x_mm"], rec["y_mm"])) != xy:
            raise f.err(e, f"point {pid!r} declared twice with different coordinates", "x")
        moved[:] = [m for m in moved if m[0] != pid] if first else moved
        rec["x_mm"], rec["y_mm"] = xy
    if e.get("z") is not None:
        f.num(e, "z")
    role = "fixed" if "xy" in fix.lower() else "free" if "xy" in adj.lower() else None
    if role is not None:
        if rec.get("role", role) != role:
            raise f.err(e, f"point {pid!r} declared fixed and adjusted", "fix" if fix else "adj")
        rec["role"] = role
    if "XY" in adj:
        datum[pid] = None  # ordered, each once (a list's "in" made thousands of points n^2)
    elif adj:  # the last adj holds, as in gama-local: adj="xy" after adj="XY" frees the point
        datum.pop(pid, None)


def _obs(f: _File, e, dflt: dict, sets: dict, out: list) -> None:
    st = f.name(e, "from") if e.get("from") is not None else None
    if e.get("orientation") is not None:  # radians, as gama-local reads it
        f.turns(e, "orientation", f.num(e, "orientation") / (2 * math.pi))
    if e.get("from_dh") is not None:
        f.num(e, "from_dh")
    kids = list(e)
    cms = [o for o in kids if _tag(o) == "cov-mat"]
    obs = [o for o in kids if _tag(o) != "cov-mat"]  # the <cov-mat> last: gama_vocab checks
    if not obs:  # (read here as no set: another file than gama-local's, which it refuses)
        raise f.err(
            e,
            "holds no observation (gama-local refuses the file: the set's empty covariance "
            'matrix "is not positive definite"): remove it',
        )
    var = list(variances(f, cms[0], len(obs))) if cms else [None] * len(obs)
    label = ""
    if dirs := [o for o in obs if _tag(o) == "direction"]:
        if st is None:
            raise f.err(e, "directions need the station", "from")
        if len(dirs) > 1 and len(targets := {f.name(o, "to") for o in dirs}) == 1:
            raise f.err(dirs[1], one_target(st, targets.pop(), len(dirs)))
        sets[st] = sets.get(st, 0) + 1
        label = "" if sets[st] == 1 else str(sets[st])
    for o, v in zip(obs, var):
        t = _tag(o)
        for a in ("from_dh", "to_dh", "bs_dh", "fs_dh"):
            if o.get(a) is not None:
                f.num(o, a)
        if t == "distance":
            d_m = f.num(o, "val", lo=0.0)
            dd = distance_default(dflt["distance"], d_m)
            rec = {"kind": "distance", "from": f.name(o, "from", st), "to": f.name(o, "to")}
            rec["sigma_mm"] = sigma(f, o, dd, v)
        elif t == "direction":
            unit = ARCSEC if f.angle(o) else CC
            s = sigma(f, o, dflt["direction"], v, unit)
            rec = {"kind": "direction", "from": st, "to": f.name(o, "to")}
            rec["sigma_arcsec"] = s * unit / ARCSEC
            if label:
                rec["set"] = label
        else:  # angle
            unit = ARCSEC if f.angle(o) else CC
            s = sigma(f, o, dflt["angle"], v, unit)
            bs, fs = (_sight(f, o, a, b) for a, b in (("bs", "to"), ("fs", "rs")))
            rec = {"kind": "angle", "at": f.name(o, "from", st), "from": bs, "to": fs}
            rec["sigma_arcsec"] = s * unit / ARCSEC
        out.append(rec)


def _sight(f: _File, o, attr: str, alias: str) -> str:
    """The point an angle's back or fore sight names: ``attr`` or its alias (``bs`` or
    ``to``, ``fs`` or ``rs``), one of the two, read as a point name of the element."""
    given = [a for a in (attr, alias) if o.get(a) is not None]
    if not given:
        raise f.err(o, "an angle needs bs and fs (or to and rs)", attr)
    if len(given) == 2:
        raise f.err(o, f"{attr!r} and {alias!r} both name this sight: give one", alias)
    return f.name(o, given[0])


def _coordinates(f: _File, e, coords: list, points: dict, moved: list) -> None:
    """Observed coordinates (``coords``: name, sigma in mm, (x, y) in mm). As in
    ``gama-local`` (whose ``<coordinates>`` point sets the point's x and y, the last given
    holding), a point declared before with other coordinates moves to the observed ones
    (``moved``: name, distance in mm and the ``<point>``'s x, y in mm, for the note): it is
    linearised and its observations' absolute terms tested there (its ``<point>`` kept had
    kept observations that ``gama-local`` removes, and another geometry, silently)."""
    pts = [o for o in e if _tag(o) == "point"]
    cms = [o for o in e if _tag(o) == "cov-mat"]
    if len(cms) != 1:
        raise f.err(e, "needs one <cov-mat> (the variances of x and y, mm^2)")
    for p in pts:
        if p.get("z") is not None or p.get("fix") or p.get("adj"):
            raise f.err(p, "observed coordinates take id, x and y only (2-D)", "z")
    var = variances(f, cms[0], 2 * len(pts))
    for a, p in enumerate(pts):
        vx, vy = var[2 * a], var[2 * a + 1]
        if not math.isclose(vx, vy, rel_tol=1e-9):
            raise f.err(
                cms[0], f"point {vocab.said(p.get('id') or '')}: observed x and y need one variance"
            )
        pid, xy = f.name(p, "id"), _xy(f, p)
        coords.append((pid, math.sqrt(vx), xy))
        rec = points.get(pid, {})
        if "x_mm" in rec and (rec["x_mm"], rec["y_mm"]) != xy:
            old = (rec["x_mm"], rec["y_mm"])
            moved.append((pid, math.dist(old, xy), old))
            rec["x_mm"], rec["y_mm"] = xy


def _vectors(f: _File, e, out: list) -> None:
    vecs = [o for o in e if _tag(o) == "vec"]
    cms = [o for o in e if _tag(o) == "cov-mat"]
    if len(cms) != 1:
        raise f.err(e, "needs one <cov-mat> (the variances of dx, dy, dz, mm^2)")
    var = variances(f, cms[0], 3 * len(vecs))
    for a, v in enumerate(vecs):
        fr, to = f.name(v, "from"), f.name(v, "to")
        for c in ("dx", "dy", "dz"):
            f.num(v, c)
        for c in ("from_dh", "to_dh"):  # numbers there too ("bad instrument/reflector height")
            if v.get(c) is not None:
                f.num(v, c)
        out.append({"kind": "dx", "from": fr, "to": to, "sigma_mm": math.sqrt(var[3 * a])})
        out.append({"kind": "dy", "from": fr, "to": to, "sigma_mm": math.sqrt(var[3 * a + 1])})


#: GNU Gama's other XML files, as its own tree holds them beside gama-local's inputs
_OTHER_ROOTS = {
    "gama-local-adjustment": " (gama-local's output, its --xml adjustment: give the input it read)",
    "gnu-gama-data": " (GNU Gama's gama-g3 data, a 3-D adjustment this suite does not read)",
}


def _network(f: _File, data: bytes):
    """The ``<network>`` element of the file's bytes, its root and attributes checked."""
    key, path = f.key, f.path
    try:  # the characters gama-local reads: its own encodings (cp-1250, ...) decoded as there
        text = gama_text(data)
    except EncodingProblem as why:
        raise ConfigError(key, f"{path}: {why}") from None
    if ent := entity_declared(text):
        raise ConfigError(
            key,
            f"{path}: its <!DOCTYPE> declares the entity {ent}: entity declarations are not read "
            "(a gama-local file needs none; write the values in place)",
        )
    if found := default_declared(text):
        el, att, v = found
        raise ConfigError(
            key,
            f"{path}: its <!DOCTYPE> gives <{el[:40]}> attribute {att[:40]!r} the default "
            f"{vocab.said(v)}: "
            "attribute defaults are not read (a gama-local file needs none; write the value on "
            "the elements, a default stdev on <points-observations>)",
        )
    try:
        root = ET.fromstring(text)
    except ET.ParseError as e:  # at bytes not of the file's encoding: said so ("invalid token")
        bad = undecodable(data) if isinstance(text, bytes) else None
        if bad and bad[0] <= e.position[0]:
            raise ConfigError(key, f"{path}: {bad[1]}") from None
        raise ConfigError(key, f"{path} is not XML: {e}") from None
    except (LookupError, ValueError) as e:  # an unknown encoding declared, undecodable bytes
        raise ConfigError(key, f"{path} cannot be decoded: {e}") from None
    if _tag(root) != "gama-local":  # first: an <html lang="en"> was refused for its attribute
        what = _OTHER_ROOTS.get(_tag(root), "")
        raise ConfigError(
            key, f"{path}: the root element is <{_tag(root)}>, not <gama-local>{what}"
        )
    if why := raw_name_problem(text):  # names as gama-local reads them
        raise ConfigError(key, f"{path}: {why}")
    vocab.drop_empty(root)  # x="", stdev="": absent, as gama-local reads them
    f.vocab(root)
    nets = [e for e in root if _tag(e) == "network"]
    if len(nets) != 1:
        raise f.err(root, f"{len(nets)} <network> elements (need one)")
    net = nets[0]
    if net.get("epoch") is not None:
        f.num(net, "epoch")
    return net


def _resolve(f: _File, points: dict, coords: list, obs: list) -> list[str]:
    """Every point has coordinates and a role; observed coordinates and observations name
    declared points. A point without coordinates, without a role in xy or adjusted that
    nothing observes is left out, as ``gama-local`` leaves it ("Removed points ... missing
    coordinates", "singular coordinates": an adj one was refused); its name is returned. One that is observed is refused, with what
    ``gama-local`` does instead."""
    key, path = f.key, f.path
    for pid, _, xy in coords:  # a point's coordinates given only there: gama-local reads them
        if pid in points and "x_mm" not in points[pid]:
            points[pid]["x_mm"], points[pid]["y_mm"] = xy
    seen = {rec[k] for rec in obs for k in ("from", "to", "at") if k in rec}
    seen.update(pid for pid, _, _ in coords)
    # (an adj point with coordinates too: gama-local removes it, "singular coordinates")
    left = [p for p, r in points.items() if p not in seen and r.get("role") in (None, "free")]
    out = set(left)  # (a set: a list's `in` took minutes over 150,000 such points)
    left += [p for p, r in points.items() if p not in seen and "x_mm" not in r and p not in out]
    declared = dict(points)  # (a name that looks like one left out is still named)
    for pid in left:
        del points[pid]
    for pid, rec in points.items():
        if "x_mm" not in rec:
            raise ConfigError(
                key,
                f"{path}: <point id={pid!r}> has no coordinates; the simulation needs every "
                "point's coordinates (gama-local computes approximate ones from the observed "
                "values, which this suite does not use)",
            )
        if "role" not in rec:
            raise ConfigError(
                key,
                f"{path}: <point id={pid!r}> is neither fix nor adj in xy (gama-local leaves "
                "it out of the adjustment with every observation of it; this suite drops no "
                'observation: give it fix="xy" or adj="xy", or remove it and its observations)',
            )
    for pid, s, _ in coords:
        if pid not in points:
            raise ConfigError(
                key, f"{path}: <coordinates>: observed coordinates of unknown point {pid!r}"
            )
        if points[pid]["role"] == "fixed":
            raise ConfigError(
                key,
                f"{path}: <coordinates>: point {pid!r} is fixed (gama-local keeps its observed "
                "coordinates as two equations with no unknown, which only add to the degrees of "
                "freedom; this suite's point is fixed or observed): observe a free point",
            )
        if points[pid]["role"] == "observed":  # gama-local adjusts both observations
            raise ConfigError(
                key,
                f"{path}: <coordinates>: the coordinates of point {pid!r} are observed twice; "
                "this suite takes one observation of a point (one sigma_mm): give them once",
            )
        points[pid].update(role="observed", sigma_mm=s)
    for rec in obs:
        for fld in ("from", "to", "at"):
            if fld in rec and rec[fld] not in points:
                like = looks_like(rec[fld], declared)  # Cyrillic А for A, decomposed É
                raise ConfigError(
                    key, f"{path}: <{rec['kind']}> {fld}={rec[fld]!r}: no such <point>{like}"
                )
    return left


def read_gama(path: str | Path, key: str = "network.gama_xml", sha256: str | None = None) -> dict:
    """Points and observations of a ``gama-local`` XML file as study records:
    ``{"network.points", "network.observations", "datum.points", "note", "frame"}`` (``note``:
    the ``<parameters>`` convention used and the frame, one sentence; ``frame``: ``(axes-xy,
    angles)``). ``sha256``: the digest the study recorded
    on load; bytes of another digest (the file edited since) are refused, so a run never
    simulates a network other than the one its config names."""
    path = Path(path)
    f = _File(key, path)
    data = read_bytes(path, key)
    if sha256 and (now := hashlib.sha256(data).hexdigest()) != sha256:
        raise ConfigError(
            "network.gama_sha256",
            f"{path} has changed since the study was loaded (sha256 {now[:12]}..., recorded "
            f"{sha256[:12]}...): load the study again",
        )
    if utf8_note(data):  # a name refused for characters the declaration made of UTF-8 bytes
        f.names_hint = ' (the file\'s bytes are UTF-8: declare encoding="UTF-8")'
    net = _network(f, data)
    note = vocab.parameters_note(f, [e for e in net if _tag(e) == "parameters"])
    axes = ws(net.get("axes-xy", NE[0]))  # gama-local's vocabulary, checked in _network
    angles = ws(net.get("angles", NE[1]))
    note += frame_note(axes, angles) + bom_note(data) + utf8_note(data)
    pos = [e for e in net if _tag(e) == "points-observations"]
    if len(pos) != 1:
        raise f.err(net, f"{len(pos)} <points-observations> elements (need one)")
    po = pos[0]
    dflt = default_stdevs(f, po)
    points: dict = {}
    obs: list = []
    datum: dict = {}
    coords: list = []
    moved: list = []
    sets: dict = {}
    for e in po:
        t = _tag(e)
        if t == "point":
            _point(f, e, points, datum, moved)
        elif t == "obs":
            _obs(f, e, dflt, sets, obs)
        elif t == "coordinates":
            _coordinates(f, e, coords, points, moved)
        elif t == "vectors":
            _vectors(f, e, obs)
        else:
            raise f.err(e, "not allowed in <points-observations>")
    left = _resolve(f, points, coords, obs)
    note += check_terms(f, net, po, points, obs, (axes, angles))  # it removes: refused
    if moved:
        (pid, d, _), more = moved[0], f" and {len(moved) - 1} more" * (len(moved) > 1)
        note += (
            f"; {pid!r}{more} at its observed coordinates (<coordinates>, {d:.6g} mm from its "
            "<point>), as gama-local takes the last given"
        )
    if f.sexagesimal:  # read as gama-local reads them, and named: a slip of the file, likely
        (tag, attr, v), n = f.sexagesimal[0], len(f.sexagesimal)
        more = f" and {n - 1} more" * (n > 1)
        note += (
            f"; d-m-s values with minutes or seconds of 60 or more read as gama-local reads "
            f"them, d + m/60 + s/3600: <{tag}> {attr}={vocab.said(v)}{more}"
        )
    if left:  # listed, never observed, no coordinates or no role: gama-local removes them
        more = f" and {len(left) - 5} more" * (len(left) > 5)
        few = ", ".join(repr(p) for p in left[:5]) + more
        note += (
            f"; left out, as gama-local leaves them: {few} (nothing observes them, and each "
            "is adj, without coordinates or neither fix nor adj in xy)"
        )
        datum = {p: None for p in datum if p in points}
    return {
        "network.points": list(points.values()),
        "network.observations": obs,
        "datum.points": list(datum),
        "note": note,
        "frame": (axes, angles),
    }
