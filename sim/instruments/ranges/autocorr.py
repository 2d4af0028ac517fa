"""The integrated autocorrelation time of an ensemble sampler's chain, about the ensemble's mean.

Model: ``tau = 1 + 2 sum_k rho(k)`` of each parameter, ``rho`` the autocorrelation of the
walkers' deviations from the mean over all kept steps and walkers (every walker samples the
same posterior after the burn-in), averaged over the walkers, summed up to emcee's automatic
window (Sokal: the smallest ``M >= c tau(M)``, as :func:`emcee.autocorr.auto_window`, ``c = 5``;
where the chain is shorter than that, at least ``n / c``).

Why not emcee's :func:`emcee.autocorr.integrated_time` as it is: it takes each walker's
autocorrelation about that walker's own mean, which removes the slow part of the chain that
tau is to measure: on chains near the suite's rule of 50 tau (:data:`sim.claims.rules.
MIN_CHAIN_TAU`) it underestimates tau by about ``10 / (n / tau)`` (10 % at 50 tau), and
emcee documents the estimate as unreliable there (its ``tol = 50``). On AR(1) chains of known
tau (32 walkers, 7 parameters, the largest tau of the 7, 200 chains at each length) emcee's
estimate passed the rule on 44 % of chains only 45 tau long and 77 % at 48; about the
ensemble's mean the walkers' spread of their means is counted, the estimate errs high by about
as much (the conservative side), and 0 % at 45 and 0.5 % at 48 passed (``tests/
test_doors44v.py``; the table is in docs/verdict-rules.md). On a long chain the two agree.
"""

from __future__ import annotations

import numpy as np

__all__ = ["ensemble_time", "WINDOW_C"]

#: emcee's default window factor ``c`` (Sokal's automatic window: ``M >= c tau(M)``)
WINDOW_C = 5.0


def ensemble_time(chain: np.ndarray, c: float = WINDOW_C) -> np.ndarray:
    """Integrated autocorrelation time (steps) of each parameter of ``chain`` (steps,
    walkers, d), about the ensemble's mean (see the module doc), shape ``(d,)``."""
    x = np.asarray(chain, float)
    return np.array([_one(x[:, :, k], c) for k in range(x.shape[2])])


def _one(x: np.ndarray, c: float) -> float:
    """tau of one parameter's chain ``x`` (steps, walkers): a parameter at a time, the
    transforms of the whole chain at once held 600 to 730 bytes a walker's step of Brown's
    posterior (7 parameters; emcee's, a walker at a time, 5), which the estimate's
    :data:`sim.mc.workunits.BAYES_BYTES`, measured before, did not hold."""
    n = x.shape[0]
    y = x - x.mean()
    m = 1 << (2 * n - 1).bit_length()
    f = np.fft.rfft(y, n=m, axis=0)
    acf = np.fft.irfft(f * np.conj(f), n=m, axis=0)[:n].mean(axis=1)  # (n,)
    with np.errstate(invalid="ignore", divide="ignore"):  # a constant parameter: NaN
        acf = acf / acf[0]
    return _windowed(2.0 * np.cumsum(acf) - 1.0, c)


def _windowed(taus: np.ndarray, c: float) -> float:
    """tau at emcee's window, the smallest lag ``M >= c tau(M)``. Where no lag of the chain
    reaches it (a chain shorter than ``c`` tau), tau is at least ``n / c`` by the window's own
    rule: that bound, or the sum at the last lag if larger (emcee's ``auto_window`` then gives
    the first lag, tau = 1: the shortest chains would have passed any rule)."""
    reach = np.arange(len(taus)) >= c * taus
    if reach.any():
        return float(taus[np.argmax(reach)])
    return float(max(taus[-1], len(taus) / c)) if np.isfinite(taus[-1]) else float("nan")
