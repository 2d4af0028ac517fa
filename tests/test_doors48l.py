"""The network kind's size and work estimate (brief L48); each test failed on the code before
its change.

* The dense path's solver probe (16 trials from a stream of its own, run by ``sim check``)
  adjusted its 16 trials in one chunk, whatever the run's ``chunk``: the memory estimate counts
  ``chunk`` trials, so at ``chunk = 2`` the probe took 8 times the counted Jacobian (39,006
  distances: 1.84 GiB asked for one array). It adjusts them in chunks of the run's ``chunk``
  now, from the same stream (the same draws, so the same statuses).
"""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import numpy as np

import sim

ALL_PAIRS = """study = "network"
trials = 40
chunk = {chunk}
[network]
random = [ {{ prefix = "R", n = {n}, half_extent_m = 500.0 }} ]
generate = [ {{ kind = "distance", from = "R*", to = "R*", sigma_mm = 1.0 }} ]
[datum]
kind = "inner"
"""


def _estimate(flat: dict) -> tuple:
    """The run's estimate ``(trials, adjustments, unknowns, bytes)`` of a flat network config."""
    from sim.mc.config import validate
    from sim.mc.network_size import network_estimate
    from sim.studies import get_study

    return network_estimate(validate(flat, get_study("network").schema, None))


def _probe_args(tmp_path: Path, monkeypatch, text: str) -> tuple:
    """The arguments ``sim.load`` hands the network's solver probe for the study ``text``."""
    import sim.studies.network.schema as schema

    seen = []
    real = schema.probe_solver
    monkeypatch.setattr(schema, "probe_solver", lambda *a: (seen.append(a), real(*a))[1])
    p = tmp_path / "net.toml"
    p.write_text(text)
    sim.load(p)
    return seen[-1]


def test_dense_probe_holds_the_chunk_the_estimate_counts(tmp_path, monkeypatch):
    """Memory over the estimate (the dense path's probe): 16 probe trials in one chunk
    took 8 to 16 times the Jacobian the estimate counts at chunk 2 or 1; now at most the
    estimate's bytes at ``chunk = 1``, with the statuses of one chunk of 16."""
    from sim.studies.network import probe

    net, an, C, pts, cfg = _probe_args(tmp_path, monkeypatch, ALL_PAIRS.format(chunk=1, n=24))
    flat = {
        "trials": 40,
        "chunk": 1,
        "network.random": [{"prefix": "R", "n": 24, "half_extent_m": 500.0}],
        "network.generate": [{"kind": "distance", "from": "R*", "to": "R*", "sigma_mm": 1.0}],
        "datum.kind": "inner",
    }
    _, _, unknowns, counted = _estimate(flat)
    assert unknowns == net.q and not isinstance(an, probe.SparseAnalytic)
    tracemalloc.start()
    try:
        split = probe._probe(net, an, C, pts, cfg)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    whole = probe._probe(net, an, C, pts, {**cfg, "chunk": 16})
    assert np.array_equal(split, whole)
    assert peak <= counted, f"probe {peak / 2**20:.1f} MiB, estimate {counted / 2**20:.1f} MiB"
