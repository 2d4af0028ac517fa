"""The network kind's self-checks under a bias (brief N45); each test failed on the code
before its change.

* On the README's network with ``bias_mm = 10`` on its four distances (5,000 of their
  sigmas), ``network.coverage95.mean`` was 0.0 and ``network.global_test.false_alarm`` 1.0,
  both counted "self-check failed", and ``network.mc_agreement.mean_ratio`` drifted (1.02 to
  1.06): a bias unknown to the adjustment shifts the points and leaves residuals, so the three
  checks measured the bias, not the simulation. Where the adjustment does not absorb the
  bias (the noise-free biased readings leave residuals or shift a point by more than 0.01
  sigma, :func:`sim.studies.network.bias_checks.bias_effect`) the three are now **not
  applicable**, counted apart, their value and their outcome against the nominal reference
  kept in the note with the bias's key and its noncentralities. A constant on one set's
  directions, absorbed by its orientation, keeps them.
* A length bias of 1e3 mm (up to 1e9 mm was accepted) on the README's 400 x 300 mm network
  ran, its Monte-Carlo sigma 3.4 times the analytic one: a bias at least the network's
  extent (its points' bounding-box diagonal) is refused, naming the key.
"""

from __future__ import annotations

from pathlib import Path

import pyarrow.parquet as pq
import pytest

import sim
from sim.mc.config import ConfigError
from sim.studies.network.analysis import estimated_points
from sim.studies.network.bias_checks import BIASED_CHECKS, bias_effect
from sim.studies.network.definition import build
from sim.studies.network.model import datum
from sim.studies.network.sparse_analysis import pre_analysis

README = """study = "network"
trials = 400
chunk = 20
[network]
points = [ {{ name = "A", x_mm = 0.0, y_mm = 0.0, role = "fixed" }},
           {{ name = "B", x_mm = 400.0, y_mm = 0.0, role = "fixed" }},
           {{ name = "C", x_mm = 400.0, y_mm = 300.0, role = "fixed" }},
           {{ name = "D", x_mm = 0.0, y_mm = 300.0, role = "fixed" }},
           {{ name = "P", x_mm = 150.0, y_mm = 120.0 }} ]
generate = [ {{ kind = "distance", from = ["A", "B", "C", "D"], to = "P", sigma_mm = 0.002{d} }},
             {{ kind = "direction", from = ["A", "B", "C", "D"], to = "*", sigma_arcsec = 2.0{a} }} ]
"""


def _file(tmp_path: Path, d: str = "", a: str = "") -> Path:
    p = tmp_path / "net.toml"
    p.write_text(README.format(d=d, a=a))
    return p


def _effect(path: Path):
    cfg = sim.load(path).config
    net = build(cfg)
    dt = datum(net, cfg)
    an = pre_analysis(net, dt, cfg["reliability.alpha0"], cfg["reliability.power"])
    C = dt.constraint_matrix(net.theta_true()[None])
    return bias_effect(net, an, C, estimated_points(net, an), cfg)


def test_a_bias_the_adjustment_does_not_absorb_leaves_the_checks_not_applicable(tmp_path):
    res = sim.load(_file(tmp_path, d=", bias_mm = 10.0")).run(tmp_path / "out", figures=False)
    rows = {r["claim"]: r for r in pq.read_table(res.path / "claims.parquet").to_pylist()}
    for c in BIASED_CHECKS:
        assert rows[c]["verdict"] == "not applicable", rows[c]
        assert rows[c]["holds"] is None
        note = rows[c]["note"]
        assert note.startswith("not applicable: the bias of network.generate (bias_mm = 10 on")
        assert "the global test's noncentrality" in note
        assert f"rule gives: {rows[c]['outcome']};" in note
    assert rows["network.coverage95.mean"]["outcome"] == "fails"  # kept: the nominal reference
    assert rows["network.redundancy.sum"]["verdict"] == "self-check"
    assert "3 self-check not applicable" in (res.path / "README.md").read_text()


def test_a_bias_absorbed_by_the_orientations_keeps_the_checks(tmp_path):
    assert _effect(_file(tmp_path)) is None  # no bias
    # a constant on each station's directions: its orientation absorbs it
    assert _effect(_file(tmp_path, a=", bias_arcsec = 30.0")) is None
    why = _effect(_file(tmp_path, d=", bias_mm = 0.01"))  # 5 sigma on every distance
    assert why is not None and "bias_mm = 0.01 on the distance at 'A' to 'P'" in why
    p = _file(tmp_path, d=", bias_mm = 0.01")  # the estimated additive constant absorbs it
    p.write_text(p.read_text().replace("[network]", "[network]\nestimate_constant = true"))
    assert _effect(p) is None


def test_a_length_bias_beyond_the_networks_extent_is_refused(tmp_path):
    for b in ("1000.0", "1e9"):
        with pytest.raises(ConfigError) as e:
            sim.load(_file(tmp_path, d=f", bias_mm = {b}"))
        assert str(e.value).startswith("network.generate[0].bias_mm: "), str(e.value)
        assert "is not shorter than the network's extent (500 mm" in str(e.value)
