"""The cross-key rules of the ``network`` study kind (a user's network as data); its keys are
:mod:`sim.studies.network.keys` (``SCHEMA``, re-exported here).

Coordinates and distance sigmas in mm, angular sigmas in arcsec. The network itself
(``network.points``, ``grids``, ``random``, ``observations``, ``generate``) is a list of
tables, checked field by field by :func:`sim.studies.network.definition.build`; ``check``
also builds the datum and refuses a rank defect the datum does not cover, and a run whose
arrays would not fit in memory.
"""

from __future__ import annotations

import math

import numpy as np

from sim.mc.config import ConfigError, given
from sim.mc.progress import phase
from sim.mc.runner import PROBE_TRIALS, require_chunks
from sim.mc.schema_helpers import recorded_sha256
from sim.studies.network.analysis import (
    check_inner,
    estimated_points,
    held_defect,
    inner_left,
    inner_over_defect,
    match_points,
)
from sim.studies.network.built import built as build
from sim.studies.network.canonical import canonical
from sim.studies.network.compare import check_compare
from sim.studies.network.gama import gama_digest, merge_gama
from sim.studies.network.keys import SCHEMA
from sim.studies.network.model import datum, defect_basis, use_sparse
from sim.studies.network.probe import probe_solver
from sim.studies.network.rank_defect import refuse_defect
from sim.studies.network.rounding import check_rounding
from sim.studies.network.singular import (
    loose_part,
    singular_cause,
    unreached,
    unreached_message,
)
from sim.studies.network.sparse_analysis import (
    chunk_bytes,
    pre_analysis,
    shows_phases,
    shows_phases_of,
    variances,
)
from sim.studies.network.validate import fits_estimate
from sim.studies.network.weights import unknown

__all__ = ["SCHEMA", "check", "unread"]

#: bytes of one chunk's dense Jacobians above which a configuration is refused
MAX_CHUNK_BYTES = 2 * 1024**3


def _build(full: dict):
    """``build(full)``; a point or observation read from ``network.gama_xml`` that the network
    refuses is named by that key and the file, not by keys the study file does not hold."""
    try:
        return build(full)
    except ConfigError as e:
        gama = full.get("network.gama_xml")
        if not gama or not str(e.key or "").startswith(("network.points", "network.observations")):
            raise
        raise ConfigError("network.gama_xml", f"{gama}: {str(e)[len(e.key) + 2 :]}") from None


def _power(cfg: dict) -> None:
    """The w-test's power above its level: a two-sided test of level alpha0 rejects with a
    probability of at least alpha0 at any bias, so at a power no higher the minimal detectable
    bias is no bias (Baarda's delta0 = z(1 - alpha0/2) + z(power) went to zero and below: an
    MDB of -0.0023 mm was printed as a finding at alpha0 = 0.5, power = 0.05)."""
    a0, pw = cfg["reliability.alpha0"], cfg["reliability.power"]
    if pw <= a0:
        raise ConfigError(
            "reliability.power",
            f"{pw:g} is not above reliability.alpha0 = {a0:g}: a w-test of level {a0:g} rejects "
            f"with a probability of at least {a0:g} whatever the bias, so no bias is the "
            "smallest it detects with that power; give a power above the level",
        )


def check(cfg: dict) -> None:
    """Cross-key rules: the network builds (every observation well defined), its datum covers
    every rank defect and is not near-singular, something is estimated, the chunk fits in
    memory (on the sparse path for a large network), the run has the chunks its jackknife
    intervals need (:data:`sim.mc.runner.MIN_CHUNKS`) and
    ``output.inner_over`` can fix the defects. Records the sha256 of ``network.gama_xml`` in
    ``network.gama_sha256``, and writes the network's records in their one spelling
    (:func:`sim.studies.network.canonical.canonical`)."""
    require_chunks(cfg)  # estimates.py and tables.py: jackknife intervals over the chunks
    _power(cfg)
    _digest(cfg)
    fits_estimate(cfg)  # the run's memory, before the network is built and factorised
    full = merge_gama(cfg)
    cfg["datum.kind"] = full["datum.kind"]  # a free gama-local file's inner datum, resolved
    with phase("network: building", shows_phases_of(full)):
        net = _build(full)
    # the steps between the building and the run's bar, each shown on a terminal as its
    # neighbours are: a 10,370-unknown grid drew nothing for 3 s after its building, 1 s
    # before its factorising and 2 s after its pre-analysis (the records' and the datum's
    # checks, the solver probe's 16 trials: a loaded machine); a dense network nothing at all
    show = shows_phases(net.q) or net.m * (net.q + 1) >= DENSE_PHASE_FROM
    with phase("network: checking its records and observations", show):
        canonical(cfg)  # its records validated: one spelling, one config hash
        sparse = use_sparse(net)
        _chunk_fits(net, cfg, sparse)
        if not np.any(net.role != 1):
            raise ConfigError("network.points", "every point is fixed: nothing to estimate")
        _no_effect(net, full, cfg)
        lone = _unreached_free(net, full)
    with phase("network: the datum (its defects and constraints)", show):
        dt = datum(net, full)
        try:
            an = _held(
                net, full, dt, sparse, {k for k in ("datum.kind", "datum.points") if given(cfg, k)}
            )
        except ConfigError as e:  # a fixed point nothing observes holds nothing: the cause
            if not lone.size:
                raise
            key, where = _where(full, net.names[lone[0]])
            raise ConfigError(key, unreached_message(net, lone, where)) from e
    _conditioned(net, an, "datum.kind")
    pts = estimated_points(net, an)
    if not pts:
        raise ConfigError(
            "network.points", "no estimated point has a regular covariance: nothing to estimate"
        )
    if an.dof < 1:  # gama-local adjusts it (untested): its global test needs one or more
        gama = "; gama-local adjusts such a file untested" if full.get("network.gama_xml") else ""
        raise ConfigError(
            "network.observations",
            f"{net.m} observations for {len(an.free)} unknowns leave {an.dof} degrees of "
            f"freedom: add observations (the global test needs one or more{gama})",
        )
    with phase(f"network: the solver probe ({PROBE_TRIALS} trials of its own)", show):
        probe_solver(net, an, dt.constraint_matrix(net.theta_true()[None]), pts, cfg)
    if cfg["compare.fix"]:
        check_compare(net, full, cfg["compare.fix"], sparse)
    if cfg["output.inner_over"]:
        pts = match_points(net, "output.inner_over", cfg["output.inner_over"])
        inner_over_defect(net, an.free, pts, "output.inner_over")
        if all(net.role[p] == 1 for p in pts):  # their covariance is zero: S Q S' = Q
            raise ConfigError(
                "output.inner_over",
                f"{', '.join(net.names[p] for p in pts[:5])}{' ...' * (len(pts) > 5)} are all "
                "fixed points: the inner datum "
                "over them is the datum they hold (its table would repeat the points' sigmas "
                "as 'inner'): name estimated points among them, or leave it out",
            )


def _chunk_fits(net, cfg: dict, sparse: bool) -> None:
    """Refuse a chunk over :data:`MAX_CHUNK_BYTES` (``chunk``; ``network`` when one trial is)."""
    nbytes = chunk_bytes(net, cfg["chunk"]) if sparse else cfg["chunk"] * net.m * (net.q + 1) * 8
    if nbytes > MAX_CHUNK_BYTES:
        one = chunk_bytes(net, 1) if sparse else net.m * (net.q + 1) * 8
        raise ConfigError(
            "chunk" if one <= MAX_CHUNK_BYTES else "network",
            f"a chunk of {cfg['chunk']} trials needs about "
            f"{nbytes / 1024**3:.1f} GiB ({net.m} observations x "
            f"{net.q} unknowns{', sparse' if sparse else ''}); "
            + (
                "use a smaller chunk"
                if one <= MAX_CHUNK_BYTES
                else f"a chunk of one trial too ({one / 1024**3:.1f} GiB, over "
                f"{MAX_CHUNK_BYTES / 1024**3:g} GiB): use fewer points or observations"
            ),
        )


#: Jacobian entries (observations x unknowns) from which a dense network shows the steps
#: before its run (:func:`sim.mc.progress.phase`): 5,000 distances of 100 points (1e6
#: entries) took 22 s in the solver probe on a loaded two-core machine (2.5 s the rest of
#: ``sim check``), 870 of 30 points 2 s
DENSE_PHASE_FROM = 1_000_000


def _where(full: dict, name: str = "") -> tuple[str, str]:
    """The key and the words that say where the network's points (the point ``name``) are
    declared: a grid's or random set's points were named ``network.points``, where the
    study file lists none of them."""
    gama = full.get("network.gama_xml")
    if gama:
        return "network.gama_xml", gama
    listed = {str(p.get("name")) for p in full.get("network.points") or [] if isinstance(p, dict)}
    for key, count in (("network.grids", ("nx", "ny")), ("network.random", ("n",))):
        for a, rec in enumerate(full.get(key) or []):
            tail = name[len(str(rec.get("prefix"))) :]
            digits = tail.isascii() and tail.isdigit() and tail[0] != "0"
            if name not in listed and name.startswith(str(rec.get("prefix"))) and digits:
                if int(tail) <= int(np.prod([int(rec.get(f, 1)) for f in count])):
                    return f"{key}[{a}]", "the study file"
    return "network.points", "the study file"


def _unreached_free(net, full: dict) -> np.ndarray:
    """Refuse a free point that no observation reaches (its position cannot be estimated,
    whatever the datum); return the fixed ones, which hold nothing in place (they only matter
    when the datum then leaves a defect: gama-local files often list unused control points)."""
    lone = unreached(net)
    free = lone[net.role[lone] != 1]
    if free.size:
        key, where = _where(full, net.names[free[0]])
        raise ConfigError(key, unreached_message(net, free, where))
    return lone


def _held(net, full: dict, dt, sparse: bool, asked: frozenset | set = frozenset()):
    """The pre-analysis of a network its datum holds: the datum's own checks (minimal
    constraints, inner-datum points), then the normals; a defect is refused naming its cause
    where it can be found. ``asked``: the datum keys set (the file, ``--set``, a sweep cell),
    not resolved from a ``gama-local`` file's ``adj="XY"`` points."""
    if full["datum.kind"] == "constraints":
        _minimal(net, dt, full)
    if full["datum.kind"] == "inner":
        # the defect the datum leaves (one fixed point: the rotation about it), not every
        # defect of the network with no point held
        H = held_defect(net, dt.free_index(net.q))
        pts = match_points(net, "datum.points", full["datum.points"] or ["*"])
        check_inner(net, H, pts, "datum.points")
    an = pre_analysis(net, dt, full["reliability.alpha0"], full["reliability.power"])
    # a gama-local file too: its adj="XY" points resolve the datum inner only where fewer than
    # two points are held (gama.py), which leaves a defect; an inner datum asked of a file its
    # fixed points or weighted coordinates hold ran the fixed datum, said as `inner` (0
    # constraints)
    gama = bool(full.get("network.gama_xml"))
    if an.ok and full["datum.kind"] == "inner":
        # after the normals: a part turning about its own fixed point, an unknown no
        # observation reaches, is a defect the fixed points leave too (named below when
        # singular); the file's adj="XY" points are not a datum.points the user set
        points = "datum.points" in asked if gama else bool(full["datum.points"])
        inner_left(net, H, "datum.points" if points else "datum.kind")
    if not an.ok:
        # dense too: name the point no observation reaches (docs/network.md), unless nothing
        # holds the network at all (then the rank defect and its advice say it better)
        held = sparse or full["datum.kind"] != "fixed" or np.any(net.role != 0)
        free = dt.free_index(net.q)
        cause = singular_cause(net, full, free) if held else ""
        # an unknown no observation reaches, or a part tied to the datum by none: no datum
        # holds it (inner or constraints cover only the network's own defect), so the advice
        # names what does ("or change the datum" gave the same refusal again)
        fix = "fix points or add observations" if cause else "fix points or change the datum"
        if sparse and not cause:
            cause = _pivot(net, an.factor, free)
        if sparse or cause:
            what = an.factor.message if sparse else "the normal matrix is singular"
            raise ConfigError("datum.kind", f"{what}{': ' + cause if cause else ''}: {fix}")
        # explicit constraints that leave a defect (one of coefficient 1e-300, say) are theirs
        kind = full["datum.kind"]
        refuse_defect(net, dt, "datum.constraints" if kind == "constraints" else "datum.kind", kind)
    check_rounding(net, an.cov, estimated_points(net, an))
    return an


#: keys of the distances alone (their true constant, offset and scale, and whether to estimate
#: the constant and the scale): set in a network without a distance, they are read by nothing
DISTANCE_KEYS = (
    "network.constant_mm",
    "network.offset_mm",
    "network.scale_ppm",
    "network.estimate_constant",
    "network.estimate_scale",
)


def _no_effect(net, cfg: dict, asked: dict) -> None:
    """Keys that would do nothing, or be blamed on the datum: an additive constant or scale to
    estimate without a distance,
    and any key of the distances that ``asked`` (the configuration as the user set it:
    :func:`sim.mc.config.given`) sets in a network without one (the network's condition of
    :mod:`sim.mc.read_when`: it depends on the observations, not on a switch)."""
    if np.any(net.kind == 0):
        return
    for what, key in (("constant", "estimate_constant"), ("scale error", "estimate_scale")):
        if cfg[f"network.{key}"]:
            raise ConfigError(
                f"network.{key}",
                f"the {what} of the distances cannot be estimated: the network has no distances",
            )
    for key in DISTANCE_KEYS:
        if given(asked, key):
            raise ConfigError(key, f"is not read: {NO_DISTANCES}")


#: why the keys of the distances are not read in a network without one
NO_DISTANCES = "it applies to distances and the network has none"


def unread(cfg: dict) -> dict[str, str]:
    """The keys of the distances, in a network without one (:attr:`sim.studies.Study.unread`:
    ``sim check`` lists them commented out); ``{}`` otherwise."""
    net = _build(merge_gama(cfg))
    return {} if np.any(net.kind == 0) else dict.fromkeys(DISTANCE_KEYS, NO_DISTANCES)


def _minimal(net, dt, full: dict) -> None:
    """``datum.constraints`` are minimal: no more of them than the network's datum defects
    (a further one would hold an estimable quantity and bend the network). A part of the
    network tied to nothing has a defect of its own, which they do not hold: it is named
    (it was "a datum defect of 0", of a network whose fixed points hold its datum)."""
    c = dt.n_constraints()
    d = defect_basis(net, dt.free_index(net.q)).shape[1]
    loose = loose_part(net, full) if c > d == 0 else ""
    if loose and d == 0:  # (with a defect to hold, c > d is the count, named below)
        raise ConfigError(
            "datum.constraints",
            f"{loose}; the fixed points hold the rest (a datum defect of 0) and minimal "
            "constraints cannot hold such a part: add observations that tie it to the rest, "
            'or fix two of its points, and use datum.kind = "fixed" without constraints',
        )
    if c > d:
        raise ConfigError(
            "datum.constraints",
            f"{c} constraints for a datum defect of {d}: minimal constraints are as many as "
            "the defect (the others would bend the network)",
        )


def _digest(cfg: dict) -> None:
    path = cfg["network.gama_xml"]
    have = recorded_sha256("network.gama_sha256", cfg["network.gama_sha256"])
    if not path:
        if have:
            raise ConfigError("network.gama_sha256", "only with network.gama_xml")
        return
    sha = gama_digest(path)
    if have and have != sha:
        raise ConfigError(
            "network.gama_sha256",
            f"{path} has changed (sha256 {sha[:12]}..., recorded {have[:12]}...)",
        )
    cfg["network.gama_sha256"] = sha


#: largest variance inflation Q_ii N_ii of an unknown before the network counts as singular
MAX_INFLATION = 1e10


def _conditioned(net, an, key: str) -> None:
    """Refuse a near-singular network (e.g. free points on the line through two fixed
    points): an unknown whose variance is over :data:`MAX_INFLATION` times what its own
    observations alone would give loses more than ten of the sixteen digits."""
    n_ii = an.n_diag
    q_ii = variances(an, np.arange(len(an.free)))  # the dense diagonal or the selected one
    span = float(np.ptp(net.xy, axis=0).max())
    coord = an.free < 2 * net.n
    loose = np.flatnonzero(coord & (np.sqrt(np.maximum(q_ii, 0)) > span))
    if loose.size:
        par = int(an.free[loose[0]])
        raise ConfigError(
            key,
            f"the network is near-singular: point {net.names[par // 2]!r} "
            f"({'xy'[par % 2]}) has a sigma of {math.sqrt(q_ii[loose[0]]):.3g} mm, more than "
            f"the network's extent ({span:.3g} mm); points nearly on one line, or nearly "
            "undetermined",
        )
    vif = q_ii * n_ii
    if not np.all(np.isfinite(vif)) or vif.max() > MAX_INFLATION:
        g = int(np.argmax(np.where(np.isfinite(vif), vif, np.inf)))
        what = unknown(net, int(an.free[g]))
        raise ConfigError(
            key,
            f"the network is near-singular: {what} is determined {vif[g]:.3g} times worse "
            f"than its observations alone would give (limit {MAX_INFLATION:g}); points "
            "nearly on one line, or nearly undetermined",
        )


def _pivot(net, factor, free: np.ndarray) -> str:
    """The unknown at the sparse factor's failed pivot (:attr:`sim.lsq.sparse.Factor.weak`),
    named as the dense path names its weakest one; "" when the factor names none."""
    if factor is None or factor.weak < 0:
        return ""
    return (
        f"{unknown(net, int(free[factor.weak]))} is nearly undetermined (the smallest pivot "
        "of the normals falls on it; points nearly on one line, or too few observations)"
    )
