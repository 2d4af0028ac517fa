"""Helper left9: a network's work estimate counts what the run does, and a large network shows
its setup steps.

The estimate (:mod:`sim.mc.network_size`) counted one unit adjustment a trial on the dense
path and one factor's worth of slot pairs on the sparse one, calibrated on grid plates that
converge in one step: the sweep doors24b measured a 50,176-point trilateration grid (200
trials) at about 8 times its estimate of 1.65e5 and the test field's 100,000 trials at 4
times theirs. It now counts a trial's Gauss-Newton iterations (the run records them, here
compared as counts) and on the sparse path each iteration's solve with the factor, whose
nonzeros it estimates from the normals' (compared with the factor the run holds). No timing
is asserted: the two measured CPU figures below are constants of the sweep's runs.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest

from sim.lsq import distributions as D
from sim.mc import network_size, progress
from sim.mc.estimate import check_limits, estimate
from sim.mc.workunits import ADJUSTMENT_S
from sim.studies import load_study
from sim.studies.network import sparse_analysis
from sim.studies.network.analysis import estimated_points, mc_chunk
from sim.studies.network.definition import build
from sim.studies.network.model import datum, use_sparse
from sim.studies.network.sparse_analysis import analyse_sparse, factor, mc_chunk_sparse
from sim.studies.network.tables import parameter_indices

ROOT = Path(__file__).resolve().parents[1]

TRI = 'generate = [ { kind = "distance", from = "P*", to = "P*", nearest = 8, sigma_mm = 2.0 } ]'
TT = (
    'generate = [ { kind = "distance", from = "P*", to = "P*", nearest = 6, sigma_mm = 2.0 },\n'
    '  { kind = "direction", from = "P*", to = "P*", nearest = 6, sigma_arcsec = 1.0 } ]'
)
PLATE = (
    'generate = [ { kind = "dx", from = "P*", to = "P*", nearest = 4, sigma_mm = 0.002 },\n'
    '  { kind = "dy", from = "P*", to = "P*", nearest = 4, sigma_mm = 0.002 } ]'
)


def _net(tmp_path, side: int, gen: str, trials: int = 40, chunk: int = 2) -> dict:
    """A side x side grid 100 m apart with the generated observations ``gen``: a field in an
    inner datum, or (coordinate differences) a plate of observed points."""
    plate = "dx" in gen
    role = ', role = "observed", sigma_mm = 0.0012' if plate else ""
    sp = "spacing_mm = 10.0" if plate else "spacing_m = 100.0"
    f = tmp_path / "n.toml"
    f.write_text(
        f'study = "network"\ntrials = {trials}\nchunk = {chunk}\nseed = 3\n[network]\n'
        f'grids = [ {{ prefix = "P", nx = {side}, ny = {side}, {sp}{role} }} ]\n{gen}\n'
        + ('[datum]\nkind = "fixed"\n' if plate else '[datum]\nkind = "inner"\n')
    )
    return load_study(f)[1]


def _iterations(cfg: dict, n: int = 8) -> np.ndarray:
    """The iterations the run records (``rows.iterations``) for ``n`` trials of ``cfg``."""
    net = build(cfg)
    dt = datum(net, cfg)
    an = sparse_analysis.pre_analysis(net, dt, 0.001, 0.8)
    pts = estimated_points(net, an)
    common = dict(
        net=net,
        free=an.free,
        cov_inv=np.linalg.inv(an.cov[pts]),
        pts=np.asarray(pts),
        crit=float(D.chi2_ppf(0.95, an.dof)),
        tol=cfg["solver.tol_mm"],
        max_iter=cfg["solver.max_iter"],
        par=parameter_indices(net, an),
    )
    rng = np.random.default_rng(11)
    if use_sparse(net):
        out = mc_chunk_sparse(rng, n, fac=an.factor, dof=an.dof, **common)
    else:
        C = dt.constraint_matrix(net.theta_true()[None])
        out = mc_chunk(rng, n, C=None if C is None else C[0], **common)
    return np.asarray(out["rows.iterations"])


@pytest.mark.parametrize(
    "case",
    ["trilateration", "triangulation", "plate", "network_testfield", "network_plate"],
)
def test_the_estimate_counts_the_iterations_the_run_records(tmp_path, case):
    """The iterations the estimate counts a trial bound those the run records, and are not a
    multiple of them (at most one more): non-linear kinds take 3 on the sparse path (one
    factor of the nominal normals for every step), where the estimate counted 1."""
    if case.startswith("network_"):
        cfg = load_study(ROOT / "studies" / f"{case}.toml")[1]
    else:
        gen = {"trilateration": TRI, "triangulation": TT, "plate": PLATE}[case]
        cfg = _net(tmp_path, 16, gen)
    k = network_size.network_counts(cfg)
    assert k.sparse == use_sparse(build(cfg))  # the estimate takes the run's path
    its = _iterations(cfg)
    assert its.max() <= k.iterations and its.mean() >= k.iterations - 1, (its, k.iterations)


@pytest.mark.parametrize("gen", [TRI, TT, PLATE], ids=["tri", "tri-tri", "plate"])
def test_the_estimated_factor_bounds_the_factor_the_run_holds(tmp_path, gen):
    """The sparse factor's nonzeros counted from the declaration (no network built) against
    the factor's: never below it, at most 3 times it."""
    cfg = _net(tmp_path, 24, gen)
    net = build(cfg)
    real = factor(net, datum(net, cfg)).nnz
    k = network_size.network_counts(cfg)
    assert k.sparse and abs(k.unknowns - net.q) <= 0.01 * net.q
    assert real <= k.factor_nnz <= 3 * real, k.factor_nnz / real


def test_the_sweeps_runs_fall_within_their_estimates(tmp_path):
    """Two runs measured (CPU, one core, single-threaded BLAS as sim runs): the 224 x 224
    trilateration grid, 88 s for 40 trials in chunks of 2 (check, build, factor and
    pre-analysis, 0.2 s a trial, tables, figures and export), so about 120 s at 200 trials,
    and the test field's 100,000 trials in 44 s (doors24b), now within [1/1.5, 3] times their
    estimates (the estimate was 8 and 4 times low)."""
    big = _net(tmp_path, 16, TRI, trials=200, chunk=4)  # checked at 16 x 16 (a second)
    big["network.grids"] = [{**big["network.grids"][0], "nx": 224, "ny": 224}]
    tf = load_study(ROOT / "studies" / "network_testfield.toml", ["trials=100000"])[1]
    for cfg, seconds in ((big, 88 + 160 * 0.2), (tf, 44.0)):
        est = estimate(cfg).adjustments * ADJUSTMENT_S
        assert seconds / 1.5 <= est <= 3 * seconds, (est, seconds)
        check_limits(estimate(cfg))  # neither is refused at the default limit


def test_shipped_network_studies_are_not_refused():
    for f in sorted((ROOT / "studies").glob("network*.toml")):
        check_limits(estimate(load_study(f)[1]))


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_a_phase_shows_on_a_terminal_and_is_erased(monkeypatch):
    monkeypatch.delenv("TERM", raising=False)
    s = _Tty()
    with progress.phase("network: tables", True, quiet=False, stream=s):
        assert s.getvalue().endswith("\x1b[Knetwork: tables ...")
        with progress.phase("network: factorising", True, quiet=False, stream=s):
            assert s.getvalue().endswith("\x1b[Knetwork: factorising ...")
        assert s.getvalue().endswith("\x1b[Knetwork: tables ...")  # the outer step again
    assert s.getvalue().endswith("\r\x1b[K")
    for kw in ({"quiet": True}, {"show": False, "quiet": False}):  # --quiet; a small network
        s = _Tty()
        with progress.phase("x", **{"show": True, **kw}, stream=s):
            pass
        assert s.getvalue() == "", kw
    s = io.StringIO()  # not a terminal (a log, a pipe)
    with progress.phase("x", True, quiet=False, stream=s):
        pass
    assert s.getvalue() == ""


def test_a_large_networks_pre_analysis_shows_its_steps_unless_quiet(tmp_path, monkeypatch):
    monkeypatch.delenv("TERM", raising=False)
    cfg = _net(tmp_path, 12, TRI)
    net = build(cfg)
    monkeypatch.setattr(sparse_analysis, "PHASE_FROM_UNKNOWNS", net.q)  # large enough
    for quiet, want in ((False, True), (True, False)):
        s = _Tty()
        monkeypatch.setattr("sys.stderr", s)
        progress.set_quiet(quiet)
        try:
            analyse_sparse(net, datum(net, cfg), 0.001, 0.8)
        finally:
            progress.set_quiet(False)
        shown = s.getvalue()
        assert ("factorising the normals" in shown and "pre-analysis" in shown) == want, shown
    monkeypatch.setattr(sparse_analysis, "PHASE_FROM_UNKNOWNS", net.q + 1)  # a small one
    s = _Tty()
    monkeypatch.setattr("sys.stderr", s)
    analyse_sparse(net, datum(net, cfg), 0.001, 0.8)
    assert s.getvalue() == ""
