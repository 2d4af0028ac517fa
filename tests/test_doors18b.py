"""The classes of the sweep doors18b (issue 26: valid but extreme designs, accepted and run
with exit 0: is every output true?), one case each; each failed on the code before its fix.

* a share whose every trial passed (k = n) got the Wilson interval [0.912, 1 - 1e-16]: an
  interval that misses its own value 1.0 (committed in ``gridplate_two_plates``'s
  ``twoplate.weight_ratio.pass_after_reweighting``; at 20 trials in four coverage rows);
  at k = 0 and k = n the bound is exactly 0 and 1 (:func:`sim.claims.intervals.binomial_ci`,
  :func:`sim.lsq.distributions.wilson_ci`);
"""

from __future__ import annotations

import numpy as np

from sim.claims.intervals import binomial_ci
from sim.lsq.distributions import wilson_ci


def test_wilson_interval_holds_its_value_at_all_and_none():
    n = np.arange(1, 400)
    for k in (np.zeros_like(n), n):
        p, lo, hi = binomial_ci(k, n)
        assert np.all((lo <= p) & (p <= hi)), n[(lo > p) | (p > hi)][:5]
        assert np.all(lo[k == 0] == 0.0) and np.all(hi[k == n] == 1.0)
    for m in range(1, 400):
        assert wilson_ci(m, m) == (wilson_ci(m, m)[0], 1.0) and wilson_ci(0, m)[0] == 0.0
    # inside the counts nothing changes: the interval strictly inside (0, 1)
    p, lo, hi = binomial_ci(np.array([3]), np.array([40]))
    assert 0 < lo[0] < p[0] < hi[0] < 1
