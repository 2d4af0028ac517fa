"""The classes of the sweep doors44x (brief X44: every observation kind and attribute of a
GNU Gama file against ``gama-local`` 2.03, files both ways, encodings), one case each; each
failed on the code before its fix. The tests that run ``gama-local`` skip without it
(``$GAMA_LOCAL``, else ``/tmp/gama-build/gama-local``).

* An observed value (``val``) far from what the coordinates give, or an ``<obs
  orientation>`` (radians, as ``gama-local`` reads it) far from the set's: ``gama-local``
  removes such an observation before it adjusts ("Outlying absolute terms", over
  ``tol-abs``, 1000 mm by default; a direction's or an angle's term weighted by ``sigma-apr``
  / stdev) and adjusts the rest, where the suite, which draws readings from the coordinates,
  kept it: another network, silently (a 0.5 rad orientation: 24 % of the largest variance
  apart, two degrees of freedom fewer there). Now refused, naming the observation
  (:mod:`sim.studies.network.gama_terms`); 400 random files in all 16 frames, d-m-s and gon,
  with and without orientations, vectors and heights, agreed with ``gama-local`` on what it
  removes.
* A UTF-16 file declared ``encoding="UTF-16LE"`` or ``"UTF-16BE"`` was read; ``gama-local``
  2.03 refuses it ("not well-formed": its bundled expat lacks a comma in its table of names,
  ``"UTF-16BE" "UTF-16LE"``, and reads them as ISO-8859-1), and reads an ASCII file so
  declared, which the suite refused ("encoding specified in XML declaration is incorrect").
  Now refused and read as there.
* A file beginning with a UTF-8 byte-order mark is read, as UTF-8; ``gama-local`` 2.03 stops
  on every such file (a segmentation fault in its expat). The report's note now says so.
"""

from __future__ import annotations

import math
import re
import subprocess
from pathlib import Path

import pytest

from benchmarks.scaling import gama_local
from sim.mc.config import ConfigError
from sim.studies.network.gama_read import read_gama
from tests.test_doors39x import FIXED, XY, _file, _obs

needs_gama = pytest.mark.skipif(gama_local() is None, reason="no gama-local on this machine")


def _gon(s: str, t: str) -> float:
    (xs, ys), (xt, yt) = XY[s], XY[t]
    return math.degrees(math.atan2(yt - ys, xt - xs)) % 360 / 0.9


def _terms_file(orientation: str | None = None, off_mm: float = 0.0, stdev: str = "10") -> str:
    """test_doors39x's network with a set at A: its directions (gon) with the orientation
    given, or C's value ``off_mm`` across its sight away from the coordinates."""
    ori = "" if orientation is None else f' orientation="{orientation}"'
    shift = {"C": off_mm / 1000 / math.dist(XY["A"], XY["C"]) * 200 / math.pi}
    dirs = "".join(
        f'<direction to="{t}" val="{(_gon("A", t) + shift.get(t, 0.0)) % 400!r}" stdev="{stdev}"/>'
        for t in "BCD"
    )
    return _file(FIXED, f'<obs from="A"{ori}>{dirs}</obs>' + _obs())


def _removed_by_gama(path: Path) -> bool:
    """Whether gama-local removes an observation: its table of outlying absolute terms lists
    one (it prints the table's title whenever a term is over, even if it removes none)."""
    text = path.with_suffix(".txt")
    subprocess.run([gama_local(), str(path), "--text", str(text)], check=True, capture_output=True)
    out = text.read_text()
    if "Outlying absolute terms in project equations" not in out:
        return False
    table = out.split("Outlying absolute terms in project equations")[1].split("Observations")[0]
    return any(re.match(r"\s+\d+\s", row) for row in table.splitlines())


@pytest.mark.parametrize(
    "orientation, off_mm, stdev, gone",
    [
        ("0.5", 0.0, "10", True),  # the orientation: 0.5 rad, every direction of the set
        ("0.0025", 0.0, "10", False),  # 0.0025 rad: 0.94 m at C (375 m), under 1000 mm
        (None, 1200.0, "10", True),  # C's value 1.2 m off the median orientation
        (None, 1200.0, "40", False),  # weighted by sigma-apr / stdev = 10 / 40: 300 mm, kept
    ],
)
def test_an_observation_gama_local_removes_for_its_absolute_term_is_refused(
    tmp_path, orientation, off_mm, stdev, gone
):
    path = tmp_path / "n.xml"
    path.write_text(_terms_file(orientation, off_mm, stdev))
    if gone:
        with pytest.raises(ConfigError) as e:
            read_gama(path)
        msg = str(e.value)
        assert "\n" not in msg and "Outlying absolute terms" in msg and "<direction>" in msg
        assert ("radians" in msg) == (orientation is not None), msg
    else:
        assert len(read_gama(path)["network.observations"]) == 3 + len(_obs().split("/>")) - 1
    if gama_local() is not None:  # what gama-local does with the same file
        assert _removed_by_gama(path) == gone


@needs_gama
def test_the_distance_gama_local_removes_is_the_one_named(tmp_path):
    """A distance 1.5 m off (a raw term, not weighted): the one gama-local lists and removes."""
    d = math.dist(XY["C"], XY["D"])
    xml = _file(
        FIXED, _obs() + f'<obs from="C"><distance to="D" val="{d + 1.5!r}" stdev="3"/></obs>'
    )
    path = tmp_path / "n.xml"
    path.write_text(xml)
    with pytest.raises(ConfigError, match=r"<distance> attribute 'val' \(to='D'\).* 1500 mm"):
        read_gama(path)
    assert _removed_by_gama(path)


def _encoded(xml: str, name: str, codec: str, bom: bytes = b"") -> bytes:
    return bom + xml.replace(
        '<?xml version="1.0"?>', f'<?xml version="1.0" encoding="{name}"?>'
    ).encode(codec)


@pytest.mark.parametrize("name", ["UTF-16LE", "utf-16be"])
def test_utf_16_le_or_be_declared_is_read_as_gama_local_reads_it(tmp_path, name):
    xml = _file(FIXED)
    codec = "utf-16-le" if name.lower().endswith("le") else "utf-16-be"
    path = tmp_path / "n.xml"
    for bom in (b"", b"\xff\xfe" if codec.endswith("le") else b"\xfe\xff"):
        path.write_bytes(_encoded(xml, name, codec, bom))
        with pytest.raises(ConfigError, match=f"'{name}'.*gama-local 2.03 does not know") as e:
            read_gama(path)
        assert "\n" not in str(e.value)
        if gama_local() is not None:
            run = subprocess.run([gama_local(), str(path)], capture_output=True, text=True)
            assert "not well-formed" in run.stderr + run.stdout  # its error, as XML
    path.write_bytes(_encoded(xml, name, "ascii"))  # ASCII bytes: read, as gama-local does
    plain = tmp_path / "p.xml"
    plain.write_text(xml)
    assert read_gama(path)["network.observations"] == read_gama(plain)["network.observations"]
    path.write_bytes(_encoded(xml, "UTF-16", codec))  # the name gama-local knows
    assert read_gama(path)["network.observations"] == read_gama(plain)["network.observations"]


def test_a_utf_8_byte_order_mark_is_read_and_the_note_says_gama_local_stops_on_it(tmp_path):
    path = tmp_path / "n.xml"
    path.write_bytes(b"\xef\xbb\xbf" + _file(FIXED).encode())
    assert "byte-order mark" in read_gama(path)["note"]
    path.write_bytes(_file(FIXED).encode())
    assert "byte-order mark" not in read_gama(path)["note"]
    if gama_local() is not None:
        path.write_bytes(b"\xef\xbb\xbf" + _file(FIXED).encode())
        run = subprocess.run([gama_local(), str(path)], capture_output=True)
        assert run.returncode != 0  # -11: SIGSEGV
