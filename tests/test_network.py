"""The network study kind (issue 14): Brown as a network, MC against analytic, reliability,
datum invariance, gama-local round trip, bad networks."""
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from sim import multilateration as ml
from sim.config import ConfigError, load_study
from sim.studies.network.analysis import analyse, in_datum
from sim.studies.network.definition import build
from sim.studies.network.gama import merge_gama, read_gama, write_gama
from sim.studies.network.model import datum

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ["network_brown", "network_testfield", "network_plate"]


def load(name, *over):
    _, cfg = load_study(ROOT / "studies" / f"{name}.toml", list(over))
    return cfg


def pre(cfg, extra=()):
    cfg = merge_gama(cfg)
    net = build(cfg)
    return net, analyse(net, datum(net, cfg, extra), 0.001, 0.8)


def test_brown_as_a_network_equals_the_brown_models():
    cfg = load("network_brown")
    net, stations = pre(cfg)
    s_idx = [net.index(f"S{k}") for k in (1, 2, 3, 4)]
    _, known = pre(cfg, tuple(s_idx))
    p_idx = [net.index(f"P{k}") for k in range(1, 26)]
    theta = ml.design_theta(167.5, 0.5, 1.0)[None]
    pts = net.xy[p_idx][None]
    for model, an in (("known", known), ("stations", stations)):
        Q = ml.covariance(pts, theta, model)[0][0] * 1e-6        # unit range sigma 1 um
        np.testing.assert_allclose(an.cov[p_idx], Q, rtol=1e-9, atol=1e-18)
    assert stations.dof == 2 * 4 * 25 // 2 - (2 * 25 + 5) and known.dof == 100 - 50


def test_redundancy_numbers_sum_to_the_degrees_of_freedom():
    for name in EXAMPLES:
        net, an = pre(load(name))
        assert an.ok and an.dof > 0
        assert abs(an.redundancy.sum() - an.dof) < 1e-8 * an.dof
        assert np.all((an.redundancy >= 0) & (an.redundancy <= 1))


def test_precision_is_datum_invariant_after_s_transformation():
    cfg = load("network_testfield")
    free = {**cfg, "network.points": [{**p, "role": "free"} for p in cfg["network.points"]]}
    net, inner = pre({**free, "datum.kind": "inner"})
    _, minimal = pre({**free, "datum.kind": "constraints",
                      "datum.constraints": [{"A.x": 1.0}, {"A.y": 1.0}, {"B.y": 1.0}]})
    _, fixed = pre(cfg)
    assert inner.ok and minimal.ok and inner.dof == minimal.dof == fixed.dof - 8 + 3
    assert not np.allclose(inner.cov, minimal.cov)            # two different datums ...
    sel = [net.index(n) for n in net.names if n.startswith("N")]
    np.testing.assert_allclose(in_datum(net, inner, sel), in_datum(net, minimal, sel),
                               rtol=1e-7, atol=1e-12)        # ... one precision
    np.testing.assert_allclose(inner.redundancy, minimal.redundancy, atol=1e-9)


def test_monte_carlo_agrees_with_analytic_within_sampling_error(tmp_path):
    out = tmp_path / "tf"
    r = subprocess.run([sys.executable, "-m", "sim", "run", str(ROOT / "studies/network_testfield.toml"),
                        "--out", str(out), "--trials", "600", "--set", "chunk=60", "--quiet"],
                       cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    p = pq.read_table(out / "points.parquet").to_pydict()
    n = 600
    se = 1 / math.sqrt(2 * (n - 1))                 # relative SE of a Gaussian sample sigma
    ratio = np.array(p["mc_sigma_x_mm"] + p["mc_sigma_y_mm"]) / \
        np.array(p["sigma_x_mm"] + p["sigma_y_mm"])
    assert np.all(np.abs(ratio - 1) < 4.5 * se), ratio     # 24 coordinates, two-sided 4.5 SE
    cov = np.array(p["coverage95"])
    assert np.all(np.abs(cov - 0.95) < 4.5 * math.sqrt(0.95 * 0.05 / n)), cov
    claims = pq.read_table(out / "claims.parquet").to_pydict()
    assert set(claims["kind"]) == {"self-check"} and "fails" not in claims["outcome"]
    assert (out / "network.png").stat().st_size > 1000 and (out / "network.xml").is_file()


def test_gama_local_round_trip(tmp_path):
    cfg = load("network_testfield")
    net = build(cfg)
    path = write_gama(net, tmp_path / "tf.xml")
    rec = read_gama(path)
    cfg2 = {**cfg, "network.grids": [], "network.generate": [], **rec}
    net2 = build(cfg2)
    assert net2.names == net.names and np.array_equal(net2.role, net.role)
    np.testing.assert_allclose(net2.xy, net.xy, rtol=0, atol=1e-9)
    rows = lambda nt: sorted(zip(nt.kind, nt.i, nt.j, nt.k, np.round(nt.sigma, 15)))  # noqa: E731
    assert rows(net2) == rows(net)
    assert net2.stations == net.stations
    # via the study file too: network.gama_xml replaces the declared network
    _, an1 = pre(cfg)
    _, an2 = pre({**cfg2, "network.points": [], "network.observations": [],
                  "network.gama_xml": str(path)})
    np.testing.assert_allclose(an1.cov, an2.cov, rtol=1e-9)


def test_gama_export_refuses_what_gama_local_cannot_say(tmp_path):
    with pytest.raises(ConfigError, match="additive constant"):
        write_gama(build(load("network_brown")), tmp_path / "b.xml")
    with pytest.raises(ConfigError, match="coordinate"):
        write_gama(build(load("network_plate")), tmp_path / "p.xml")


@pytest.mark.parametrize("override,key", [
    ('network.generate=[{kind="distance", from="A", to="Q*", sigma_mm=1.0}]', "network.generate"),
    ('network.observations=[{kind="distance", from="A", to="B", sigma_mm=-1.0}]', "sigma_mm"),
    ('datum.kind="inner"', None),
    ('network.observations=[{kind="bearing", from="A", to="B", sigma_mm=1.0}]', "kind"),
    ('network.points=[{name="A", x_mm=0.0, y_mm=0.0}, {name="A", x_mm=1.0, y_mm=0.0}]', "duplicate"),
])
def test_bad_networks_are_one_line_errors(override, key, tmp_path):
    r = subprocess.run([sys.executable, "-m", "sim", "check", str(ROOT / "studies/network_testfield.toml"),
                        "--set", override], cwd=ROOT, capture_output=True, text=True, timeout=120)
    if key is None:              # inner constraints over fixed pillars are still a valid datum
        assert r.returncode == 0, r.stderr
        return
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert key in r.stderr and "Traceback" not in r.stderr


def test_too_few_observations_is_named():
    r = subprocess.run([sys.executable, "-m", "sim", "check", str(ROOT / "studies/network_plate.toml"),
                        "--set", "network.generate=[]"], cwd=ROOT, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 2 and "0 degrees of freedom" in r.stderr, r.stderr


def test_rank_defect_not_covered_by_the_datum_names_it(tmp_path):
    study = tmp_path / "free.toml"
    study.write_text((ROOT / "studies/network_testfield.toml").read_text()
                     .replace('role = "fixed"', 'role = "free"'))
    r = subprocess.run([sys.executable, "-m", "sim", "check", str(study)], cwd=ROOT,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "rank defect of 3" in r.stderr, r.stderr
