"""A fresh reading of session 36's change (sweep doors37r): each class was found through a
real door and fixed; each test fails on the code before its fix:

* the memory check of a network before it is built (``fits_estimate``) named the key that
  holds most of its points, ``network.grids``, when what made the network too large was its
  observations: a 60 x 50 grid (3,000 points) with ``generate`` of distances from every point
  to every point (no ``nearest``: 9,000,000 observations, 44 GiB) was refused as
  ``network.grids: ... use fewer points or observations``, and the 3,000 points alone fit in
  a few MiB. Observations over ``MANY_SIGHTS`` (50) a point now name the key that declares
  them, ``network.generate`` (``network.observations`` when those listed are most).
"""

from __future__ import annotations

import pytest
from oneline import SIM_ERROR, one_line

import sim
from sim.cli import main

#: a network of few points whose generated sights (every point to every point) are too many
EVERY_PAIR = """study = "network"
trials = 1000
chunk = 50
seed = 1

[network]
name = "every pair"
grids = [ { prefix = "G", nx = 60, ny = 50, spacing_mm = 10.0, role = "observed", sigma_mm = 0.001 } ]
generate = [ { kind = "distance", from = "G*", to = "G*", sigma_mm = 0.002 } ]

[datum]
kind = "inner"
"""


def test_a_network_too_large_by_its_sights_names_them(capsys, tmp_path, monkeypatch):
    monkeypatch.delenv("SIM_MAX_MEMORY_GB", raising=False)
    path = tmp_path / "pairs.toml"
    path.write_text(EVERY_PAIR, encoding="utf-8")
    one_line(
        capsys,
        main(["check", str(path)]),
        "network.generate: a network of about 3,000 points and 9,006,000 observations",
        prefix=SIM_ERROR,
    )
    with pytest.raises(sim.ConfigError, match=r"^network\.generate: "):
        sim.load(path)
