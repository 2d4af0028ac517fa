"""Compiled fast path of the ``stress`` error field (optional, via numba).

Seed: ``000_668e60e68f004f98.txt`` (Wolf & Pearsall 1976). :mod:`sim.instruments.plotter.errorfields`'s
``stress`` component is a smooth random field made of ``K`` random Fourier features,
``f_c(p) = sum_k b_kc cos(w_k . p + phi_kc)`` per axis ``c`` (``p`` mm, ``w`` rad/mm), so
every trial, point and wave costs a sine and a cosine: ``T n K`` of each, the largest single
cost of the Wolf study. NumPy's double-precision ``sin`` and ``cos`` are scalar library calls
on most machines (about 27 ns each here). Here the field is summed in one compiled pass with
:func:`sincos`, a branch-free sine and cosine the compiler vectorises across the points:

* argument reduction by ``pi / 2`` in two parts (Cody & Waite; fdlibm's ``__ieee754_rem_pio2``
  constants ``pio2_1``, a 33-bit head, and ``pio2_1t``, its tail): ``x = n pi/2 + r``,
  ``|r| <= pi / 4``, exact to about ``|n| 2^-85`` for the phases met here (``|n| < 2^20``);
* fdlibm's minimax polynomials of ``sin`` and ``cos`` on ``[-pi/4, pi/4]``
  (``__kernel_sin``, ``__kernel_cos``, error below one unit in the last place);
* the quadrant ``n mod 4`` picks and signs the two without branches.

So a sine or cosine differs from the library's by a few units in the last place of
``max(1, |x|)`` (a test holds it to ``4 eps max(1, |x|)`` over the phases of the study); the
field itself is summed in another order than NumPy's matrix products, so the two paths agree
to rounding (a test). Where :func:`sim.lsq.compile.available` is False,
:func:`sim.instruments.plotter.errorfields.evaluate_components` runs the NumPy path.
"""

from __future__ import annotations

import numpy as np

from sim.lsq import compile

__all__ = ["sincos", "sincos_array", "stress_field"]

# fdlibm (e_rem_pio2.c, k_sin.c, k_cos.c)
_INVPIO2 = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e00  # first 33 bits of pi / 2
_PIO2_1T = 6.07710050650619224932e-11  # pi / 2 - _PIO2_1
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11
#: adding and subtracting 1.5 * 2^52 rounds a double below 2^51 to the nearest whole number
_ROUND = 6755399441055744.0


def sincos(x):  # pragma: no cover - compiled (the test calls it through the kernel)
    """``(np.sin(x), np.cos(x))`` to a few units in the last place, for a double with
    ``|x| < 2^20 pi / 2``, without branches (compiled into the kernels that call it)."""
    n = (x * _INVPIO2 + _ROUND) - _ROUND
    r = (x - n * _PIO2_1) - n * _PIO2_1T
    z = r * r
    s = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    hz = 0.5 * z
    w = 1.0 - hz
    c = w + (
        ((1.0 - w) - hz) + z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    )
    q = n - 4.0 * np.floor(n * 0.25)  # 0, 1, 2, 3
    odd = q == 1.0 or q == 3.0
    sx = c if odd else s
    cx = s if odd else c
    if q >= 2.0:
        sx = -sx
    if q == 1.0 or q == 2.0:
        cx = -cx
    return sx, cx


def _stress(X, Y, w, bc, bs, scale, out):  # pragma: no cover - compiled
    """``out[t, i, c] = scale[t] sum_k (cos(ph) bc[t, k, c] - sin(ph) bs[t, k, c])`` with
    ``ph = X[t, i] w[t, k, 0] + Y[t, i] w[t, k, 1]``: the NumPy path's
    ``scale * (cos(P @ w.T) @ bc - sin(P @ w.T) @ bs)``; the points are the inner loop (the
    compiler's vector lanes), the waves the outer one."""
    T, n = X.shape
    K = w.shape[1]
    f0 = np.empty(n)
    f1 = np.empty(n)
    for t in range(T):
        f0[:] = 0.0
        f1[:] = 0.0
        for k in range(K):
            wx, wy = w[t, k, 0], w[t, k, 1]
            c0, c1, s0, s1 = bc[t, k, 0], bc[t, k, 1], bs[t, k, 0], bs[t, k, 1]
            for i in range(n):
                s, c = sincos(X[t, i] * wx + Y[t, i] * wy)
                f0[i] += c * c0 - s * s0
                f1[i] += c * c1 - s * s1
        a = scale[t]
        for i in range(n):
            out[t, i, 0] = a * f0[i]
            out[t, i, 1] = a * f1[i]


def _sincos_array(x, s, c):  # pragma: no cover - compiled
    for i in range(x.size):
        s[i], c[i] = sincos(x[i])


def sincos_array(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`sincos` of every element of ``x`` (for the tests)."""
    x = np.ascontiguousarray(x, dtype=np.float64).ravel()
    s, c = np.empty_like(x), np.empty_like(x)
    compile.compiled(_sincos_array, helpers=(sincos,))(x, s, c)
    return s, c


def stress_field(
    P: np.ndarray, w: np.ndarray, b: np.ndarray, phi: np.ndarray, scale: np.ndarray
) -> np.ndarray:
    """The ``stress`` displacements ``(T, n, 2)``: ``scale[t] sum_k b_kc cos(w_k . p + phi_kc)``
    at points ``P (T, n, 2)`` mm, waves ``w (T, K, 2)`` rad/mm, weights ``b`` and phases
    ``phi (T, K, 2)``, written as ``cos(w.p) b cos(phi) - sin(w.p) b sin(phi)``."""
    T, n = P.shape[:2]
    if n and w.size and 2.0 * np.max(np.abs(P)) * np.max(np.abs(w)) > 1.0e6:  # |x| < 2^20
        raise ValueError("stress field: phases beyond 1e6 rad (points or waves out of range)")
    X = np.ascontiguousarray(P[..., 0], dtype=np.float64)
    Y = np.ascontiguousarray(P[..., 1], dtype=np.float64)
    bc = np.ascontiguousarray(b * np.cos(phi))
    bs = np.ascontiguousarray(b * np.sin(phi))
    out = np.empty((T, n, 2))
    compile.compiled(_stress, helpers=(sincos,))(
        X,
        Y,
        np.ascontiguousarray(w, dtype=np.float64),
        bc,
        bs,
        np.ascontiguousarray(scale, dtype=np.float64),
        out,
    )
    return out
