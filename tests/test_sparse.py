"""The sparse path (issue 23): sparse equals dense on small networks (sigma, redundancy, MDB to
1e-10), selected inversion equals the dense inverse on the pattern, the compiled gradient
equals the dense Jacobian's, a batch of trials gives the same numbers however it is split,
the k-d tree finds the same nearest targets as a full sort, and a network the old count
limits refused now checks."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from scipy import sparse

from sim.lsq import sparse as lsq_sparse
from sim.mc import network_size
from sim.mc.config import ConfigError
from sim.mc.estimate import check_limits, estimate
from sim.studies import load_study
from sim.studies.network import model
from sim.studies.network.analysis import analyse, in_datum, inner_defect, mc_chunk
from sim.studies.network.definition import _targets, build
from sim.studies.network.gama import merge_gama
from sim.studies.network.kernel import residual_gradient
from sim.studies.network.model import computed, datum, jacobian_sparse, pattern, simulate
from sim.studies.network.sparse_analysis import (
    analyse_sparse,
    in_datum_sparse,
    mc_chunk_sparse,
    variances,
)

ROOT = Path(__file__).resolve().parent.parent


def load(name, *over):
    _, cfg = load_study(ROOT / "studies" / f"{name}.toml", list(over))
    return merge_gama(cfg)


def trilateration(tmp_path, n=6, kind="inner", extra=""):
    """A jittered n x n trilateration grid, 8 nearest neighbours, in ``kind`` datum."""
    f = tmp_path / "tri.toml"
    f.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\nseed = 5\n[network]\n'
        f'random = [ {{ prefix = "P", n = {n * n}, half_extent_mm = 5000.0 }} ]\n'
        'generate = [ { kind = "distance", from = "P*", to = "P*", nearest = 8, '
        'sigma_mm = 1.0 }, { kind = "direction", from = "P1*", to = "P*", nearest = 4, '
        f'sigma_arcsec = 2.0 }} ]\n{extra}[datum]\nkind = "{kind}"\n'
    )
    _, cfg = load_study(f)
    return cfg


CASES = {
    "brown (constraints datum, constant, offset)": lambda tmp: load("network_brown"),
    "test field (fixed, directions, angle)": lambda tmp: load("network_testfield"),
    "grid plate (observed coordinates)": lambda tmp: load("network_plate"),
    "trilateration, inner datum": lambda tmp: trilateration(tmp),
    "trilateration, scale estimated": lambda tmp: trilateration(
        tmp, 5, extra="estimate_scale = true\nestimate_constant = true\n"
    ),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_sparse_equals_dense_on_small_networks(case, tmp_path):
    cfg = CASES[case](tmp_path)
    net = build(cfg)
    dt = datum(net, cfg)
    d = analyse(net, dt, 0.001, 0.8)
    s = analyse_sparse(net, dt, 0.001, 0.8)
    assert d.ok and s.ok and s.dof == d.dof
    sig_d = np.sqrt(np.maximum(d.cov[:, [0, 1], [0, 1]], 0))
    sig_s = np.sqrt(np.maximum(s.cov[:, [0, 1], [0, 1]], 0))
    scale = sig_d.max()
    np.testing.assert_allclose(sig_s, sig_d, rtol=1e-10, atol=1e-10 * scale)
    np.testing.assert_allclose(s.cov, d.cov, rtol=0, atol=1e-10 * scale**2)
    np.testing.assert_allclose(s.redundancy, d.redundancy, rtol=0, atol=1e-10)
    fin = np.isfinite(d.mdb)
    assert np.array_equal(fin, np.isfinite(s.mdb))
    # MDB = delta0 sigma / sqrt(r): an error of 1e-10 in r is one of 0.5e-10 / r relative
    r = d.redundancy[fin]
    np.testing.assert_array_less(
        np.abs(s.mdb[fin] / d.mdb[fin] - 1), 1e-10 * np.maximum(1.0, 0.5 / r) + 1e-14
    )
    np.testing.assert_array_less(
        np.abs(s.bnr[fin] / d.bnr[fin] - 1), 1e-10 * np.maximum(1.0, 1 / r) + 1e-12
    )
    # the sparse path's external reliability is exactly the local one: the largest
    # displacement an undetected MDB causes at the observation's own points (from the dense
    # shift Q Aw_i' MDB_i / sigma_i), never above the dense path's largest over all points
    tol_ext = 1e-10 * np.maximum(1.0, 0.5 / r) + 1e-14
    Aw = model.weighted_design(net, d.free).toarray()
    shift = np.zeros((net.q, net.m))
    shift[d.free] = (d.Q @ Aw.T) * np.where(fin, d.mdb / net.sigma, 0.0)
    disp = np.hypot(shift[0 : 2 * net.n : 2], shift[1 : 2 * net.n : 2])  # (n, m)
    local = np.zeros(net.m)
    for e in (net.i, net.j, net.k):
        local = np.maximum(local, np.where(e >= 0, disp[np.maximum(e, 0), np.arange(net.m)], 0))
    err = np.abs(s.ext_max_mm[fin] - local[fin])
    assert np.all(err <= tol_ext * local[fin] + 1e-14 * local.max())
    assert np.all(s.ext_max_mm[fin] <= d.ext_max_mm[fin] * (1 + tol_ext))
    par = np.arange(len(d.free))
    np.testing.assert_allclose(
        variances(s, par), variances(d, par), rtol=1e-9, atol=1e-12 * d.Q.diagonal().max()
    )
    pts = list(range(net.n))
    np.testing.assert_allclose(
        in_datum_sparse(net, s, pts), in_datum(net, d, pts), rtol=0, atol=1e-10 * scale**2
    )


def test_selected_inverse_equals_the_dense_inverse_on_the_pattern():
    rng = np.random.default_rng(3)
    p = 60
    B = sparse.random(p, p, density=0.05, random_state=4) + sparse.eye(p)
    N = (B @ B.T + sparse.eye(p)).tocsc()
    f = lsq_sparse.factorize(N)
    assert f.ok
    a, b = N.nonzero()
    Q = np.linalg.inv(N.toarray())
    np.testing.assert_allclose(f.entries(a, b), Q[a, b], rtol=0, atol=1e-12 * abs(Q).max())
    X = rng.standard_normal((p, 7))
    np.testing.assert_allclose(f.solve(X), Q @ X, rtol=1e-10, atol=1e-12)


def test_numpy_twins_equal_the_compiled_kernels(tmp_path, monkeypatch):
    """SIM_NO_JIT=1: SciPy's substitutions and the network gradient's NumPy twin give the
    compiled kernels' numbers to rounding (the same sums in another order)."""
    rng = np.random.default_rng(5)
    p = 60
    B = sparse.random(p, p, density=0.05, random_state=6) + sparse.eye(p)
    f = lsq_sparse.factorize((B @ B.T + sparse.eye(p)).tocsc())
    X = rng.standard_normal((p, 5))
    cfg = load("network_testfield")
    net = build(cfg)
    free = datum(net, cfg).free_index(net.q)
    fpos = np.full(net.q, -1)
    fpos[free] = np.arange(len(free))
    theta = net.theta_true()[None] + rng.normal(0, 1e-3, (3, net.q))
    obs = simulate(net, rng, 3)
    x1, (r1, g1) = f.solve(X), residual_gradient(net, fpos, theta, obs)
    monkeypatch.setenv("SIM_NO_JIT", "1")
    x2, (r2, g2) = f.solve(X), residual_gradient(net, fpos, theta, obs)
    np.testing.assert_allclose(x2, x1, rtol=0, atol=1e-13 * abs(x1).max())
    np.testing.assert_allclose(r2, r1, rtol=0, atol=1e-12 * abs(r1).max())
    np.testing.assert_allclose(g2, g1, rtol=0, atol=1e-12 * abs(g1).max())


def test_a_singular_network_is_refused_with_its_pivot():
    p = 10
    d = np.r_[np.ones(p - 1), 1e-30]
    N = sparse.csc_matrix(
        np.diag(d) + np.diag(np.full(p - 1, 0.5), 1) + np.diag(np.full(p - 1, 0.5), -1)
    )
    f = lsq_sparse.factorize(N)
    assert not f.ok and "singular" in f.message


def test_symbolic_pattern_is_closed_where_values_cancel(tmp_path):
    """A regular grid's normals have entries that cancel to exactly zero; the factor's pattern
    is the filled graph regardless, so every point block is found."""
    cfg = trilateration(tmp_path)
    net = build(cfg)
    s = analyse_sparse(net, datum(net, cfg), 0.001, 0.8)
    assert np.isfinite(s.cov).all() and np.isfinite(s.redundancy).all()


def test_sparse_jacobian_and_compiled_gradient_equal_the_dense_jacobian(tmp_path):
    for cfg in (load("network_testfield"), load("network_brown"), trilateration(tmp_path)):
        net = build(cfg)
        rng = np.random.default_rng(1)
        theta = net.theta_true()[None] + rng.normal(0, 1e-3, (3, net.q))
        val, J = computed(net, theta, jac=True)
        val2, vals = jacobian_sparse(net, theta)
        cols = pattern(net)
        Js = np.zeros((3, net.m, net.q + 1))
        for s in range(cols.shape[1]):
            Js[:, np.arange(net.m), np.where(cols[:, s] >= 0, cols[:, s], net.q)] += vals[..., s]
        np.testing.assert_array_equal(val2, val)
        np.testing.assert_allclose(Js[..., : net.q], J, rtol=1e-15, atol=0)
        obs = simulate(net, rng, 3)
        free = datum(net, cfg).free_index(net.q)
        fpos = np.full(net.q, -1)
        fpos[free] = np.arange(len(free))
        r, g = residual_gradient(net, fpos, theta, obs)
        r_d = obs - val
        ang = np.isin(net.kind, (1, 2))
        r_d = np.where(ang, (r_d + np.pi) % (2 * np.pi) - np.pi, r_d)
        np.testing.assert_allclose(r, r_d, rtol=1e-12, atol=1e-15)
        g_d = np.einsum("tmq,tm->tq", J, r_d / net.sigma**2)[:, free]
        np.testing.assert_allclose(g, g_d, rtol=1e-9, atol=1e-9 * abs(g_d).max())


def _sparse_chunk(net, an, rng, n, pts):
    cov_inv = np.linalg.inv(an.cov[pts])
    return mc_chunk_sparse(
        rng, n, net, an.free, an.factor, cov_inv, pts, 12.0, 1e-10, 20, an.dof, None
    )


def test_sparse_monte_carlo_equals_the_dense_chunk(tmp_path):
    """Same seed, same readings: the sparse chunk's sums equal the dense engine's (both solve
    the same least-squares problems to the tolerance)."""
    cfg = trilateration(tmp_path)
    net = build(cfg)
    dt = datum(net, cfg)
    d, s = analyse(net, dt, 0.001, 0.8), analyse_sparse(net, dt, 0.001, 0.8)
    pts = np.arange(net.n)
    C = dt.constraint_matrix(net.theta_true()[None])[0]
    a = mc_chunk(
        np.random.default_rng(9), 30, net, d.free, C, np.linalg.inv(d.cov), pts, 12.0, 1e-10, 20
    )
    b = _sparse_chunk(net, s, np.random.default_rng(9), 30, pts)
    assert a["sum.n"][0, 0] == b["sum.n"][0, 0] == 30
    scale = np.abs(a["sum.ee"]).max()
    np.testing.assert_allclose(b["sum.ee"], a["sum.ee"], rtol=0, atol=1e-8 * scale)
    np.testing.assert_allclose(b["sum.e"], a["sum.e"], rtol=0, atol=1e-8 * np.sqrt(scale) * 30)
    np.testing.assert_allclose(b["rows.sigma0"], a["rows.sigma0"], rtol=1e-8)
    assert np.array_equal(b["sum.inside"], a["sum.inside"])


def test_a_batch_gives_the_same_numbers_however_it_is_split(tmp_path):
    cfg = trilateration(tmp_path, 7)
    net = build(cfg)
    an = analyse_sparse(net, datum(net, cfg), 0.001, 0.8)
    obs = simulate(net, np.random.default_rng(2), 12)
    fpos = np.full(net.q, -1)
    fpos[an.free] = np.arange(len(an.free))
    theta0 = np.repeat(net.theta_true()[None], 12, 0)

    def solve(rows):
        return lsq_sparse.gauss_newton_shared(
            lambda th, k: residual_gradient(net, fpos, th, obs[rows][k]),
            theta0[rows],
            an.free,
            an.factor,
            1.0 / net.sigma**2,
            1e-10,
            20,
        )

    whole = solve(np.arange(12))
    parts = [solve(np.arange(0, 5)), solve(np.arange(5, 6)), solve(np.arange(6, 12))]
    joined = [np.concatenate([p[k] for p in parts]) for k in range(4)]
    np.testing.assert_allclose(joined[0], whole[0], rtol=1e-13, atol=1e-13)  # theta
    # vpv: each residual obs - computed carries the rounding of values of size |obs| (about
    # 4 ulp: the coordinate differences, their squares' sum, the root, the subtraction), which
    # the BLAS kernels chosen for another batch size round otherwise (1.7e-13 relative on an
    # AMD EPYC); a mixed-up trial would differ by whole units
    r, _ = residual_gradient(net, fpos, whole[0], obs)
    w = 1.0 / net.sigma**2
    rounding = 2 * (w * np.abs(r) * np.abs(obs)).sum(1) * 4 * np.finfo(float).eps
    assert (np.abs(joined[1] - whole[1]) <= rounding).all(), (joined[1] - whole[1], rounding)
    np.testing.assert_array_equal(joined[2], whole[2])  # iterations
    np.testing.assert_array_equal(joined[3], whole[3])  # status
    assert (whole[3] == 0).all()


def test_nearest_targets_by_kd_tree_equal_a_full_sort():
    rng = np.random.default_rng(0)
    grid = np.array([[c, b] for b in range(9) for c in range(9)], float) * 10.0  # many ties
    for xy in (grid, rng.uniform(-1, 1, (120, 2))):
        n = len(xy)
        fr = list(range(0, n, 3))
        to = list(rng.permutation(n)[: n - 5])
        for k in (1, 2, 4, 8):
            got = _targets(xy, fr, to, k)
            for s, tg in zip(fr, got):
                cand = [t for t in to if t != s]
                d = np.hypot(*(xy[cand] - xy[s]).T)
                want = [cand[b] for b in np.argsort(d, kind="stable")[:k]]
                assert tg == want


def test_the_issue_network_that_counts_refused_now_checks(tmp_path):
    """20 x 20 grid, nearest 8 (the issue's example: 400 x 400 pairs were refused before
    nearest applied): it checks, on the sparse path."""
    f = tmp_path / "g.toml"
    f.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\n'
        'grids = [ { prefix = "P", nx = 20, ny = 20, spacing_mm = 1000.0 } ]\n'
        'generate = [ { kind = "distance", from = "P*", to = "P*", nearest = 8, '
        'sigma_mm = 1.0 } ]\n[datum]\nkind = "inner"\n'
    )
    _, cfg = load_study(f)
    net = build(cfg)
    assert net.n == 400 and net.m == 3200
    an = analyse_sparse(net, datum(net, cfg), 0.001, 0.8)
    assert an.ok and abs(an.redundancy.sum() - an.dof) < 1e-6


def test_the_datum_must_cover_the_defect():
    p = 4
    N = sparse.csc_matrix(
        np.array([[1.0, -1, 0, 0], [-1, 2, -1, 0], [0, -1, 2, -1], [0, 0, -1, 1]])
    )
    G = np.ones((p, 1))
    f = lsq_sparse.factorize(N, G, np.array([[1.0], [0], [0], [0]]))
    assert f.ok
    a, b = N.nonzero()
    K = np.block([[N.toarray(), np.eye(p)[:, :1]], [np.eye(p)[:1], np.zeros((1, 1))]])
    np.testing.assert_allclose(f.entries(a, b), np.linalg.inv(K)[a, b], atol=1e-12)
    # unknown 1 is held (the largest of the null space scaled to the unit-diagonal normals,
    # diag(N)^(1/2) G); 0 and 2 are then not joined in the pattern: not computed
    assert list(f.keep) == [0, 2, 3] and np.isnan(f.entries(0, 2))
    bad = lsq_sparse.factorize(N, G, np.array([[1.0, 0], [0, 1], [0, 0], [0, 0]]))
    assert not bad.ok and "2 constraints for a rank defect of 1" in bad.message
    assert not lsq_sparse.factorize(N, G, None).ok


def test_the_estimate_counts_nonzeros_and_bounds_a_network_by_memory(tmp_path, monkeypatch):
    """The network estimator: unknowns from the declaration, memory of the sparse path
    growing with the chunk; a network too large for the memory limit is refused with the
    estimate (exit 2 at the command line), not by a count."""
    _, cfg = load_study(ROOT / "studies" / "network_gridplate_2500.toml")
    est = estimate(cfg)
    assert est.unknowns >= 5000 and est.trials == cfg["trials"]
    assert estimate({**cfg, "chunk": 200}).bytes > est.bytes
    # a set larger than NAME_SAMPLE is matched through evenly spaced names: close to the
    # exact count (the declared 2,500-point grid through 500 of its names)
    exact = est.bytes
    monkeypatch.setattr(network_size, "NAME_SAMPLE", 500)
    assert estimate(cfg).bytes == pytest.approx(exact, rel=0.02)
    big = {**cfg, "network.grids": [{**cfg["network.grids"][0], "nx": 3000, "ny": 3000}]}
    with pytest.raises(ConfigError, match="GiB"):
        check_limits(estimate(big))
    f = tmp_path / "huge.toml"
    f.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\n[network]\n'
        'grids = [ { prefix = "P", nx = 100000, ny = 100000, spacing_mm = 1.0 } ]\n'
        'generate = [ { kind = "distance", from = "P*", to = "P*", nearest = 4, '
        "sigma_mm = 1.0 } ]\n"
    )
    with pytest.raises(ConfigError, match="memory limit"):
        load_study(f)


def test_large_network_keeps_the_datum_semantics_on_the_sparse_path(tmp_path, monkeypatch):
    """Above SPARSE_MIN_UNKNOWNS the defects come from the sparse design: a directions-only
    network with one fixed point has the rotation and the scale about it as its defects (the
    same span as the dense design gives); the inner datum over them and the inner_over
    transformation (translation, rotation and scale: no length) equal the dense path's.

    The bound is derived, not chosen: both paths invert the same unit-diagonal normals by a
    backward-stable factorisation (relative backward error of order eps), so to first order
    their cofactors agree to ``kappa eps`` relative to the largest variance, ``kappa`` the
    condition number of the scaled normals the sparse factor holds (here about 9e6: a
    directions-only network with one fixed point; observed errors are about 1/14 of the
    bound). The redundancy numbers ``1 - a' Q a`` (``a' Q a`` at most 1) take the same bound."""
    f = tmp_path / "dir.toml"
    f.write_text(
        'study = "network"\ntrials = 40\nchunk = 2\nseed = 3\n[network]\n'
        'points = [ { name = "F", x_mm = 0.0, y_mm = 0.0, role = "fixed" } ]\n'
        'random = [ { prefix = "P", n = 225, half_extent_mm = 20000.0 } ]\n'
        'generate = [ { kind = "direction", from = "*", to = "*", nearest = 6, '
        'sigma_arcsec = 2.0 } ]\n[datum]\nkind = "inner"\n'
    )
    _, cfg = load_study(f)
    net = build(cfg)
    assert model.use_sparse(net)
    dt = datum(net, cfg)
    free = dt.free_index(net.q)
    D_s = model.defect_basis(net, free)
    s = analyse_sparse(net, dt, 0.001, 0.8)
    with monkeypatch.context() as m:
        m.setattr(model, "SPARSE_MIN_UNKNOWNS", 10**9)
        D_d = model.defect_basis(net, free)
        H_d = inner_defect(net)
    assert D_s.shape[1] == D_d.shape[1] == 2 and H_d.shape[1] == 4
    np.testing.assert_allclose(D_s @ D_s.T, D_d @ D_d.T, rtol=0, atol=1e-10)
    np.testing.assert_allclose(D_s.T @ D_s, np.eye(2), rtol=0, atol=1e-12)
    np.testing.assert_allclose(inner_defect(net) @ inner_defect(net).T, H_d @ H_d.T, atol=1e-10)
    d = analyse(net, dt, 0.001, 0.8)
    assert d.ok and s.ok and s.dof == d.dof
    F = s.factor
    n_r = len(F.keep)
    L = sparse.csc_matrix((F.data, F.indices, F.indptr), shape=(n_r, n_r)).toarray()
    L += np.eye(n_r)
    tol = np.linalg.cond(L @ np.diag(F.D) @ L.T) * np.finfo(float).eps
    assert 1e-11 < tol < 1e-8  # the conditioning the bound was derived for
    scale = np.sqrt(d.cov[:, [0, 1], [0, 1]]).max()
    np.testing.assert_allclose(s.cov, d.cov, rtol=0, atol=tol * scale**2)
    np.testing.assert_allclose(s.redundancy, d.redundancy, rtol=0, atol=tol)
    np.testing.assert_allclose(s.n_diag, d.n_diag, rtol=1e-12)
    pts = list(range(1, 40))
    np.testing.assert_allclose(
        in_datum_sparse(net, s, pts), in_datum(net, d, pts), rtol=0, atol=tol * scale**2
    )


def test_a_large_network_runs_end_to_end_on_the_sparse_path(tmp_path):
    """`sim run` of a 20 x 20 grid (distances and directions to the nearest, inner datum,
    estimated scale, another datum and a compared parameterisation): every table written,
    Monte Carlo within its sampling error of the analytic sigmas, redundancy sum = dof."""
    f = tmp_path / "big.toml"
    f.write_text(
        'study = "network"\ntrials = 60\nchunk = 3\nseed = 3\n[network]\n'
        "estimate_scale = true\n"
        'grids = [ { prefix = "P", nx = 20, ny = 20, spacing_mm = 10000.0 } ]\n'
        'generate = [ { kind = "distance", from = "P*", to = "P*", nearest = 8, sigma_mm = 1.0 },'
        ' { kind = "direction", from = "P*", to = "P*", nearest = 4, sigma_arcsec = 1.0 } ]\n'
        '[datum]\nkind = "inner"\n[output]\ninner_over = ["P1?"]\n'
        '[compare]\nfix = ["P1", "P400"]\n'
    )
    out = tmp_path / "out"
    r = subprocess.run(
        [sys.executable, "-m", "sim", "run", str(f), "--out", str(out), "--quiet"],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert r.returncode == 0, r.stderr
    s = pq.read_table(out / "summary.parquet").to_pydict()
    assert s["points"] == [400] and s["converged"] == [60]
    assert abs(s["redundancy_sum"][0] - s["dof"][0]) < 1e-6
    # mean of 800 sigma ratios, each from 60 trials (sd about 1/sqrt(120) each, correlated):
    # 10 % is several times the sampling error of the mean
    assert abs(s["mc_over_analytic"][0] - 1) < 0.1
    pts = pq.read_table(out / "points.parquet").to_pydict()
    assert len(pts["point"]) == 400 and np.isfinite(pts["dilution_pct"]).sum() >= 398
    par = pq.read_table(out / "parameters.parquet").to_pydict()
    assert "scale" in par["parameter"] and all(np.isfinite(par["sigma"]))
    d = pq.read_table(out / "datums.parquet").to_pydict()
    assert len(d["point"]) == 400 and np.all(np.isfinite(d["sigma_x_mm"]))
    assert (out / "network.png").is_file() and (out / "reliability.png").is_file()
