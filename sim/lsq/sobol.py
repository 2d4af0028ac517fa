"""Scrambled Sobol' points in the unit cube, the design of a joint exploration of inputs.

The sequence of Sobol' (1967) in base 2, generated in Gray-code order (Antonov & Saleev,
1979; Bratley & Fox, 1988, algorithm 659) from the direction numbers of Joe & Kuo (2008,
``new-joe-kuo-6.21201``, search criterion D(6)), 30 bits per coordinate, randomised by a
left linear matrix scramble and a digital shift (Matoušek, 1998; Owen, 2003).

:func:`sobol_base2` gives the same points, bit for bit, as
``scipy.stats.qmc.Sobol(d, scramble=True, rng=rng).random_base2(m)`` with the same
``numpy.random.Generator`` (and leaves ``rng`` in the same state: the scramble draws from a
child of ``rng``'s seed sequence, ``rng.spawn(1)``, never from ``rng``'s own stream); the
test ``tests/test_sobol.py`` holds it to SciPy. It reads the direction numbers from the file
SciPy ships with ``scipy.stats`` without importing ``scipy.stats``, which costs 0.5 to 0.8 s
of CPU in every process that does (a ``sim run`` that explores a consistent region:
:func:`sim.claims.inference.explore`). The points are unitless, in [0, 1).
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np
import scipy

__all__ = ["BITS", "sobol_base2"]

#: bits per coordinate (SciPy's default): 2**30 distinct points at most
BITS = 30
#: Joe & Kuo's primitive polynomials and initial direction numbers, as SciPy packs them
#: (``poly``: the polynomial's coefficients as the bits of an integer, leading and constant
#: term included; ``vinit``: the initial numbers m_1..m_s of each dimension)
_NUMBERS = Path(scipy.__file__).parent / "stats" / "_sobol_direction_numbers.npz"


@lru_cache(maxsize=8)
def direction_numbers(d: int) -> np.ndarray:
    """The ``(d, BITS)`` direction numbers v[k, j] (as integers of ``BITS`` bits, the first
    bit the most significant): the first dimension is van der Corput's sequence, dimension
    ``k`` follows the recurrence of its primitive polynomial of degree ``s`` (Bratley & Fox,
    eq. (2)): m_j = 2 a_1 m_{j-1} ^ 4 a_2 m_{j-2} ^ ... ^ 2^s m_{j-s} ^ m_{j-s}."""
    with np.load(_NUMBERS) as z:
        poly = [int(p) for p in z["poly"][:d]]
        vinit = z["vinit"][:d].astype(np.int64)
    if len(poly) < d:
        raise ValueError(f"sobol: at most {len(poly)} dimensions (got {d})")
    m = np.zeros((d, BITS), dtype=np.int64)
    m[0, :] = 1
    for k in range(1, d):
        p = poly[k]
        s = p.bit_length() - 1  # the degree
        m[k, :s] = vinit[k, :s]
        for j in range(s, BITS):
            new = int(m[k, j - s])
            for i in range(s):
                if (p >> (s - 1 - i)) & 1:
                    new ^= int(m[k, j - i - 1]) << (i + 1)
            m[k, j] = new
    return (m << (BITS - 1 - np.arange(BITS))).astype(np.uint64)  # v_j = m_j / 2^j, as bits


def _scrambled(v: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Left matrix scramble of the direction numbers and the digital shift, drawn (in this
    order, as SciPy draws them) from ``rng``: a random lower-triangular binary matrix with a
    unit diagonal per dimension multiplies the bits of every direction number (mod 2)."""
    d = v.shape[0]
    shift = rng.integers(2, size=(d, BITS), dtype=np.uint32).astype(np.uint64)
    shift = shift @ (np.uint64(1) << np.arange(BITS, dtype=np.uint64))  # bit j of the shift
    ltm = np.tril(rng.integers(2, size=(d, BITS, BITS), dtype=np.uint32)).astype(np.int64)
    ltm[:, np.arange(BITS), np.arange(BITS)] = 1
    msb = np.uint64(BITS - 1) - np.arange(BITS, dtype=np.uint64)
    bits = ((v[:, :, None] >> msb) & np.uint64(1)).astype(np.int64)  # (d, j, bit), MSB first
    out = np.einsum("djk,dpk->djp", bits, ltm) % 2  # bit p of the scrambled number
    return (out.astype(np.uint64) << msb).sum(axis=2, dtype=np.uint64), shift


def sobol_base2(d: int, m: int, rng: np.random.Generator) -> np.ndarray:
    """The first ``2**m`` points of a scrambled Sobol' sequence in ``d`` dimensions, an
    ``(2**m, d)`` array in [0, 1); the first point is the digital shift itself."""
    if not 1 <= d or not 0 <= m <= BITS:
        raise ValueError(f"sobol: need d >= 1 and 0 <= m <= {BITS} (got d={d}, m={m})")
    try:
        v = direction_numbers(d)
    except OSError:  # a SciPy that keeps its direction numbers elsewhere: its own generator
        from scipy.stats import qmc

        return qmc.Sobol(d=d, scramble=True, rng=rng).random_base2(m)
    v, shift = _scrambled(v, rng.spawn(1)[0])
    i = np.arange(2**m, dtype=np.uint64)
    gray = i ^ (i >> np.uint64(1))  # point i XORs the numbers of the bits set in gray(i)
    q = np.broadcast_to(shift, (2**m, d)).copy()
    for b in range(m):
        q ^= ((gray >> np.uint64(b)) & np.uint64(1))[:, None] * v[:, b][None, :]
    return q.astype(np.float64) / 2.0**BITS
