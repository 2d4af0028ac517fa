"""The classes of the sweep doors33g (brief G33: GNU Gama files both ways, the encodings G32
left, round trips), one case each; each failed on the code before its fix. ``gama-local``
decodes a file with expat and its own handler of the names expat does not know
(``lib/gnu_gama/xml/encoding_unknown_handler.cpp``: ``cp-1250``, ``windows-1250``,
``cp-1251``, ``windows-1251`` and ``iso-8859-2``, compared exactly, by its own tables; any
other name by the identity table, ISO-8859-1); the reference behaviour was taken from a
driver built of that handler and of expat (its bundled 1.1 and the system's 2.x agree on
every case below).

* ``encoding="cp-1250"`` (and ``cp-1251``), gama-local's own spelling, was refused ("cannot
  be decoded: unknown encoding", Python has no codec of that name) even over ASCII bytes, and
  so was any name Python does not know over an ASCII file; gama-local reads both. Now read as
  gama-local reads them (its tables: ``\\xc8`` is ``Č`` in cp-1250, ``И`` in cp-1251).
* ``encoding="latin_1"`` (``latin1``, ``L1``: Python's names of ISO-8859-1) over bytes beyond
  ASCII was refused as an encoding gama-local does not know; gama-local reads those bytes as
  ISO-8859-1, which is what the name says: now read.
* ``encoding="UTF8"`` over UTF-8 bytes was refused as "not XML: not well-formed (invalid
  token)", naming no encoding (gama-local reads the bytes as ISO-8859-1, other point names):
  now the line names the encoding and what to declare.
* A file beginning with a processing instruction (``<?xml-stylesheet href="s.xsl"
  encoding="koi8-r"?>``, no XML declaration) over UTF-8 bytes was refused as declaring
  koi8-r: the declaration's pattern took ``<?xml-stylesheet`` for ``<?xml``. gama-local (and
  Python's parser) read such a file as UTF-8; now read so.
* ``encoding="windows-1250"`` was decoded by Python's codec, where gama-local's table differs:
  the byte 0x80 was the point ``D€`` here (exit 0), ``D`` and U+0080 there; now decoded by
  gama-local's table (such a name is then refused, naming the id, as not printable).
* A UTF-8 byte-order mark before ``encoding="iso-8859-1"`` was read silently in the
  declared encoding (``Dü`` became the point ``DÃ¼``, as gama-local reads it, not what the
  mark says): now refused, naming the mark and the declaration.
* Round trips (every study's and example's network, a random one of 5,000 points in a
  national grid, odd ids, huge and tiny sigmas, exported and imported again): a coordinate of
  about one in a hundred came back one unit in the last place off (125.011 mm was written
  ``0.12501099999999998`` m, ``x / 1000``, and read back as 125.01100000000001 mm,
  ``x_m * 1000``): the export now moves the decimal point of the coordinate's digits
  (``0.125011``) and the import moves it back, so the coordinates are the study's to the last
  digit (and gama-local reads the metres the study meant).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from sim.mc.config import ConfigError
from sim.studies import load_study
from sim.studies.network.definition import build
from sim.studies.network.gama import merge_gama, write_gama
from sim.studies.network.gama_read import read_gama

SOURCE = (Path(__file__).parent / "data" / "gama" / "one_fixed.xml").read_text()
BODY = SOURCE.split("\n", 1)[1]


def _file(tmp_path: Path, enc: str, name: bytes, bom: bytes = b"") -> Path:
    head = f'<?xml version="1.0" encoding="{enc}"?>\n'.encode()
    path = tmp_path / "n.xml"
    path.write_bytes(bom + head + BODY.encode().replace(b'"D"', b'"' + name + b'"'))
    return path


@pytest.mark.parametrize(
    "enc, name, read",
    [
        ("cp-1250", b"D\xc8\x8a", "DČŠ"),
        ("cp-1251", b"D\xc8", "DИ"),
        ("x-foo", b"Dx", "Dx"),  # no byte beyond ASCII: every name reads alike
        ("latin_1", b"D\xc8", "DÈ"),
    ],
)
def test_an_encoding_gama_local_reads_is_read_as_there(tmp_path, enc, name, read):
    names = [p["name"] for p in read_gama(_file(tmp_path, enc, name))["network.points"]]
    assert read in names, names


@pytest.mark.parametrize(
    "enc, name, bom, needles",
    [
        ("UTF8", "Dé".encode(), b"", ("'UTF8'", "ISO-8859-1", "declare UTF-8")),
        ("iso-8859-1", "Dü".encode(), b"\xef\xbb\xbf", ("byte-order mark", "'iso-8859-1'")),
        # gama-local's cp1250 table: 0x80 is U+0080, a control character, not Python's euro sign
        ("windows-1250", b"D\x80", b"", ("<point>", "'id'", "'D\\x80'")),
    ],
)
def test_an_encoding_read_otherwise_is_one_line_naming_it(tmp_path, enc, name, bom, needles):
    with pytest.raises(ConfigError) as e:
        read_gama(_file(tmp_path, enc, name, bom))
    line = str(e.value)
    assert "\n" not in line and "n.xml" in line and all(n in line for n in needles), line


def test_an_exported_coordinate_reads_back_to_the_last_digit(tmp_path):
    st = tmp_path / "s.toml"
    st.write_text(
        'study = "network"\n[network]\npoints = [\n'
        '  { name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" },\n'
        '  { name = "B", x_mm = 1000.0, y_mm = 0.0, role = "fixed" },\n'
        '  { name = "C", x_mm = 125.011, y_mm = 503.3, role = "free" } ]\n'
        'generate = [ { kind = "distance", from = ["A", "B"], to = "C", sigma_mm = 0.01 },\n'
        '  { kind = "direction", from = ["A", "B"], to = "*", sigma_arcsec = 1.0 } ]\n'
    )
    net = build(merge_gama(load_study(st)[1]))
    path = write_gama(net, tmp_path / "n.xml")
    assert 'x="0.125011"' in path.read_text()
    back = {p["name"]: p for p in read_gama(path)["network.points"]}
    assert back["C"]["x_mm"] == 125.011 and back["C"]["y_mm"] == 503.3


def test_a_processing_instruction_declares_no_encoding(tmp_path):
    path = tmp_path / "n.xml"
    pi = '<?xml-stylesheet href="s.xsl" encoding="koi8-r"?>\n'
    path.write_bytes((pi + BODY.replace('"D"', '"DÉ"')).encode())
    assert "DÉ" in [p["name"] for p in read_gama(path)["network.points"]]
