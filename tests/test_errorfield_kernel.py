"""The compiled stress field (sim.instruments.plotter.errorfield_kernel) against the NumPy path it replaces: its
sine and cosine within a few units in the last place of the library's, the field equal within
a bound derived from those errors, non-finite points kept to themselves, absurd phases
refused."""

import numpy as np
import pytest

from sim.instruments.plotter import errorfield_kernel as ek
from sim.instruments.plotter import errorfields as ef
from sim.lsq import compile

pytestmark = pytest.mark.skipif(not compile.available(), reason="numba not installed")
EPS = np.finfo(float).eps


def test_sincos_within_a_few_ulp_of_the_library():
    rng = np.random.default_rng(5)
    # random phases of the study's size, the quadrant boundaries, signed zeros, large phases
    x = np.concatenate(
        [
            rng.uniform(-40.0, 40.0, 200_000),
            np.arange(-400, 401) * np.pi / 4,
            np.nextafter(np.arange(-40, 41) * np.pi / 2, np.inf),
            [0.0, -0.0],
            rng.uniform(-1e5, 1e5, 1000),
        ]
    )
    s, c = ek.sincos_array(x)
    scale = np.maximum(1.0, np.abs(x)) * EPS
    assert np.max(np.abs(s - np.sin(x)) / scale) < 4.0
    assert np.max(np.abs(c - np.cos(x)) / scale) < 4.0
    assert np.all(np.abs(s) <= 1.0) and np.all(np.abs(c) <= 1.0)
    s, c = ek.sincos_array(np.array([np.nan, np.inf]))
    assert np.all(np.isnan(s)) and np.all(np.isnan(c))


def test_stress_field_equals_numpy_path(monkeypatch):
    rng = np.random.default_rng(8)
    spec = ef.FieldSpec(stress_um=2.0, stress_length_mm=40.0, stress_waves=16)
    T, n = 30, 57
    params = ef.draw(spec, rng, T)
    P = rng.uniform(-130.0, 130.0, (T, n, 2))
    P[4, 9, 1] = np.nan
    fast = ef.evaluate_components(spec, params, P, skip_zero=True)["stress"]
    monkeypatch.setenv("SIM_NO_JIT", "1")
    ref = ef.evaluate_components(spec, params, P, skip_zero=True)["stress"]
    # bound: each of the K terms |b| (|d sin| + |d cos|) with both sides' sine and cosine
    # within 4 ulp of max(1, |phase|), plus the two summation orders (K terms each)
    q = params["stress"]
    K = spec.stress_waves
    ph = np.abs(np.matmul(np.nan_to_num(P), q["w"].transpose(0, 2, 1)))  # (T, n, K)
    bb = np.abs(q["b"])  # (T, K, 2)
    scale = (q["a"] * np.sqrt(2.0 / K))[:, None, None]
    tol = scale * (
        np.matmul(8 * EPS * np.maximum(1.0, ph), 2 * bb) + 2 * K * EPS * bb.sum(1)[:, None]
    )
    bad = np.zeros((T, n), bool)
    bad[4, 9] = True
    assert np.all(np.isnan(fast[bad])) and np.all(np.isnan(ref[bad]))
    assert np.all(np.abs(fast - ref)[~bad] <= tol[~bad])
    assert not np.array_equal(fast[~bad], np.zeros_like(fast[~bad]))


def test_stress_field_refuses_phases_beyond_its_reduction():
    rng = np.random.default_rng(2)
    spec = ef.FieldSpec(stress_um=1.0)
    params = ef.draw(spec, rng, 2)
    with pytest.raises(ValueError, match="phases"):
        ef.evaluate(spec, params, np.full((2, 3, 2), 1.0e9))
