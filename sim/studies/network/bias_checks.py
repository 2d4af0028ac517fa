"""Whether a network's observation biases leave its Monte-Carlo self-checks a reference.

The coverage of the analytic 95 % ellipses, the global test's false-alarm rate and the
Monte-Carlo spread against the analytic covariance are self-checks of unbiased readings: a
bias the adjustment does not know (``bias_mm``, ``bias_arcsec``) and does not absorb shifts
the adjusted points (the coverage falls towards 0), leaves residuals (the test rejects
towards every trial) and, through the residuals times the observations' curvature, widens
the spread. On the README's network with ``bias_mm = 10`` on its distances the coverage was
0.0 and the false-alarm rate 1.0, counted "self-check failed": they measured the bias, not
the simulation. A bias the adjustment absorbs (a constant on one set's directions, in its
orientation; on every distance, with ``network.estimate_constant``) changes none of them.

The rule: the noise-free biased readings are adjusted once (the run's own chunk function,
with the noise drawn as zeros). Their weighted residual sum of squares ``v'Pv`` is the global
test's noncentrality and each estimated point's ``e' C^-1 e`` (its shift against its
analytic covariance) its ellipse's; where either exceeds :data:`NEGLIGIBLE` (a shift of 0.01
sigma) the three checks are **not applicable** (their value and their outcome against the
nominal reference are kept in the note, and they are counted apart, not as failed).
"""

from __future__ import annotations

import numpy as np

from sim.studies.network.analysis import estimated_points
from sim.studies.network.built import built as build
from sim.studies.network.definition import Network
from sim.studies.network.gama import merge_gama
from sim.studies.network.linearity import largest_bias, row_key
from sim.studies.network.model import datum
from sim.studies.network.probe import chunk_fn
from sim.studies.network.sparse_analysis import pre_analysis

__all__ = ["NEGLIGIBLE", "BIASED_CHECKS", "bias_effect", "bias_notes"]

#: the noncentrality (in sigma squared) below which a bias is absorbed: 0.01 sigma, which
#: moves the false-alarm rate and the coverage by well under a thousandth
NEGLIGIBLE = 1e-4
#: the self-checks whose reference assumes unbiased readings
BIASED_CHECKS = (
    "network.mc_agreement.mean_ratio",
    "network.coverage95.mean",
    "network.global_test.false_alarm",
)


class _NoNoise:
    """A stand-in generator whose normal draws are zeros: the noise-free readings."""

    def standard_normal(self, shape):
        return np.zeros(shape)


def _named(net: Network, cfg: dict) -> str:
    """The largest bias (in its sigmas) as ``key: the distance at 'A' to 'P' (10 mm)``."""
    r, unit, f, obs = largest_bias(net)
    n = int(np.count_nonzero(net.bias))
    more = f" and {n - 1} other biased observation{'s' if n > 2 else ''}" if n > 1 else ""
    return f"{row_key(cfg, r)} (bias_{unit} = {net.bias[r] * f:g} on {obs}{more})"


def bias_effect(net: Network, an, C, pts, cfg: dict) -> str | None:
    """Why the three :data:`BIASED_CHECKS` are not applicable to ``net`` (the adjustment
    does not absorb its biases; the note's start, the rule's outcome follows), or None (no
    bias, or every bias absorbed)."""
    why = _unabsorbed(net, an, C, pts, cfg)
    if why is None:
        return None
    return (
        f"not applicable: {why}: the check measures the bias, not the simulation; against its "
        "nominal reference the rule gives: "
    )


def _unabsorbed(net: Network, an, C, pts, cfg: dict) -> str | None:
    """What the biases of ``net`` the adjustment does not absorb do to the noise-free readings
    (the bias named, the noncentrality, the largest shift), or None (none, or all absorbed)."""
    if not np.any(net.bias):
        return None
    out = chunk_fn(net, an, C, pts, cfg)(_NoNoise(), 1)
    if not out["rows.converged"][0]:
        lam, shift = np.inf, np.inf
    else:
        s0 = float(out["rows.sigma0"][0])
        lam = s0 * s0 * an.dof if an.dof > 0 else 0.0
        e = out["sum.e"][0]  # (k, 2): the noise-free shifts of the estimated points
        cinv = np.linalg.inv(an.cov[pts])
        shift = float(np.max(np.einsum("ki,kij,kj->k", e, cinv, e), initial=0.0))
    if lam <= NEGLIGIBLE and shift <= NEGLIGIBLE:
        return None
    return (
        f"the bias of {_named(net, cfg)}, unknown to the adjustment, leaves "
        f"residuals of weighted square sum {lam:.4g} (the global test's noncentrality) and "
        f"shifts a point by {np.sqrt(shift):.4g} sigma of its ellipse (noise-free readings)"
    )


def bias_notes(cfg: dict) -> list[str]:
    """What ``sim check`` says before the run of a network whose biases the adjustment will
    not absorb: its three self-checks will be not applicable (N45: said only in the results).
    The network is built and pre-analysed as the run does it; nothing when no bias is set."""
    full = merge_gama(cfg)
    net = build(full)
    if not np.any(net.bias):
        return []
    dt = datum(net, full)
    an = pre_analysis(net, dt, cfg["reliability.alpha0"], cfg["reliability.power"])
    if not an.ok:  # (refused by the study's check before this is asked)
        return []
    pts = estimated_points(net, an)
    why = _unabsorbed(net, an, dt.constraint_matrix(net.theta_true()[None]), pts, cfg)
    if why is None:
        return []
    return [
        f"the self-checks {', '.join(BIASED_CHECKS)} will be not applicable (counted apart, not "
        f"as failed): {why}, which they would measure instead of the simulation"
    ]
