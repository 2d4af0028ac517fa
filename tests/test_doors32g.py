"""The classes of the sweep doors32g (brief G32: what ``gama-local`` refuses, the suite must not
read as something else), one case each; each failed on the code before its fix. ``gama-local``'s
parser (``lib/gnu_gama/xml/gkfparser.cpp``: expat without namespace processing) reads every
name and value as written.

* A namespace prefix on the elements (``<g:gama-local xmlns:g="...">``), an attribute of
  ``<gama-local>`` other than ``xmlns`` and ``version`` (``xmlns:g``), an ``xmlns`` on
  ``<network>`` and a prefixed attribute of another namespace (``o:note`` on a ``<point>``)
  were read as the same network (ElementTree drops prefixes and declarations, exit 0);
  ``gama-local`` refuses each (an unknown element, an undefined attribute). Now one line
  naming the file, the element and the attribute.
* A value of a closed vocabulary with white space around it (``axes-xy=" ne"``,
  ``fix="xy "``, ``sigma-act="apriori "``) was trimmed and read: ``gama-local`` compares it as
  written and refuses it. Now refused in one line (numbers are still read with white space
  around them, as ``gama-local``'s ``IsFloat`` trims it, and so are ids, see below).
* A point id with a run of white space inside (``"A  B"``) was another point than ``"A B"``:
  ``gama-local``'s ``PointID`` trims an id and makes each run one space, so two ``<point>``
  elements ``"A  B"`` and ``"A B"`` at different places were two points here (exit 0) and one
  point declared twice there. Ids are now read as ``PointID`` reads them; the export refuses a
  study's point name with two spaces in a row (``gama-local`` would read another name):
  "not exported", naming the point.
* A declared encoding ``gama-local`` does not know (``koi8-r``, ``ISO-8859-2`` in capitals: its
  handler compares names exactly) over bytes beyond ASCII was decoded by Python's
  codec, where ``gama-local`` reads the bytes as ISO-8859-1: a point ``И`` here was ``é`` there. Now refused in one line naming the encoding; an ASCII
  file under any declaration, and the encodings ``gama-local`` knows, are read.
* ``<parameters language="en" encoding="utf-8">`` was read: those are options of
  ``gama-local``'s command line, and its parser (and ``gama-local.xsd``) refuses them on
  ``<parameters>``. Now an unknown attribute, one line.
* A no-break space (U+00A0) as text between elements was taken for white space (Python's
  ``strip()``); ``gama-local`` refuses it (``isspace`` of the C locale): now refused.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from sim.cli import main
from sim.mc.config import ConfigError
from sim.studies import load_study
from sim.studies.network.definition import build
from sim.studies.network.gama import export, merge_gama
from sim.studies.network.gama_read import NS, read_gama
from tests.oneline import SIM_ERROR, one_line

SOURCE = (Path(__file__).parent / "data" / "gama" / "one_fixed.xml").read_text()
ROOT = f'<gama-local xmlns="{NS}">'


def _refused(tmp_path: Path, xml: str, *needles: str) -> str:
    path = tmp_path / "n.xml"
    path.write_text(xml, encoding="utf-8")
    with pytest.raises(ConfigError) as e:
        read_gama(path)
    line = str(e.value)
    assert "\n" not in line and "n.xml" in line and all(n in line for n in needles), line
    return line


@pytest.mark.parametrize(
    "xml, needles",
    [
        (
            SOURCE.replace(ROOT, f'<g:gama-local xmlns:g="{NS}">')
            .replace("</gama-local>", "</g:gama-local>")
            .replace("<network ", "<g:network ")
            .replace("</network>", "</g:network>"),
            ("<g:gama-local>", "namespace prefix"),
        ),
        (SOURCE.replace(ROOT, f'<gama-local xmlns="{NS}" xmlns:g="{NS}">'), ("'xmlns:g'",)),
        (SOURCE.replace(ROOT, f'<gama-local xmlns="{NS}" id="x">'), ("<gama-local>", "'id'")),
        (SOURCE.replace("<network axes-xy", f'<network xmlns="{NS}" axes-xy'), ("<network>",)),
        (
            SOURCE.replace(ROOT, f'<gama-local xmlns="{NS}" xmlns:o="http://example.org/o">'),
            ("<gama-local>", "'xmlns:o'"),
        ),
    ],
)
def test_names_gama_local_reads_with_their_prefix_are_refused(tmp_path, xml, needles):
    _refused(tmp_path, xml, *needles)


def test_a_foreign_prefixed_attribute_is_refused_in_one_line(tmp_path, capsys):
    xml = SOURCE.replace('adj="XY" />', 'adj="XY" o:note="mine" xmlns:o="urn:o" />', 1)
    _refused(tmp_path, xml, "<point>", "'o:note'")
    toml = tmp_path / "n.toml"
    toml.write_text(
        f'study = "network"\ntrials = 200\nchunk = 10\n\n[network]\n'
        f'gama_xml = "{tmp_path / "n.xml"}"\n'
    )
    one_line(capsys, main(["check", str(toml)]), SIM_ERROR, "n.xml", "<point>", "'o:note'")


@pytest.mark.parametrize(
    "old, new, needles",
    [
        ('axes-xy="ne"', 'axes-xy=" ne"', ("<network>", "'axes-xy'")),
        ('fix="xy"', 'fix="xy "', ("<point>", "'fix'")),
        ('sigma-act="apriori"', 'sigma-act="apriori "', ("<parameters>", "'sigma-act'")),
    ],
)
def test_a_keyword_with_white_space_around_is_refused(tmp_path, old, new, needles):
    _refused(tmp_path, SOURCE.replace(old, new, 1), *needles)


@pytest.mark.parametrize("attr", ['language="en"', 'encoding="utf-8"'])
def test_a_command_line_option_on_parameters_is_refused(tmp_path, attr):
    xml = SOURCE.replace('<parameters sigma-apr="1"', f'<parameters {attr} sigma-apr="1"')
    _refused(tmp_path, xml, "<parameters>", repr(attr.split("=")[0]), "unknown attribute")


def test_numbers_with_white_space_around_are_still_read(tmp_path):
    path = tmp_path / "n.xml"
    path.write_text(SOURCE.replace('x="250.0"', 'x=" 250.0\t"'))
    assert len(read_gama(path)["network.points"]) == 4  # gama-local's IsFloat trims it too


@pytest.mark.parametrize("where", ["text", "tail"])
def test_a_no_break_space_between_elements_is_refused(tmp_path, where):
    pt = '<point id="B" x="250.0" y="10.0" adj="XY" />'
    new = pt + "\u00a0" if where == "tail" else pt[:-3] + ">\u00a0</point>"
    _refused(tmp_path, SOURCE.replace(pt, new), "<point>", "unexpected text")


def test_an_id_is_read_as_gama_locals_point_id(tmp_path):
    two = SOURCE.replace('<point id="D"', '<point id="A  B" x="5" y="5" adj="xy" /><point id="D"')
    two = two.replace('<point id="D"', '<point id="A\tB" x="6" y="5" adj="xy" /><point id="D"')
    _refused(tmp_path, two, "<point>", "'A B'", "declared twice")
    path = tmp_path / "n.xml"
    path.write_text(SOURCE.replace('<point id="A"', '<point id=" A\n"').replace('"B"', '" B "'))
    assert read_gama(path)["network.points"] == read_gama_text(tmp_path, SOURCE)


def read_gama_text(tmp_path: Path, xml: str) -> list:
    path = tmp_path / "plain.xml"
    path.write_text(xml)
    return read_gama(path)["network.points"]


def test_a_name_with_two_spaces_in_a_row_is_not_exported(tmp_path):
    st = tmp_path / "s.toml"
    st.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\n'
        'points = [ { name = "F", x_mm = 0.0, y_mm = 0.0, role = "fixed" },\n'
        '  { name = "G", x_mm = 0.0, y_mm = 90000.0, role = "fixed" },\n'
        '  { name = "A  B", x_mm = 100000.0, y_mm = 0.0 },\n'
        '  { name = "A B", x_mm = 100000.0, y_mm = 90000.0 } ]\n'
        'generate = [ { kind = "distance", from = "*", to = "*", sigma_mm = 2.0 },\n'
        '  { kind = "direction", from = "F", to = "*", sigma_arcsec = 3.0 } ]\n'
    )
    full = merge_gama(load_study(st)[1])
    note = export(build(full), full, tmp_path / "n.xml")
    assert note.startswith("not exported") and "'A  B'" in note and "one space" in note, note
    assert not (tmp_path / "n.xml").exists()


@pytest.mark.parametrize(
    "enc, codec, read",
    [
        ("koi8-r", "koi8-r", False),
        ("ISO-8859-2", "iso-8859-2", False),
        ("UTF-8", "utf-8", True),
        ("iso-8859-2", "iso-8859-2", True),
        ("koi8-r", "ascii", True),  # no byte beyond ASCII: read alike
    ],
)
def test_an_encoding_gama_local_does_not_know_is_refused(tmp_path, enc, codec, read):
    body = SOURCE.split("\n", 1)[1]
    name = "D" if codec == "ascii" else "D\u00e9" if codec != "koi8-r" else "D\u0418"
    xml = f'<?xml version="1.0" encoding="{enc}"?>\n' + body.replace('"D"', f'"{name}"')
    path = tmp_path / "n.xml"
    path.write_bytes(xml.encode(codec))
    if read:
        assert name in [p["name"] for p in read_gama(path)["network.points"]]
        return
    with pytest.raises(ConfigError) as e:
        read_gama(path)
    assert "n.xml" in str(e.value) and repr(enc) in str(e.value) and "ISO-8859-1" in str(e.value)
