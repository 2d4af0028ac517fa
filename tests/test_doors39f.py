"""Fuzz, seeds 3901.. and the doors fuzzer's 39001126/7 and 39011126/7 (brief F39), and a new
mutation kind, SPLICE (tests/fuzz_splice.py): bad inputs made by crossing valid ones -- a table
of one study pasted into another's file, a key moved into a sibling or parent table, a table
given twice through dotted keys and a header, an inline table where an array of tables is
expected and back, a network's record with another record's field, a sweep of one study in
another's file; a GNU Gama element under another parent or after another element, the
attributes of one element on another, a ``run.json`` or a table of one run beside another
run's tables. The TOML splices, the attribute splices and the run splices were all refused in
one line naming the file and the key or element (or read as the same document: TOML's dotted
keys and headers are one table); the classes below were found. One case each, each failed on
the code before its fix.

* A ``<point>`` after the ``<cov-mat>`` of a ``<coordinates>`` (or a ``<vec>`` after that of a
  ``<vectors>``) was read as if before it: with a ``dim`` counting it, the file ran (exit 0),
  where ``gama-local`` refuses any element after a ``<cov-mat>`` ("no observations after
  cov-mat"); with the ``dim`` of the points before it, the line was ``dim 2 for 4
  observations``, counting a point the matrix does not follow. Only ``<obs>`` had the rule.
  Any element after the ``<cov-mat>`` of its parent is now refused naming it (``<cov-mat>:
  one <cov-mat>, the last element of its <coordinates>``).
* The doors fuzzer's ``run(workers=2.0)`` was listed as a bad argument, which it is no longer
  (it is 2, as ``trials=400.0`` is 400): seed 39001126's case 11 failed on a valid call. The
  list now holds 2.5.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from sim.cli import main
from tests.oneline import SIM_ERROR, one_line

ROOT = Path(__file__).resolve().parent.parent
GAMA = ROOT / "tests" / "data" / "gama" / "one_fixed.xml"
END = "    </points-observations>\n"


def _gama_check(tmp_path, capsys, text: str, *needles: str) -> str:
    x = tmp_path / "net.xml"
    x.write_text(text)
    study = tmp_path / "net.toml"
    study.write_text(f'study = "network"\ntrials = 40\nchunk = 2\n[network]\ngama_xml = "{x}"\n')
    return one_line(capsys, main(["check", str(study)]), str(x), *needles, prefix=SIM_ERROR)


@pytest.mark.parametrize(
    "block, parent",
    [
        (
            '<coordinates><point id="B" x="250.0" y="10.0"/><cov-mat dim="4" band="0">1 1 1 1'
            '</cov-mat><point id="C" x="240.0" y="260.0"/></coordinates>',
            "coordinates",
        ),
        (
            '<coordinates><point id="B" x="250.0" y="10.0"/><cov-mat dim="2" band="0">1 1'
            '</cov-mat><point id="C" x="240.0" y="260.0"/></coordinates>',
            "coordinates",
        ),
        (
            '<vectors><vec from="A" to="B" dx="250" dy="10" dz="0"/><cov-mat dim="6" band="0">'
            '1 1 1 1 1 1</cov-mat><vec from="A" to="C" dx="1" dy="1" dz="0"/></vectors>',
            "vectors",
        ),
    ],
)
def test_an_element_after_the_cov_mat_of_coordinates_is_refused(tmp_path, capsys, block, parent):
    text = GAMA.read_text()
    assert END in text
    line = _gama_check(
        tmp_path, capsys, text.replace(END, block + "\n" + END), "<cov-mat>: one <cov-mat>, the "
    )
    assert f"the last element of its <{parent}>" in line and "observations" not in line
    ok = '<coordinates><point id="B" x="250.0" y="10.0"/><cov-mat dim="2" band="0">1 1</cov-mat>'
    (tmp_path / "net.xml").write_text(text.replace(END, ok + "</coordinates>\n" + END))
    assert main(["check", str(tmp_path / "net.toml")]) == 0, capsys.readouterr().err
