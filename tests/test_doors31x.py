"""The classes of the sweep doors31x (brief X31: GNU Gama files hostile in their XML structure
and at real size), one case each; each failed on the code before its fix.

* A DOCTYPE that declares entities was expanded by the parser: a few kilobytes of nested
  entities ("billion laughs") were stopped by expat's amplification limit, but one entity of 60
  characters referenced four million times (12 MB, under that limit) held 640 MB and was read
  as a network (exit 0); an external entity naming ``/etc/passwd`` was "undefined" only because
  ElementTree does not load it. A declared entity is now refused before the file is parsed, in
  one line naming it (``&q;``, ``%p;``): a ``gama-local`` file needs none. A DOCTYPE without
  declarations (``SYSTEM "gama-local.dtd"`` of older files) is still read, its DTD not fetched.
* A number attribute of many digits ending in a letter (``x="999...9q"``) was matched by a
  regular expression that backtracked quadratically: 10 MB held ``sim check`` for hours. The
  expression is now possessive (linear), and a long value, id or sight is quoted in the
  message by its first 19 characters and its length (a 1 MB ``to`` made a 1 MB "one line").
* A d-m-s angle with minutes of over 4300 digits (``1-000...01-0``) ended in Python's
  ValueError for ``int()`` of a long string, a traceback; it is now read as gama-local reads
  it, and minutes beyond a C ``int`` are one line (doors46x: minutes of 60 or more are read
  as gama-local reads them, the note naming them).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from sim.cli import main
from sim.mc.config import ConfigError
from sim.studies.network.gama_read import read_gama
from tests.oneline import SIM_ERROR, one_line, python_lines

SOURCE = Path(__file__).parent / "data" / "gama" / "one_fixed.xml"
BODY = SOURCE.read_text().split("\n", 1)[1]  # the file without its XML declaration


def _study(tmp_path: Path, xml: str) -> str:
    (tmp_path / "n.xml").write_text(xml, encoding="utf-8")
    toml = tmp_path / "n.toml"
    toml.write_text(
        f'study = "network"\ntrials = 200\nchunk = 10\n\n[network]\ngama_xml = "{tmp_path / "n.xml"}"\n'
    )
    return str(toml)


@pytest.mark.parametrize(
    "decl,ref,needle",
    [
        ('<!ENTITY q "' + "x" * 60 + '">', "&q;" * 1000, "&q;"),  # expands inside the limit
        ('<!ENTITY x SYSTEM "file:///etc/passwd">', "&x;", "&x;"),
        ('<!ENTITY % p SYSTEM "http://127.0.0.1:9/p.dtd"> %p;', "p", "%p;"),
    ],
)
def test_a_doctype_declaring_an_entity_is_refused_before_it_expands(
    decl, ref, needle, tmp_path, capsys
):
    xml = f'<?xml version="1.0"?>\n<!DOCTYPE gama-local [{decl}]>\n'
    toml = _study(tmp_path, xml + BODY.replace("one fixed point", ref))
    line = one_line(capsys, main(["check", toml]), SIM_ERROR, "n.xml", needle, "<!DOCTYPE>")
    assert "entity declarations are not read" in line
    # a DOCTYPE without declarations (older gama files name their DTD) is read; nothing fetched
    plain = '<?xml version="1.0"?>\n<!DOCTYPE gama-local SYSTEM "http://127.0.0.1:9/g.dtd">\n'
    assert (
        len(read_gama(Path(_study(tmp_path, plain + BODY)).with_suffix(".xml"))["network.points"])
        == 4
    )


def test_a_long_number_attribute_is_refused_at_once_and_quoted_short(tmp_path):
    path = tmp_path / "n.xml"
    long_x = SOURCE.read_text().replace('x="250.0"', 'x="' + "9" * 1_000_000 + 'q"')
    path.write_text(long_x)
    # in a fresh Python with a deadline: the backtracking expression took hours on this value
    p = python_lines(
        "from sim.studies.network.gama_read import read_gama",
        "try:",
        f"    read_gama({str(path)!r})",
        "except ValueError as e:",
        "    print(e)",
    )
    assert p.returncode == 0 and "'" + "9" * 19 + "'... (1,000,001 characters) is not a" in p.stdout
    long_to = SOURCE.read_text().replace(
        '<direction to="B" val="2.545122269598366"',
        '<direction to="' + "B" * 1_000_000 + '" val="q"',
    )
    path.write_text(long_to)
    with pytest.raises(
        ConfigError, match=r"\(to='" + "B" * 19 + r"'\.\.\. \(1,000,000 characters\)\)"
    ) as e:
        read_gama(path)
    assert len(str(e.value)) < 300


def test_dms_minutes_of_thousands_of_digits_are_read_or_refused_in_one_line(tmp_path):
    path = tmp_path / "n.xml"
    val = 'val="2.545122269598366"'
    # 1-01-0 is no direction of these points: a tol-abs under which gama-local keeps it
    text = SOURCE.read_text().replace('sigma-act="apriori"', 'sigma-act="apriori" tol-abs="1e9"')
    path.write_text(text.replace(val, 'val="1-' + "0" * 5000 + '1-0"'))
    assert len(read_gama(path)["network.observations"]) == 17  # 1-01-0, as gama-local reads it
    path.write_text(SOURCE.read_text().replace(val, 'val="1-' + "9" * 5000 + '-0"'))
    with pytest.raises(ConfigError, match="over 2147483647 minutes, refused by gama-local"):
        read_gama(path)
