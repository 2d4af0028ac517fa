"""Regenerate the GNU Gama reference files of tests/test_gama.py.

    GAMA_LOCAL=/path/to/gama-local .venv/bin/python tests/data/gama/regenerate.py

Writes, for every case, ``<case>.xml``: the network as this suite exports it
(:func:`sim.studies.network.gama.export`) or, for the ``user_*`` cases, as a gama-local user
writes it (d-m-s angles with stdevs in arcseconds, default stdevs with the a + b D^c model,
a diagonal ``<cov-mat>`` in an ``<obs>``), and ``<case>.out.xml``: ``gama-local``'s XML
adjustment output for it (``gama-local <case>.xml --xml <case>.out.xml``). Without
``GAMA_LOCAL`` only the inputs are written (the outputs are then stale: the tests check that
the inputs are what the export writes). gama-local 2.03 was built from its public source
(``cmake -S gama -B build && cmake --build build --target gama-local``).
"""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
sys.path.insert(0, str(ROOT))

from sim.studies import load_study  # noqa: E402
from sim.studies.network.definition import build  # noqa: E402
from sim.studies.network.gama import export, merge_gama  # noqa: E402

NS = "http://www.gnu.org/software/gama/gama-local"
#: exported cases: name -> study file
EXPORTS = {
    "testfield": ROOT / "studies/network_testfield.toml",
    "brown": ROOT / "studies/network_brown.toml",
    "plate": ROOT / "studies/network_plate.toml",
    "directions_free": HERE / "directions_free.toml",
    "one_fixed": HERE / "one_fixed.toml",
    "two_sets": HERE / "two_sets.toml",
}
#: user-style cases: name -> the exported case they are rewritten from
USER = {"user_dms": "two_sets", "user_defaults": "one_fixed"}


def write_export(case: str) -> str:
    _, cfg = load_study(EXPORTS[case])
    full = merge_gama(cfg)
    return export(build(full), full, HERE / f"{case}.xml")


def dms(gon: float) -> str:
    """gon -> gama-local's degree form d-m-s (seconds to 1e-9)."""
    deg = gon * 0.9
    d = int(deg)
    m = int((deg - d) * 60)
    s = ((deg - d) * 60 - m) * 60
    return f"{d}-{m:02d}-{s:013.10f}"


def _q(t: str) -> str:
    return f"{{{NS}}}{t}"


def user_dms(src: Path, dst: Path) -> None:
    """Directions and angles in d-m-s with stdevs in arcseconds; the station B's
    observations with a diagonal <cov-mat> instead of stdev attributes."""
    tree = ET.parse(src)
    for t in ("direction", "angle"):
        for e in tree.iter(_q(t)):
            e.set("val", dms(float(e.get("val"))))
            e.set("stdev", repr(float(e.get("stdev")) * 0.324))
    for o in tree.iter(_q("obs")):
        if o.get("from") == "B":
            var = []
            for e in o:
                var.append(float(e.attrib.pop("stdev")) ** 2)
            cm = ET.SubElement(o, _q("cov-mat"), {"dim": str(len(var)), "band": "0"})
            cm.text = " ".join(repr(v) for v in var)
    ET.register_namespace("", NS)
    tree.write(dst, xml_declaration=True, encoding="unicode")


def user_defaults(src: Path, dst: Path) -> None:
    """No stdev attributes: the defaults of <points-observations>, distance-stdev as
    a + b D^c (2 mm + 3 mm/km, c = 1) and direction-stdev in cc."""
    tree = ET.parse(src)
    po = next(tree.iter(_q("points-observations")))
    po.set("distance-stdev", "2 3 1")
    po.set("direction-stdev", "4.6296296296296")
    for t in ("direction", "distance"):
        for e in tree.iter(_q(t)):
            del e.attrib["stdev"]
    ET.register_namespace("", NS)
    tree.write(dst, xml_declaration=True, encoding="unicode")


def main() -> int:
    for case in EXPORTS:
        print(f"{case}.xml: {write_export(case)}")
    user_dms(HERE / "two_sets.xml", HERE / "user_dms.xml")
    user_defaults(HERE / "one_fixed.xml", HERE / "user_defaults.xml")
    gama = os.environ.get("GAMA_LOCAL")
    if not gama:
        print("GAMA_LOCAL is not set: the gama-local outputs were not regenerated")
        return 0
    for case in [*EXPORTS, *USER]:
        out = HERE / f"{case}.out.xml"
        r = subprocess.run(
            [gama, str(HERE / f"{case}.xml"), "--xml", str(out)], capture_output=True, text=True
        )
        if r.returncode != 0 or not out.is_file():
            print(f"{case}: gama-local failed: {r.stdout}{r.stderr}")
            return 1
        print(f"{case}.out.xml written")
    return 0


if __name__ == "__main__":
    sys.exit(main())
