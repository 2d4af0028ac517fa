"""Scaling rows of the benchmark (``scaling.parquet``, ``scaling.png``): how the sparse path's
cost grows with the size of the problem (issue 23).

* ``network``: trilateration grids (distances to the 8 nearest, inner datum) and
  triangulation grids (directions to the 8 nearest, one orientation per station, two corner
  points fixed) of 10 x 10 to 100 x 100 points on the network kind's sparse path
  (:mod:`sim.studies.network.sparse_analysis`): the analytic pre-analysis (factor, per-point
  sigma and ellipses, redundancy numbers, MDB), one Monte-Carlo chunk (time per trial), the
  peak memory of the process, and GNU Gama's ``gama-local`` (``$GAMA_LOCAL``, else
  ``/tmp/gama-build/gama-local`` if it exists) on the same network (its XML export, the
  sparse envelope solver ``--algorithm envelope``, text output with per-point precision, at
  most 300 s) with the ratio of its time to the analytic one. gama-local runs on a regular
  datum: the triangulation's two fixed corners, and for the trilateration (an inner datum
  here) the two corners of its first row fixed -- on a free network gama-local computes
  every cofactor it prints by a solve of its own (quadratic in the points: 400 points took
  25 s, 2,500 did not finish in 10 minutes). Version 2.03 also builds the dense design
  matrix (observations x unknowns) whatever the algorithm, so a network whose dense design
  exceeds :data:`GAMA_MAX_DESIGN_GIB` is not given to it (``gama_note`` says why).
* ``gridplate``: seed ``001``'s combined adjustment of one comparator coordinate
  (:func:`sim.instruments.gridplate.combined_adjustment`) on plates of 10 x 10 to 200 x 200
  points: the adjustment with the cofactors of one trial (analytic) and its time per trial.
  Its point blocks are eliminated first (the arrow-shaped normals' sparse factor, no fill).
* ``block``: the independent-model block (seed ``003``) of 10 to 200 models
  (:func:`sim.instruments.block.independent_models.adjust_block`, the sparse ``L D L'`` of
  :mod:`sim.lsq.sparse_batch` from 58 models): the cofactors of one trial (analytic) and the
  adjustment's time per trial.

Every size runs in a fresh process (``python -m benchmarks.scaling --child ...``), so the
peak memory (``VmHWM``) is that size's own. The slope of log time against log size (points;
models for blocks) is fitted over each kind's sizes (the target: at most 1.5 for the
Monte-Carlo time per trial). Times are wall clock of single-threaded work on a machine that
may be shared: they are what this run saw, not a constant; ``load_1min`` is the machine's
load average when the row was measured.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.brown import peak_rss_mib
from sim.instruments import gridplate as gp
from sim.instruments.block import independent_models as im
from sim.instruments.block.layout import make_block, select_control
from sim.instruments.plates import grid_points
from sim.lsq import distributions as D
from sim.mc.children import ended
from sim.mc.config import validate
from sim.report.plotting import plt, save
from sim.studies.network.definition import build
from sim.studies.network.gama import write_gama
from sim.studies.network.model import datum
from sim.studies.network.schema import SCHEMA
from sim.studies.network.sparse_analysis import analyse_sparse, mc_chunk_sparse

__all__ = ["scaling_rows", "scaling_figure", "gama_local", "TARGET_SLOPE"]

#: the issue's targets: time per trial growing no faster than points^1.5; the analytic
#: pre-analysis of 10,000 points under 10 s; 1,000 trials of 2,500 points under 60 s
TARGET_SLOPE = 1.5
TARGET_ANALYTIC_10K_S = 10.0
TARGET_MC_2500_S = 60.0
SIDES = (10, 20, 30, 50, 100)
QUICK_SIDES = (10, 20)
MODELS = ((2, 5), (2, 10), (4, 13), (4, 25), (8, 25))  # strips x models: 10 ... 200
QUICK_MODELS = ((2, 5), (2, 10))
PLATES = (10, 20, 50, 100, 200)  # grid plate sides: 100 ... 40,000 points
QUICK_PLATES = (10, 20)
#: gama-local 2.03 builds the dense design matrix: networks whose dense design is larger are
#: not given to it (10,000 points: 80,000 distances x 20,000 unknowns, 12 GiB)
GAMA_MAX_DESIGN_GIB = 2.0
GAMA_TIMEOUT_S = 300


def gama_local() -> str | None:
    """Path of a ``gama-local`` executable, or None."""
    p = os.environ.get("GAMA_LOCAL") or "/tmp/gama-build/gama-local"
    return p if os.path.isfile(p) and os.access(p, os.X_OK) else None


def _network_cfg(kind: str, side: int) -> dict:
    obs = (
        {"kind": "distance", "from": "P*", "to": "P*", "nearest": 8, "sigma_mm": 1.0}
        if kind == "trilateration"
        else {"kind": "direction", "from": "P*", "to": "P*", "nearest": 8, "sigma_arcsec": 1.0}
    )
    raw = {
        "trials": 40,
        "chunk": 20,
        "network.grids": [{"prefix": "P", "nx": side, "ny": side, "spacing_mm": 100000.0}],
        "network.generate": [obs],
        "datum.kind": "inner",
    }
    if kind == "triangulation":  # position, rotation and scale from two fixed corners
        raw["network.grids"][0]["origin_mm"] = [0.0, 0.0]
        raw["network.points"] = [
            {"name": "A", "x_mm": -1e5, "y_mm": -1e5, "role": "fixed"},
            {"name": "B", "x_mm": 1e5 * side, "y_mm": -1e5, "role": "fixed"},
        ]
        raw["network.generate"] = [
            obs,
            {"kind": "distance", "from": ["A", "B"], "to": "P*", "nearest": 3, "sigma_mm": 1.0},
        ]
        raw["datum.kind"] = "fixed"
    return validate(raw, SCHEMA)


def _child_network(kind: str, side: int, trials: int, gama: str | None) -> dict:
    cfg = _network_cfg(kind, side)
    # compile the kernels first (numba caches them; the first process of a machine compiles)
    small = build(_network_cfg(kind, 4))
    a0 = analyse_sparse(small, datum(small, _network_cfg(kind, 4)), 0.001, 0.8)
    p0 = np.flatnonzero(small.role != 1)
    inv0 = np.linalg.inv(a0.cov[p0])
    mc_chunk_sparse(
        np.random.default_rng(1), 2, small, a0.free, a0.factor, inv0, p0, 1.0, 1e-9, 20, a0.dof
    )
    t0 = time.perf_counter()
    net = build(cfg)
    an = analyse_sparse(net, datum(net, cfg), 0.001, 0.8)
    t_an = time.perf_counter() - t0
    pts = np.flatnonzero(net.role != 1)
    crit = float(D.chi2_ppf(0.95, an.dof))
    cov_inv = np.linalg.inv(an.cov[pts])
    t1 = time.perf_counter()
    out = mc_chunk_sparse(
        np.random.default_rng(1),
        trials,
        net,
        an.free,
        an.factor,
        cov_inv,
        pts,
        crit,
        1e-9,
        20,
        an.dof,
    )
    t_mc = (time.perf_counter() - t1) / trials
    row = {
        "points": net.n,
        "observations": net.m,
        "unknowns": len(an.free),
        "factor_nonzeros": an.factor.nnz,
        "analytic_s": t_an,
        "mc_s_per_trial": t_mc,
        "converged": float(out["sum.n"][0, 0]) / trials,
        "peak_mib": peak_rss_mib(),
        "redundancy_sum_minus_dof": float(an.redundancy.sum() - an.dof),
        "gama_s": float("nan"),
    }
    row["gama_note"] = _gama(gama, net, side, row) if gama else "no gama-local"
    return row


def _gama_xml(net, side: int, path: Path) -> None:
    """The network's gama-local input on a regular datum: fixed points stay fixed; a network
    without any gets the two corners of its first row fixed (``P1``, ``P<side>``)."""
    write_gama(net, path)
    # gama-local 2.03 reads no angles="400" on <network>
    txt = path.read_text().replace(' angles="400"', "").replace('adj="XY"', 'adj="xy"')
    if 'fix="xy"' not in txt:
        for name in ("P1", f"P{side}"):
            txt = re.sub(rf'(<point id="{name}"[^>]*?)adj="xy"', r'\1fix="xy"', txt)
    path.write_text(txt)


def _gama(gama: str, net, side: int, row: dict) -> str:
    """Time gama-local on ``net`` into ``row["gama_s"]``; returns a note (empty: measured)."""
    gib = net.m * row["unknowns"] * 8 / 2**30
    if gib > GAMA_MAX_DESIGN_GIB:
        return f"not run: gama-local 2.03's dense design would take {gib:.0f} GiB"
    with tempfile.TemporaryDirectory(prefix="sim-scaling-") as d:
        xml = Path(d) / "net.xml"
        _gama_xml(net, side, xml)
        t2 = time.perf_counter()
        try:
            r = subprocess.run(
                [gama, str(xml), "--algorithm", "envelope", "--text", str(Path(d) / "o.txt")],
                capture_output=True,
                timeout=GAMA_TIMEOUT_S,
            )
        except subprocess.TimeoutExpired:  # recorded as not measured (NaN)
            return f"not measured: over {GAMA_TIMEOUT_S} s"
        if r.returncode != 0:
            return f"not measured: gama-local {ended(r.returncode)}"
        row["gama_s"] = time.perf_counter() - t2
    return ""


def _child_gridplate(side: int, trials: int) -> dict:
    """Seed 001's combined adjustment (weighted grid, one comparator coordinate) of a
    ``side`` x ``side`` plate: 10 mm pitch, 1 um readings, 2 um certificate."""

    def case(k, T):
        rng = np.random.default_rng(7)
        G = grid_points(k, 10.0)
        grid = G + rng.normal(0.0, 0.002, (T,) + G.shape)
        comp = 1.00001 * G[:, 0] + 2e-5 * G[:, 1] + 120.0 + rng.normal(0.0, 0.001, (T, k * k))
        return lambda: gp.combined_adjustment(comp, grid, 1.0, 0.25)

    case(3, 2)()  # compile
    adjust = case(side, trials)
    t0 = time.perf_counter()
    res = adjust()
    t_mc = (time.perf_counter() - t0) / trials
    one = case(side, 1)
    t1 = time.perf_counter()
    r1 = one()
    t_an = time.perf_counter() - t1
    return {
        "points": side * side,
        "models": 0,
        "observations": 3 * side * side,
        "unknowns": 2 * side * side + 3,
        "analytic_s": t_an,
        "mc_s_per_trial": t_mc,
        "converged": float(np.all(np.isfinite(res.params)) and np.isfinite(r1.cofactor).all()),
        "peak_mib": peak_rss_mib(),
    }


def _child_block(strips: int, models: int, trials: int) -> dict:
    def case(S, Mo, T):
        rng = np.random.default_rng(5)
        b = make_block(S, Mo, n_ground=11 * S * Mo, pass_rows=3)
        xm, _ = im.noisy_models(b, rng, T, 0.05)
        ctrl = select_control(b, "perimeter")
        st = im.BlockStructure(b.obs_model, b.obs_point, ctrl, b.n_models, b.n_points)
        X0 = b.points + rng.normal(0, 2.0, (T,) + b.points.shape)
        s0, R0, t0 = im.initial_values(st, xm, X0)
        cx = np.broadcast_to(b.points[ctrl], (T, ctrl.size, 3))
        wc = np.full((ctrl.size, 3), 25.0)
        return b, lambda: im.adjust_block(st, xm, np.ones(3), cx, wc, s0, R0, t0, X0)

    case(2, 3, 2)[1]()  # compile
    b, adjust = case(strips, models, trials)
    t0 = time.perf_counter()
    res = adjust()
    t_mc = (time.perf_counter() - t0) / trials
    b1, adjust1 = case(strips, models, 1)
    r1 = adjust1()
    t1 = time.perf_counter()
    r1.engine.point_cofactors()
    t_an = time.perf_counter() - t1
    return {
        "points": b.n_points,
        "models": b.n_models,
        "observations": int(3 * b.obs_model.size),
        "unknowns": 7 * b.n_models + 3 * b.n_points,
        "analytic_s": t_an,
        "mc_s_per_trial": t_mc,
        "converged": float(np.mean(res.converged)),
        "peak_mib": peak_rss_mib(),
    }


def _load() -> float:
    """The 1-minute load average (NaN where the system does not say)."""
    try:
        return float(os.getloadavg()[0])
    except OSError:  # pragma: no cover - not on this project's machines
        return float("nan")


def _in_child(args: list[str]) -> dict:
    load = _load()
    r = subprocess.run(
        [sys.executable, "-m", "benchmarks.scaling", "--child", *args],
        capture_output=True,
        text=True,
        timeout=1800,
    )
    if r.returncode != 0:
        tail = (r.stderr.strip().splitlines() or ["no output"])[-1]
        raise RuntimeError(f"scaling {' '.join(args)}: {tail}")
    return {**json.loads(r.stdout.strip().splitlines()[-1]), "load_1min": max(load, _load())}


def _slope(x, y) -> float:
    x, y = np.log(np.asarray(x, float)), np.log(np.asarray(y, float))
    ok = np.isfinite(x) & np.isfinite(y)
    return float(np.polyfit(x[ok], y[ok], 1)[0]) if ok.sum() >= 2 else float("nan")


def scaling_rows(quick: bool = False) -> dict:
    """The scaling table (columns, one row per kind and size) and the fitted slopes."""
    gama = gama_local()
    rows: list[dict] = []
    for kind in ("trilateration", "triangulation"):
        for side in QUICK_SIDES if quick else SIDES:
            trials = 10 if side >= 100 else 20
            r = _in_child(["network", kind, str(side), str(trials), gama or ""])
            rows.append({"kind": kind, "models": 0, **r})
    for side in QUICK_PLATES if quick else PLATES:
        r = _in_child(["gridplate", str(side), "4" if side >= 200 else "20"])
        rows.append({"kind": "gridplate", "gama_s": float("nan"), "gama_note": "", **r})
    for S, Mo in QUICK_MODELS if quick else MODELS:
        r = _in_child(["block", str(S), str(Mo), "5"])
        rows.append({"kind": "block", "gama_s": float("nan"), "gama_note": "", **r})
    cols = {k: [r.get(k, float("nan")) for r in rows] for k in rows[0]}
    kinds = np.array(cols["kind"])
    for c in ("analytic_s", "mc_s_per_trial"):
        cols[f"slope_{c}"] = [float("nan")] * len(rows)
        for k in np.unique(kinds):
            sel = np.flatnonzero(kinds == k)
            size = np.array(cols["models" if k == "block" else "points"])[sel]
            s = _slope(size, np.array(cols[c])[sel])
            for i in sel:
                cols[f"slope_{c}"][i] = s
    with np.errstate(divide="ignore", invalid="ignore"):
        cols["gama_over_analytic"] = list(
            np.array(cols["gama_s"], float) / np.array(cols["analytic_s"], float)
        )
    cols["gama_local"] = [gama or ""] * len(rows)
    return cols


def scaling_figure(cols: dict, path: Path) -> Path:
    """Log-log time against size: the network's analytic pre-analysis, its Monte-Carlo time
    per trial and gama-local's one adjustment against points; the block's against models;
    the grid plate's against points; a reference line of slope 1.5 through each network
    kind's first Monte-Carlo point."""
    fig, (a1, a3, a2) = plt.subplots(1, 3, figsize=(14.0, 4.2))
    kinds = np.array(cols["kind"])
    for n_k, k in enumerate(("trilateration", "triangulation")):
        sel = kinds == k
        if not sel.any():
            continue
        x = np.array(cols["points"])[sel]
        for c, mk, lab in (
            ("analytic_s", "o-", "analytic precision"),
            ("mc_s_per_trial", "s--", "Monte Carlo per trial"),
            ("gama_s", "^:", "gama-local, one adjustment"),
        ):
            y = np.array(cols[c], float)[sel]
            if np.isfinite(y).any():
                a1.loglog(x, y, mk, color=f"C{n_k}", label=f"{k}: {lab}")
        y0 = np.array(cols["mc_s_per_trial"], float)[sel][0]
        a1.loglog(x, y0 * (x / x[0]) ** TARGET_SLOPE, color="0.6", lw=0.8)
    a1.set_xlabel("points")
    a1.set_ylabel("time (s)")
    a1.set_title("networks (grey: points^1.5)")
    a1.legend(fontsize=6)
    sel = kinds == "gridplate"
    if sel.any():
        x = np.array(cols["points"])[sel]
        a3.loglog(x, np.array(cols["analytic_s"])[sel], "o-", label="one trial with cofactors")
        a3.loglog(x, np.array(cols["mc_s_per_trial"])[sel], "s--", label="adjustment per trial")
        a3.set_xlabel("grid points")
        a3.set_title("grid plates (seed 001)")
        a3.legend(fontsize=7)
    sel = kinds == "block"
    if sel.any():
        x = np.array(cols["models"])[sel]
        a2.loglog(x, np.array(cols["analytic_s"])[sel], "o-", label="cofactors of one trial")
        a2.loglog(x, np.array(cols["mc_s_per_trial"])[sel], "s--", label="adjustment per trial")
        a2.set_xlabel("number of models")
        a2.set_title("independent-model blocks")
        a2.legend(fontsize=7)
    fig.tight_layout()
    return save(fig, path)


def _child(argv: list[str]) -> int:
    if argv[0] == "network":
        row = _child_network(argv[1], int(argv[2]), int(argv[3]), argv[4] or None)
    elif argv[0] == "gridplate":
        row = _child_gridplate(int(argv[1]), int(argv[2]))
    else:
        row = _child_block(int(argv[1]), int(argv[2]), int(argv[3]))
    print(json.dumps(row))
    return 0


if __name__ == "__main__":
    sys.exit(_child(sys.argv[2:]) if sys.argv[1:2] == ["--child"] else 2)
