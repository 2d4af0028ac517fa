"""Issue 26, sweep 31y: GNU Gama files hostile in structure and at real size.

* a number attribute of a ``gama-local`` file that is a long run of digits ending in garbage
  (100,000 digits and an ``x``; the brief's 10 MB attribute) hung the reader: its number
  pattern ``\\d+\\.?\\d*`` split the run of digits every way before refusing it (quadratic
  backtracking). The pattern now matches each digit one way: refused at once, one line
  naming the file, the element and the attribute.
"""

from __future__ import annotations

import subprocess
import sys

NS = "http://www.gnu.org/software/gama/gama-local"


def test_a_long_garbage_number_is_refused_at_once(tmp_path):
    path = tmp_path / "long.xml"
    path.write_text(
        f'<gama-local xmlns="{NS}"><network><points-observations>'
        '<point id="A" x="0" y="0" fix="xy"/><point id="B" x="100" y="0" adj="xy"/>'
        f'<obs from="A"><distance to="B" val="{"9" * 100_000}x" stdev="1"/></obs>'
        "</points-observations></network></gama-local>"
    )
    code = (
        "import sys\nfrom sim.studies.network.gama_read import read_gama\n"
        "from sim.mc.config import ConfigError\n"
        f"try:\n    read_gama({str(path)!r})\nexcept ConfigError as e:\n"
        "    print(str(e)[:200], str(e)[-40:]); sys.exit(2)\n"
    )
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=30)
    assert p.returncode == 2, p.stderr
    assert "<distance> attribute 'val'" in p.stdout and "is not a number" in p.stdout
