"""The suite's scrambled Sobol' points (sim.lsq.sobol) are SciPy's, bit for bit, and draw from
the caller's generator as SciPy does; importing the suite's exploration does not import
scipy.stats."""

import subprocess
import sys

import numpy as np
import pytest
from scipy.stats import qmc

from sim.lsq.sobol import BITS, direction_numbers, sobol_base2


@pytest.mark.parametrize("d", [1, 2, 3, 6, 11, 40])
@pytest.mark.parametrize("seed", [0, 7, 2**40 + 3])
def test_the_points_are_scipys_and_the_generator_moves_as_with_scipy(d, seed):
    for m in (0, 1, 4, 9):
        ours, theirs = np.random.default_rng(seed), np.random.default_rng(seed)
        a = sobol_base2(d, m, ours)
        b = qmc.Sobol(d=d, scramble=True, rng=theirs).random_base2(m)
        assert a.dtype == b.dtype and np.array_equal(a, b), (d, m)
        # the stream is untouched and the seed sequence spawned once, as by SciPy
        assert ours.random() == theirs.random()
        assert ours.spawn(1)[0].random() == theirs.spawn(1)[0].random()


def test_the_points_are_a_01_net_in_every_coordinate():
    """Each coordinate of 2**m points holds one point in each of the 2**m equal intervals
    (the scramble keeps the net property), and two seeds give other points."""
    for m in (3, 8):
        u = sobol_base2(5, m, np.random.default_rng(1))
        assert ((0 <= u) & (u < 1)).all()
        for k in range(5):
            assert sorted(np.floor(u[:, k] * 2**m).astype(int)) == list(range(2**m))
    assert not np.array_equal(
        sobol_base2(3, 4, np.random.default_rng(1)), sobol_base2(3, 4, np.random.default_rng(2))
    )


def test_the_direction_numbers_start_as_joe_and_kuo_print_them():
    """Dimension 1 is van der Corput's (every m_j = 1); dimension 2 (x + 1, m_1 = 1) gives
    m = 1, 3, 5, 15, 17, 51 (Joe & Kuo 2008's recurrence)."""
    v = direction_numbers(2).astype(np.int64)
    m = v >> (BITS - 1 - np.arange(BITS))
    assert (m[0] == 1).all()
    assert list(m[1, :6]) == [1, 3, 5, 15, 17, 51]


def test_without_the_direction_numbers_file_scipy_makes_the_points(monkeypatch, tmp_path):
    """A SciPy that keeps its direction numbers elsewhere: the same points, from SciPy."""
    from sim.lsq import sobol

    monkeypatch.setattr(sobol, "_NUMBERS", tmp_path / "missing.npz")
    sobol.direction_numbers.cache_clear()
    try:
        a = sobol_base2(4, 5, np.random.default_rng(9))
    finally:
        sobol.direction_numbers.cache_clear()
    b = qmc.Sobol(d=4, scramble=True, rng=np.random.default_rng(9)).random_base2(5)
    assert np.array_equal(a, b)


def test_bad_sizes_are_refused():
    with pytest.raises(ValueError, match="d >= 1"):
        sobol_base2(0, 3, np.random.default_rng(0))
    with pytest.raises(ValueError, match="m <= 30"):
        sobol_base2(2, 31, np.random.default_rng(0))


def test_an_exploration_does_not_import_scipy_stats():
    code = (
        "import sys, numpy as np\n"
        "from sim.claims.inference import explore\n"
        "from sim.lsq.sobol import sobol_base2\n"
        "sobol_base2(3, 5, np.random.default_rng(0))\n"
        "print('scipy.stats' in sys.modules)\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert r.stdout.strip() == "False"
