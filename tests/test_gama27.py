"""GNU Gama files in every frame ``gama-local`` reads (brief G27): ``axes-xy`` (8) x ``angles``
(2), against ``gama-local`` 2.03 (the comparisons skip without it: ``$GAMA_LOCAL``).

Three reference networks of tests/data/gama (``ne``, left-handed: directions in two sets, an
angle and distances; a free network of directions in the inner datum; observed coordinates
and coordinate-difference vectors) are written in each frame: coordinates mapped into it,
``val`` recomputed in its convention so that ``gama-local``'s adjustment converges. What the
harness found:

* the network is the same in every combination: ``gama-local``'s covariance of each point is
  ne's mapped into the frame, ``M C M'`` (M: the frame's axes in n, e), to its 8 printed
  digits. A direction's or angle's sense (clockwise or counter-clockwise) flips the sign of
  its row of the design (with its orientation unknown's) and leaves the normals unchanged;
* ``gama-local`` adjusts a file whose angles run against its frame (a left-handed frame with
  right-handed angles, or the reverse) with every y negated (``remove_inconsistency``) and
  writes its XML ``<cov-mat>`` in that internal frame: cov(x, y) there has the opposite sign
  of the file's frame, in which it writes the adjusted coordinates. Its text output's ellipse
  bearing alpha runs from +x in the sense of the file's angles in every combination.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from test_doors20d import gama_cov, needs_gama, ours, study_of

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests/data/gama"
NS = "http://www.gnu.org/software/gama/gama-local"
CASES = ("two_sets", "directions_free", "plate")
LEFT = ("ne", "es", "sw", "wn")  # x to y clockwise, as gama-local's default angles run
RIGHT = ("en", "nw", "se", "ws")
COMBOS = [(ax, ang) for ang in ("left-handed", "right-handed") for ax in LEFT + RIGHT]
_UNIT = {"n": (1.0, 0.0), "e": (0.0, 1.0), "s": (-1.0, 0.0), "w": (0.0, -1.0)}
_GON = math.pi / 200


def frame(axes: str) -> np.ndarray:
    """M: (n, e) coordinates -> the frame's (x, y) (its rows: the x and y axes in n, e)."""
    return np.array([_UNIT[axes[0]], _UNIT[axes[1]]])


def consistent(axes: str, angles: str) -> bool:
    """The frame and the angles have the same handedness (bearings from +x towards +y)."""
    return (axes in LEFT) == (angles == "left-handed")


def reframe(src: Path, axes: str, angles: str) -> str:
    """The ne, left-handed gama-local file ``src`` written in the frame ``axes`` with
    ``angles``: points, observed coordinates and vectors mapped by :func:`frame`; directions
    and angles recomputed from the mapped points in the file's convention (from +x towards +y
    when frame and angles agree, towards -y when they do not), in gon."""
    ET.register_namespace("", NS)
    root = ET.fromstring(src.read_text())
    net = root.find(f"{{{NS}}}network")
    assert net.get("axes-xy", "ne") == "ne" and net.get("angles", "left-handed") == "left-handed"
    net.set("axes-xy", axes)
    net.set("angles", angles)
    m = frame(axes)
    sign = 1.0 if consistent(axes, angles) else -1.0
    xy: dict = {}
    for p in net.iter(f"{{{NS}}}point"):
        if p.get("x") is not None:
            v = m @ [float(p.get("x")), float(p.get("y"))]
            p.set("x", repr(float(v[0])))
            p.set("y", repr(float(v[1])))
            xy.setdefault(p.get("id"), v)
    for v in net.iter(f"{{{NS}}}vec"):
        d = m @ [float(v.get("dx")), float(v.get("dy"))]
        v.set("dx", repr(float(d[0])))
        v.set("dy", repr(float(d[1])))

    def bearing(a: str, b: str) -> float:
        d = xy[b] - xy[a]
        return math.atan2(sign * d[1], d[0]) / _GON % 400

    for o in net.iter(f"{{{NS}}}obs"):
        st = o.get("from")
        for e in o:
            if e.tag == f"{{{NS}}}direction":
                e.set("val", repr(bearing(st, e.get("to"))))
            elif e.tag == f"{{{NS}}}angle":
                e.set("val", repr((bearing(st, e.get("fs")) - bearing(st, e.get("bs"))) % 400))
    return ET.tostring(root, encoding="unicode")


def suite_cov(tmp_path: Path, xml: str, name: str) -> dict:
    """The suite's covariance of each estimated point (mm^2) of the file ``xml``."""
    net, an = ours(study_of(tmp_path, xml, name))
    return {nm: an.cov[a] for a, nm in enumerate(net.names) if net.role[a] != 1}


def file_frame(cov: dict, axes: str, angles: str) -> dict:
    """gama-local's XML covariances in the file's frame: as written for a consistent file,
    with cov(x, y) negated for one whose angles run against its frame (its internal y)."""
    d = np.diag([1.0, 1.0 if consistent(axes, angles) else -1.0])
    return {k: d @ c @ d for k, c in cov.items()}


def assert_same(got: dict, want: dict, tol: float) -> None:
    assert sorted(got) == sorted(want)
    scale = max(np.abs(c).max() for c in want.values())
    for k in want:
        np.testing.assert_allclose(got[k], want[k], rtol=0, atol=tol * scale, err_msg=k)


@needs_gama
@pytest.mark.parametrize("case", CASES)
def test_gama_local_adjusts_the_same_network_in_every_frame(tmp_path, case):
    """gama-local's covariances of each of the 16 files are the ne file's mapped into the
    frame, once its internal frame (y negated) is undone for an inconsistent file; without
    that step they differ (cov(x, y) of the wrong sign) in a network with correlated x, y."""
    ne = suite_cov(tmp_path, (DATA / f"{case}.xml").read_text(), "ne")
    for axes, angles in COMBOS:
        src = tmp_path / f"{axes}_{angles}.xml"
        src.write_text(reframe(DATA / f"{case}.xml", axes, angles))
        raw = gama_cov(src)
        m = frame(axes)
        want = {k: m @ c @ m.T for k, c in ne.items()}
        assert_same(file_frame(raw, axes, angles), want, 1e-6)
        off = max(abs(c[0, 1]) for c in want.values()) / max(np.abs(c).max() for c in want.values())
        if not consistent(axes, angles) and off > 1e-3:  # the internal frame is visible
            with pytest.raises(AssertionError):
                assert_same(raw, want, 1e-6)
