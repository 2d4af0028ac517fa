"""``gama-local``'s test of absolute terms, which removes observations before it adjusts.

Before its adjustment ``gama-local`` (2.03, ``LocalNetwork::remove_huge_abs_terms``) compares
each observed value (``val``) with the value the coordinates of the file give: the absolute
term of its project equation, in millimetres (for a distance ``|val - d0|``, for a ``dx``,
``dy`` or ``dz`` ``|val - dx0|``, for a direction and an angle the angle between them,
wrapped to half a turn, times the distance ``d0`` to its (back) sight; a direction's
orientation is its ``<obs orientation>``, in radians as ``gama-local`` reads it, or else the
median of ``bearing - val`` over the set, as its ``Orientation::orientation`` computes it).
When one term exceeds ``tol-abs`` (``<parameters tol-abs>``, 1000 mm by default), it removes
every distance and vector whose term exceeds it and every direction and angle whose term
*weighted* (times ``sigma-apr / stdev``, the stdev in cc: their terms are read from the
equations homogenised by then) exceeds it ("Observations with outlying absolute terms
removed") and adjusts the rest: another network, another precision. This suite draws its
readings from the coordinates and uses no ``val``: it would keep them, so :func:`check_terms`
refuses such a file, naming the first. (A ``dz`` between fixed heights takes part in the
test; it has no unknown here, so its own removal only changes ``gama-local``'s degrees of
freedom: the note names it. Observed coordinates are tested against the point's last
given coordinates, its ``<point>``'s when that comes after them. A set of one direction is
passive in ``gama-local`` (``revision_observations``: fewer than two targets), neither adjusted
nor tested: no term here.)"""

from __future__ import annotations

import math

from sim.studies.network.definition import ARCSEC
from sim.studies.network.gama_frames import consistent
from sim.studies.network.gama_vocab import _DMS, CC, _tag, ws

__all__ = ["TOL_ABS_MM", "SIGMA_APR", "angle_rad", "terms", "removed", "check_terms"]

#: gama-local's default tol-abs (mm) and sigma-apr
TOL_ABS_MM = 1000.0
SIGMA_APR = 10.0


def angle_rad(text: str) -> float:
    """An angular ``val`` in radians as ``gama-local`` reads it (``deg2gon``: ``d-m-s`` in
    degrees, a signed value negative only when not zero; else gon). Checked already."""
    v = ws(text)
    if _DMS.match(v):
        d, m, s = v.lstrip("+-").split("-", 2)
        # float: int() of 5,000 digits ("1-000...01-0", 1 degree 1 minute) is a ValueError
        gon = (float(d) / 360 + float(m) / 21600 + float(s) / 1296000) * 400
        return (-gon if v.startswith("-") else gon) * math.pi / 200
    return float(v) * math.pi / 200


def _wrap(a: float) -> float:
    """``a`` (rad) into [-pi, pi], as gama-local wraps an absolute term (in cc): the IEEE
    remainder by a turn, in one step. gama-local subtracts turn after turn, as this did: a
    ``val="1e15"`` (gon) of a direction, or an ``<obs orientation>`` of 1e15 radians, ran
    ``sim check`` and every run for ever (gama-local 2.03 does not end on that file either;
    a val is a finite float, :mod:`sim.studies.network.gama_vocab`)."""
    return math.remainder(a, 2 * math.pi)


def _median_orientation(sz: list[float]) -> float:
    """``gama-local``'s approximate orientation of a set: the median of ``bearing - val``,
    each wrapped to half a turn (of two values more than a quarter turn apart: the lower)."""
    sz = sorted(sz)
    n = len(sz)
    lo, hi = sz[(n - 1) // 2], sz[n // 2]
    return lo if abs(hi - lo) > math.pi / 2 and n < 3 else (lo + hi) / 2


def _heights(po) -> dict:
    """Point name -> its fixed height (m), of the points whose ``z`` is fixed: ``gama-local``
    adjusts a ``dz`` between two of them (its only one tested here)."""
    z: dict = {}
    for p in (e for e in po.iter() if _tag(e) == "point" and e.get("z") is not None):
        if "z" in ws(p.get("fix", "")).lower():
            z[" ".join(ws(p.get("id")).split())] = float(ws(p.get("z")))
    return z


def terms(f, po, points: dict, y_sign: float) -> list:
    """``(element, absolute term in mm, kind)`` of every observation of
    ``<points-observations>`` ``po``, in the reader's order (kind ``dz``: a vector's third
    row, which the reader drops; ``passive``: the direction of a set of one, no term in
    ``gama-local``; or the attribute the term is in: ``val``, ``orientation``, ``dx``,
    ``dy``). ``points``: name -> record with ``x_mm``, ``y_mm``; ``y_sign``: -1
    where the file's angles run against its frame (``gama-local`` negates every y); ``f``:
    the reader's error helper (its ``name`` reads a point name as the reader did)."""

    def xy(name: str) -> tuple[float, float]:
        p = points[name]
        return p["x_mm"] / 1000, y_sign * p["y_mm"] / 1000

    def bearing(a: str, b: str) -> tuple[float, float]:
        (xa, ya), (xb, yb) = xy(a), xy(b)
        return math.atan2(yb - ya, xb - xa), math.hypot(xb - xa, yb - ya)

    out: list = []
    z = _heights(po)
    for e in po:
        if _tag(e) == "obs":
            st = f.name(e, "from") if e.get("from") is not None else None
            kids = [o for o in e if _tag(o) != "cov-mat"]
            dirs = {
                id(o): (angle_rad(o.get("val")), *bearing(st, f.name(o, "to")))
                for o in kids
                if _tag(o) == "direction"
            }
            lone = len(dirs) == 1  # gama-local sets it passive: not adjusted, not tested
            ori = e.get("orientation")
            if dirs:
                sz = [_wrap(s - v) for v, s, _ in dirs.values()]
                zero = float(ws(ori)) if ori is not None else _median_orientation(sz)
            for o in kids:
                if _tag(o) == "distance":
                    _, d0 = bearing(f.name(o, "from", st), f.name(o, "to"))
                    out.append((o, abs(float(ws(o.get("val"))) - d0) * 1000, "val"))
                elif _tag(o) == "direction" and lone:
                    out.append((o, 0.0, "passive"))
                elif _tag(o) == "direction":
                    v, s, d0 = dirs[id(o)]
                    why = "val" if ori is None else "orientation"
                    out.append((o, abs(_wrap(v + zero - s)) * d0 * 1000, why))
                else:  # angle
                    at = f.name(o, "from", st)
                    bs = f.name(o, "bs" if o.get("bs") is not None else "to")
                    fs = f.name(o, "fs" if o.get("fs") is not None else "rs")
                    (s1, d1), (s2, _) = bearing(at, bs), bearing(at, fs)
                    ds = s2 - s1 + (2 * math.pi if s2 < s1 else 0.0)
                    out.append((o, abs(_wrap(angle_rad(o.get("val")) - ds)) * d1 * 1000, "val"))
        elif _tag(e) == "coordinates":  # the point's last given x, y (mm) against these
            for c in (o for o in e if _tag(o) == "point"):
                pt = points[f.name(c, "id")]
                for ax in ("x", "y"):
                    out.append((c, abs(pt[f"{ax}_mm"] - f.mm(c, ax)), ax))
        elif _tag(e) == "vectors":
            for v in (o for o in e if _tag(o) == "vec"):
                a, b = f.name(v, "from"), f.name(v, "to")
                (xa, ya), (xb, yb) = xy(a), xy(b)
                out.append((v, abs(float(ws(v.get("dx"))) - (xb - xa)) * 1000, "dx"))
                out.append((v, abs(y_sign * float(ws(v.get("dy"))) - (yb - ya)) * 1000, "dy"))
                if a in z and b in z:
                    out.append((v, abs(float(ws(v.get("dz"))) - (z[b] - z[a])) * 1000, "dz"))
    return out


def removed(found: list, recs: list, tol_mm: float, m0: float) -> list:
    """What ``gama-local`` removes of ``found`` (:func:`terms`; ``recs``: the reader's
    observation records, one a term but ``dz``): nothing unless a term exceeds ``tol_mm``;
    then every distance and vector whose term does and every direction and angle whose term
    times ``m0 / stdev`` (stdev in cc) does, ``(element, term, weighted term, kind)``."""
    if not any(term > tol_mm for _, term, _ in found):
        return []
    out, rows = [], iter(recs)
    for e, term, kind in found:
        if kind == "dz":
            continue  # no unknown, no record here
        if kind in ("x", "y"):  # observed coordinates: no record here, the raw term
            if term > tol_mm:
                out.append((e, term, term, kind))
            continue
        rec = next(rows)  # an angle's or a direction's term is homogenised there by then
        if kind == "passive":
            continue
        angular = _tag(e) in ("direction", "angle")
        weighted = term * m0 / (rec["sigma_arcsec"] * ARCSEC / CC) if angular else term
        if weighted > tol_mm:
            out.append((e, term, weighted, kind))
    return out


def check_terms(f, net, po, points: dict, recs: list, frame: tuple[str, str]) -> str:
    """Refuse, in one line naming the observation, a file in which ``gama-local`` would remove
    an observation for its absolute term (:func:`removed`): this suite would keep it. When
    the one named is removed for its weighted term only, the line names the term that starts
    the test (a ``dz`` perhaps). Returns a note ("" or the ``dz`` terms ``gama-local`` removes
    alone: this suite drops every ``dz``, so the networks are the same)."""
    pars = [e for e in net if _tag(e) == "parameters"]
    tol = pars[0].get("tol-abs") if pars else None
    m0 = pars[0].get("sigma-apr") if pars else None
    tol_mm = TOL_ABS_MM if tol is None else float(ws(tol))
    m0 = SIGMA_APR if m0 is None else float(ws(m0))
    found = terms(f, po, points, 1.0 if consistent(*frame) else -1.0)
    gone = removed(found, recs, tol_mm, m0)
    dz = [(e, term) for e, term, kind in found if kind == "dz" and term > tol_mm]
    if not gone:
        if not dz:
            return ""
        more = f" and {len(dz) - 1} more" * (len(dz) > 1)
        return (
            f"; gama-local removes the dz of {_named(dz[0][0])}{more} before it adjusts "
            f'("Outlying absolute terms": {dz[0][1]:.6g} mm from the fixed heights, over '
            f"tol-abs = {tol_mm:g} mm), as this study drops every dz"
        )
    e, term, weighted, kind = gone[0]
    n_more = len(gone) - 1 + len(dz)
    more = f" (and {n_more} more)" if n_more else ""
    ori = (
        f" with the orientation of its <obs>, {ws(e_ori)} radians as gama-local reads it,"
        if kind == "orientation" and (e_ori := _orientation_of(po, e)) is not None
        else ""
    )
    how = f", {weighted:.6g} mm weighted by sigma-apr / stdev," if weighted != term else ""
    why = ""
    if term <= tol_mm:  # removed for its weighted term: what starts the test is another's
        te, tt, tk = next(x for x in found if x[1] > tol_mm)
        what = f"the {tk} of {_named(te)}" if tk in ("dx", "dy", "dz", "x", "y") else _named(te)
        why = f" (the test runs as {what} is {tt:.6g} mm off)"
    raise f.err(
        e,
        f'gama-local removes this observation{more} before it adjusts ("Outlying absolute '
        f'terms"{why}): its value{ori} is {term:.6g} mm from what the coordinates give{how} '
        f"over tol-abs = {tol_mm:g} mm; this suite draws its readings from the coordinates and "
        "would keep it: correct the value or the coordinates, or remove the observation",
        "val" if kind in ("val", "orientation") else kind,
    )


def _named(e) -> str:
    """An observation element by its points: ``<vec from='C' to='D'>``."""
    attrs = " ".join(f"{a}={ws(e.get(a))!r}" for a in ("id", "from", "to", "bs", "fs") if e.get(a))
    return f"<{_tag(e)} {attrs}>" if attrs else f"<{_tag(e)}>"


def _orientation_of(po, e) -> str | None:
    """The ``orientation`` of the ``<obs>`` that holds ``e``."""
    return next((o.get("orientation") for o in po if any(k is e for k in o)), None)
