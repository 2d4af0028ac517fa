"""Seed 001: combined adjustment with weighted grid coordinates, precision, chi-square test."""
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from sim import gridplate as gp
from sim import transforms2d as t2
from sim.config import ConfigError, load_study
from sim.plate import grid_points

ROOT = Path(__file__).resolve().parents[1]

UM = 1e-3
G = grid_points(5, 40.0)
N = G.shape[0]


def _plates(rng, T, sx_um=1.2, sg_um=0.7):
    p = t2.affine_from_rows(1 - 7.5e-6, 1 + 7.5e-6, 3.8 * t2.ARCSEC,
                            rng.uniform(-0.02, 0.02, T), (120.0, 118.0))
    comp = t2.apply_affine(p, G) + rng.normal(0, sx_um * UM, (T, N, 2))
    cert = G + rng.normal(0, sg_um * UM, (T, N, 2))
    return p, comp, cert


def test_infinite_grid_weight_is_ordinary_affine():
    rng = np.random.default_rng(1)
    _, comp, cert = _plates(rng, 50)
    fa = t2.fit_affine(cert, comp)
    for k in (0, 1):
        r = gp.combined_adjustment(comp[..., k], cert, 1.0, np.inf)
        np.testing.assert_allclose(r.params, fa.params[:, 3 * k:3 * k + 3], rtol=0, atol=1e-12)
        Qa = fa.cofactor[:, :3, :3]  # compared relative to sqrt(Q_ii Q_jj): rounding level
        sd = np.sqrt(np.einsum("tii->ti", Qa))
        np.testing.assert_allclose((r.cofactor - Qa) / sd[:, :, None] / sd[:, None, :], 0,
                                   atol=1e-12)
        np.testing.assert_allclose(r.s0, np.sqrt((fa.residuals[..., k] ** 2).sum(1) / (N - 3)),
                                   rtol=1e-10)
        assert np.all(r.v_grid == 0)


def test_noise_free_recovered_exactly():
    rng = np.random.default_rng(2)
    p, comp, cert = _plates(rng, 20, sx_um=0.0, sg_um=0.0)
    for k in (0, 1):
        r = gp.combined_adjustment(comp[..., k], cert, 1.0, 3.0)
        np.testing.assert_allclose(r.params, p[:, 3 * k:3 * k + 3], atol=1e-11)
        np.testing.assert_allclose(r.grid, cert, atol=1e-11)
        assert np.all(r.s0 < 1e-10)


def test_large_grid_weight_tends_to_affine():
    rng = np.random.default_rng(3)
    _, comp, cert = _plates(rng, 30)
    a = gp.combined_adjustment(comp[..., 0], cert, 1.0, 1e9)
    b = gp.combined_adjustment(comp[..., 0], cert, 1.0, np.inf)
    np.testing.assert_allclose(a.params, b.params, atol=1e-12)
    np.testing.assert_allclose(a.s0, b.s0, rtol=1e-6)


def test_combined_residual_equals_misclosure_theory():
    """Gauss-Helmert view: s0^2 (1/Px + (A^2+B^2)/Pc) = rms of the misclosures (N-3 dof)."""
    rng = np.random.default_rng(4)
    _, comp, cert = _plates(rng, 40)
    r = gp.combined_adjustment(comp[..., 0], cert, 1.0, 2.5)
    k = r.params[:, 0] ** 2 + r.params[:, 1] ** 2
    f = t2.fit_affine(cert, comp)
    sw2 = (f.residuals[..., 0] ** 2).sum(1) / (N - 3)
    np.testing.assert_allclose(r.s0 ** 2 * (1 + k / 2.5), sw2, rtol=1e-6)


def test_a_posteriori_variance_unbiased_with_right_weights():
    rng = np.random.default_rng(5)
    T = 4000
    _, comp, cert = _plates(rng, T)
    r = gp.combined_adjustment(comp[..., 0], cert, 1 / (1.2 * UM) ** 2, 1 / (0.7 * UM) ** 2)
    m = np.mean(r.s0 ** 2)
    assert abs(m - 1) < 4 * np.sqrt(2 / r.dof / T)


@pytest.mark.parametrize("stated_um", [0.7, 1.6, 0.2])
def test_chi2_rejects_wrong_grid_sigma_at_expected_rate(stated_um):
    rng = np.random.default_rng(6)
    T = 6000
    _, comp, cert = _plates(rng, T)
    sx = 1.2 * UM
    r = gp.combined_adjustment(comp[..., 0], cert, 1.0, sx ** 2 / (stated_um * UM) ** 2)
    _, _, rej = gp.chi2_test(r.s0, r.dof, sx, 0.05)
    c = (1.2 ** 2 + 0.7 ** 2) / (1.2 ** 2 + stated_um ** 2)
    lo, hi = stats.chi2.ppf(0.025, r.dof), stats.chi2.ppf(0.975, r.dof)
    expect = stats.chi2.cdf(lo / c, r.dof) + stats.chi2.sf(hi / c, r.dof)
    assert abs(rej.mean() - expect) < 4 * np.sqrt(expect * (1 - expect) / T)
    if stated_um == 1.6:
        assert expect > 0.5  # the test has power against a grid sigma stated 2.3x too large


def test_repeat_precision_unbiased():
    rng = np.random.default_rng(7)
    T, P, L = 3000, 2, 4
    readings = rng.normal(0, 1.5, (T, P, N, L, 2)) + rng.normal(0, 5, (T, P, N, 1, 2))
    si, s = gp.repeat_precision(readings)
    dof = 2 * P * N * (L - 1)
    assert abs(np.mean(s ** 2) / 1.5 ** 2 - 1) < 4 * np.sqrt(2 / dof / T)
    assert abs(np.mean(si ** 2) / (2 * 1.5 ** 2) - 1) < 4 * np.sqrt(2 / (2 * (L - 1)) / (T * P * N))


def test_reweight_reaches_the_fixed_point():
    rng = np.random.default_rng(8)
    _, comp, cert = _plates(rng, 200)
    rw = gp.reweight(comp[..., 0], cert, 0.7 * UM)
    ok = np.isfinite(rw["ratio"])
    np.testing.assert_allclose(rw["sigma_grid_implied"][ok], 0.7 * UM, rtol=1e-6)
    assert np.all(rw["passes"][ok])
    # sigma_x'^2 = s_w^2 - (A^2 + B^2) sigma_g^2 (subtraction estimate)
    f = t2.fit_affine(cert, comp)
    sw2 = (f.residuals[..., 0] ** 2).sum(1) / (N - 3)
    k = rw["result"].params[:, 0] ** 2 + rw["result"].params[:, 1] ** 2
    np.testing.assert_allclose(rw["s0"][ok] ** 2, (sw2 - k * (0.7 * UM) ** 2)[ok], rtol=1e-5)


def test_bad_config_names_the_key(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text('study = "gridplate_two_plates"\n[comparator]\ncoord_sigma_um = 0.5\n')
    with pytest.raises(ConfigError, match="comparator.coord_sigma_um"):
        load_study(f)
    f.write_text('study = "gridplate_two_plates"\n[grid]\nsigma_stated_um = 0.0\n')
    with pytest.raises(ConfigError, match="grid.sigma_stated_um"):
        load_study(f)


def test_study_runs_small(tmp_path):
    from sim.cli import main
    from sim.storage import read_table

    out = tmp_path / "gp"
    rc = main(["run", str(ROOT / "studies/gridplate_two_plates.toml"), "--trials", "40", "--quiet",
               "--set", "chunk=20", "--set", "analysis.ratios=[1.0, 3.0]", "--out", str(out)])
    assert rc == 0
    t = read_table(out / "claims.parquet").to_pydict()
    assert "twoplate.weight_ratio.grid_sigma_1to3_um" in t["claim"]
    assert set(t["kind"]) <= {"prediction", "input", "finding", "self-check"}
    for fig in ("residuals", "parameters", "coverage", "chi2_power", "implied_grid"):
        assert (out / f"{fig}.png").is_file()
