"""The network study kind (issue 14): Brown as a network, MC against analytic, reliability,
datum invariance, gama-local round trip, bad networks."""

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from sim.cli import main
from sim.instruments.ranges import multilateration as ml
from sim.mc.config import ConfigError
from sim.studies import load_study
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
    theta = ml.design_theta(139.5, 0.5, 1.0)[None]
    pts = net.xy[p_idx][None]
    for model, an in (("known", known), ("stations", stations)):
        Q = ml.covariance(pts, theta, model)[0][0] * 1e-6  # unit range sigma 1 um
        np.testing.assert_allclose(an.cov[p_idx], Q, rtol=1e-9, atol=1e-18)
    assert stations.dof == 2 * 4 * 25 // 2 - (2 * 25 + 5) and known.dof == 100 - 50


def test_brown_network_example_equals_the_brown_dilution_study_files(tiny_run):
    """studies/network_brown.toml run through `sim run` gives the point sigmas that
    `brown_dilution` writes for its `known` and `stations` models (same geometry, 1 um)."""
    b = pq.read_table(tiny_run("brown_dilution") / "points.parquet").to_pydict()
    n = pq.read_table(tiny_run("network_brown") / "points.parquet").to_pydict()
    at = {(round(x, 6), round(y, 6)): k for k, (x, y) in enumerate(zip(n["x_mm"], n["y_mm"]))}
    rows = {m: [k for k, mm in enumerate(b["model"]) if mm == m] for m in ("known", "stations")}
    net_rows = [at[(round(b["x_mm"][k], 6), round(b["y_mm"][k], 6))] for k in rows["stations"]]
    assert len(set(net_rows)) == 25
    bx, by = np.array(b["sigma_x_um"]), np.array(b["sigma_y_um"])
    # the example's own parameterisation (stations estimated, alpha and beta known), in um
    np.testing.assert_allclose(
        np.array(n["sigma_x_mm"])[net_rows] * 1e3, bx[rows["stations"]], rtol=1e-9
    )
    np.testing.assert_allclose(
        np.array(n["sigma_y_mm"])[net_rows] * 1e3, by[rows["stations"]], rtol=1e-9
    )
    # its dilution column is Brown's "stations recovered" against "stations known"
    pooled = {m: np.sqrt((bx[r] ** 2 + by[r] ** 2) / 2) for m, r in rows.items()}
    np.testing.assert_allclose(
        np.array(n["dilution_pct"])[net_rows],
        100 * (pooled["stations"] / pooled["known"] - 1),
        rtol=1e-7,
        atol=1e-9,
    )


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
    _, minimal = pre(
        {
            **free,
            "datum.kind": "constraints",
            "datum.constraints": [{"A.x": 1.0}, {"A.y": 1.0}, {"B.y": 1.0}],
        }
    )
    _, fixed = pre(cfg)
    assert inner.ok and minimal.ok and inner.dof == minimal.dof == fixed.dof - 8 + 3
    assert not np.allclose(inner.cov, minimal.cov)  # two different datums ...
    sel = [net.index(n) for n in net.names if n.startswith("N")]
    np.testing.assert_allclose(
        in_datum(net, inner, sel), in_datum(net, minimal, sel), rtol=1e-7, atol=1e-12
    )  # ... one precision
    np.testing.assert_allclose(inner.redundancy, minimal.redundancy, atol=1e-9)


def test_monte_carlo_agrees_with_analytic_within_sampling_error(tmp_path):
    out = tmp_path / "tf"
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "sim",
            "run",
            str(ROOT / "studies/network_testfield.toml"),
            "--out",
            str(out),
            "--trials",
            "600",
            "--set",
            "chunk=30",
            "--quiet",
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    p = pq.read_table(out / "points.parquet").to_pydict()
    n = 600
    se = 1 / math.sqrt(2 * (n - 1))  # relative SE of a Gaussian sample sigma
    ratio = np.array(p["mc_sigma_x_mm"] + p["mc_sigma_y_mm"]) / np.array(
        p["sigma_x_mm"] + p["sigma_y_mm"]
    )
    assert np.all(np.abs(ratio - 1) < 4.5 * se), ratio  # 24 coordinates, two-sided 4.5 SE
    cov = np.array(p["coverage95"])
    assert np.all(np.abs(cov - 0.95) < 4.5 * math.sqrt(0.95 * 0.05 / n)), cov
    claims = pq.read_table(out / "claims.parquet").to_pydict()
    assert set(claims["kind"]) == {"self-check", "finding"} and "fails" not in claims["outcome"]
    assert sum(k == "self-check" for k in claims["kind"]) == 4
    row = {c: r for c, r in zip(claims["claim"], pq.read_table(out / "claims.parquet").to_pylist())}
    # counted from the study file: 4 pillars x 12 new points distances, 4 x 15 directions,
    # 12 x 2 nearest-neighbour distances and one angle; 12 new points (x, y) and one
    # orientation per pillar's direction set: 133 - 28 = 105 degrees of freedom, on both edges
    # of the zone (105 +- 1e-6)
    r = row["network.redundancy.sum"]
    dof = (4 * 12 + 4 * 15 + 12 * 2 + 1) - (12 * 2 + 4)
    assert r["value"] == pytest.approx(dof, abs=1e-9) and dof == 105 and r["outcome"] == "holds"
    # the linear model's 95 % ellipses cover 95 % (the mean over 12 points of shares of 600
    # trials: at most the binomial standard error of one point)
    r = row["network.coverage95.mean"]
    assert abs(r["value"] - 0.95) < 4 * math.sqrt(0.95 * 0.05 / n) and r["ci_low"] < r["ci_high"]
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
    _, an2 = pre(
        {**cfg2, "network.points": [], "network.observations": [], "network.gama_xml": str(path)}
    )
    np.testing.assert_allclose(an1.cov, an2.cov, rtol=1e-9)


def test_gama_export_refuses_what_gama_local_cannot_say(tmp_path):
    """(issue 24: beta, the known constant and dx/dy now export; see tests/test_gama.py)"""
    cfg = load("network_brown")
    with pytest.raises(ConfigError, match="additive-constant unknown"):
        write_gama(build({**cfg, "network.estimate_constant": True}), tmp_path / "b.xml")
    obs = [{"kind": "distance", "from": "A", "to": "N1", "sigma_mm": 1.0, "bias_mm": 0.1}]
    cfg = load("network_testfield")
    with pytest.raises(ConfigError, match="bias"):
        write_gama(build({**cfg, "network.observations": obs}), tmp_path / "t.xml")


@pytest.mark.parametrize(
    "override,key",
    [
        (
            'network.generate=[{kind="distance", from="A", to="Q*", sigma_mm=1.0}]',
            "network.generate",
        ),
        ('network.observations=[{kind="distance", from="A", to="B", sigma_mm=-1.0}]', "sigma_mm"),
        ('datum.kind="inner"', "nothing to constrain"),  # fixed pillars: no defect (s37)
        ('network.observations=[{kind="bearing", from="A", to="B", sigma_mm=1.0}]', "kind"),
        (
            'network.points=[{name="A", x_mm=0.0, y_mm=0.0}, {name="A", x_mm=1.0, y_mm=0.0}]',
            "duplicate",
        ),
    ],
)
def test_bad_networks_are_one_line_errors(override, key, capsys):
    # `sim check` in this process (the console script and python -m sim are sim.cli.main:
    # test_cli.py)
    code = main(["check", str(ROOT / "studies/network_testfield.toml"), "--set", override])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert key in err and "Traceback" not in err


def test_too_few_observations_is_named(capsys):
    code = main(["check", str(ROOT / "studies/network_plate.toml"), "--set", "network.generate=[]"])
    err = capsys.readouterr().err
    assert code == 2 and "0 degrees of freedom" in err, err


def test_rank_defect_not_covered_by_the_datum_names_it(tmp_path):
    study = tmp_path / "free.toml"
    study.write_text(
        (ROOT / "studies/network_testfield.toml")
        .read_text()
        .replace('role = "fixed"', 'role = "free"')
    )
    r = subprocess.run(
        [sys.executable, "-m", "sim", "check", str(study)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 2 and "rank defect of 3" in r.stderr, r.stderr


def test_jacobian_matches_finite_differences_with_constant_and_scale():
    """The model's Jacobian (every kind, the additive constant, the offset and the scale) is
    the derivative of its computed observations: central differences agree to 1e-6."""
    from sim.studies.network.model import computed

    for name, over in (
        ("network_brown", ("network.scale_ppm=50.0",)),
        ("network_testfield", ("network.scale_ppm=-30.0", "network.constant_mm=0.2")),
    ):
        net = build(load(name, *over))
        theta = net.theta_true() + 1e-3 * np.random.default_rng(3).standard_normal(net.q)
        _, J = computed(net, theta[None], jac=True)
        h = np.where(np.arange(net.q) < 2 * net.n, 1e-5 * np.abs(net.xy).max(), 1e-6)
        h[net.i_scale] = 1.0
        num = np.empty_like(J[0])
        ang = np.isin(net.kind, (1, 2))
        for g in range(net.q):
            e = np.zeros(net.q)
            e[g] = h[g]
            d = computed(net, (theta + e)[None])[0] - computed(net, (theta - e)[None])[0]
            d[ang] = (d[ang] + np.pi) % (2 * np.pi) - np.pi  # an angle's difference, wrapped
            num[:, g] = d / (2 * h[g])
        np.testing.assert_allclose(J[0], num, rtol=1e-6, atol=1e-9 * np.abs(J).max())


def test_an_estimated_scale_is_recovered_without_bias_and_with_its_analytic_sigma(tmp_path):
    out = tmp_path / "scale"
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "sim",
            "run",
            str(ROOT / "studies/network_testfield.toml"),
            "--out",
            str(out),
            "--trials",
            "600",
            "--set",
            "chunk=30",
            "--quiet",
            "--set",
            "network.estimate_scale=true",
            "--set",
            "network.scale_ppm=20.0",
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    p = pq.read_table(out / "parameters.parquet").to_pydict()
    k = p["parameter"].index("scale")
    assert p["unit"][k] == "ppm" and p["true"][k] == 20.0
    n = 600
    assert abs(p["mc_sigma"][k] / p["sigma"][k] - 1) < 4.5 / math.sqrt(2 * (n - 1))
    assert abs(p["mc_mean_error"][k]) < 4.5 * p["sigma"][k] / math.sqrt(n)
    assert len(p["parameter"]) == 5  # four orientations and the scale
    s = pq.read_table(out / "summary.parquet").to_pydict()
    assert "scale" in s["gama_xml"][0]  # gama-local cannot say it: refused
    # one more unknown never improves precision: every coordinate variance grows or stays
    _, fixed = pre(load("network_testfield"))
    _, scaled = pre(load("network_testfield", "network.estimate_scale=true"))
    assert scaled.dof == fixed.dof - 1
    d = np.einsum("nii->ni", scaled.cov) - np.einsum("nii->ni", fixed.cov)
    assert np.all(d >= -1e-12) and d.max() > 0


def test_an_estimated_scale_adds_the_scale_defect_to_a_free_distance_network():
    cfg = load("network_testfield", "network.estimate_scale=true")
    free = {
        **cfg,
        "network.points": [{**p, "role": "free"} for p in cfg["network.points"]],
        "network.generate": [g for g in cfg["network.generate"] if g["kind"] == "distance"]
        + [
            {
                "kind": "distance",
                "from": ["A", "B", "C", "D"],
                "to": ["A", "B", "C", "D"],
                "sigma_mm": 1.0,
            }
        ],
        "network.observations": [],
    }
    net, inner = pre({**free, "datum.kind": "inner"})
    C = datum(net, {**free, "datum.kind": "inner"}).constraint_matrix(net.theta_true()[None])
    assert inner.ok and C.shape[-1] == 4  # translation x, y, rotation, scale
    _, without = pre({**free, "network.estimate_scale": False, "datum.kind": "inner"})
    assert without.ok and inner.dof == without.dof  # one unknown more, one defect more
    from sim.studies.network.schema import check

    with pytest.raises(ConfigError, match=r"rank defect of 4 .* \(3 constraints\)"):
        check(
            {
                **free,
                "datum.kind": "constraints",
                "datum.constraints": [{"A.x": 1.0}, {"A.y": 1.0}, {"B.y": 1.0}],
            }
        )


def test_a_sweep_tabulates_the_design_figures_per_cell(tmp_path):
    """A [sweep] over a network key gives, per cell, the analytic design figures; an estimated
    scale is one more unknown, so no point sigma may shrink."""
    study = tmp_path / "sweep.toml"
    study.write_text(
        (ROOT / "studies/network_testfield.toml").read_text()
        + '\n[sweep]\n"network.estimate_scale" = [false, true]\n'
    )
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "sim",
            "run",
            str(study),
            "--out",
            str(tmp_path / "s"),
            "--quiet",
            "--no-figures",  # the cells' tables are read
            "--set",
            "trials=200",
            "--set",
            "chunk=10",
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    t = pq.read_table(tmp_path / "s/sweep.parquet").to_pydict()
    assert t["network.estimate_scale"] == [False, True] and all(t["feasible"])
    rms = t["network.design.sigma_rms_mm"]
    assert rms[1] > rms[0] > 0
    assert t["network.design.redundancy_min"][1] <= t["network.design.redundancy_min"][0] + 1e-12
    _, fixed = pre(load("network_testfield"))
    sig = np.sqrt(np.einsum("nii->ni", fixed.cov)[fixed.cov[:, 0, 0] > 0])
    assert abs(rms[0] - np.sqrt(np.mean(sig**2))) < 1e-12 * rms[0]
