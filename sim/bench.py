"""Benchmark of the batched multilateration solver (``make bench``).

Two questions, one Parquet row per cell (``results/bench/bench.parquet``) and a figure:

1. Trials per second of the 25-point ``pivot`` adjustment, batched, against a per-trial loop
   of ``scipy.optimize.least_squares`` given the analytic Jacobian, on the same simulated
   observations and tolerance (both stop on corrections below ~1e-10 mm).
2. Cost per trial against the number of points (25 to 10,000): linear if the point blocks are
   eliminated (reduced normals), cubic for a dense solve.
3. Each engine of :mod:`sim.lsq` (P-position design cell, two-grid-plate combined
   adjustment, independent-model block) against a per-trial ``scipy.optimize.least_squares``
   loop of the same adjustment on the same observations (rows ``engine_*``, ``scipy_*``;
   the SciPy time is measured on a few trials and scaled to the engine's count).
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from . import multilateration as ml
from .plate import grid_points, random_points
from .storage import provenance, write_table

__all__ = ["main"]


def _obs(n_pts: int, trials: int, seed: int, h: float = 167.5):
    rng = np.random.default_rng(seed)
    k = int(round(np.sqrt(n_pts)))
    pts = grid_points(k, 220.0 / (k - 1)) if k * k == n_pts else random_points(n_pts, 110.0, rng)
    theta = ml.design_theta(h, 0.5, 1.0)
    P = np.broadcast_to(pts, (trials,) + pts.shape)
    obs = ml.simulate_ranges(P, np.broadcast_to(theta, (trials, 7)), rng, setting_sigma_um=1.0,
                             settings=1)
    t0 = theta.copy()
    t0[5:] = 0.0
    return pts, theta, obs, t0


def _scipy_one(obs1: np.ndarray, t0: np.ndarray, p0: np.ndarray):
    """One trial with scipy: unknowns [points (2n), globals (7)], analytic Jacobian."""
    n = obs1.shape[0]

    def unpack(z):
        return z[:2 * n].reshape(1, n, 2), z[2 * n:][None]

    def fun(z):
        P, th = unpack(z)
        return (ml.ranges(P, th) - obs1[None]).ravel()

    def jac(z):
        P, th = unpack(z)
        lin = ml._model(None).linearize(P, th, True)
        Jp, Jg = lin.Jp, lin.Jg
        J = np.zeros((n * 4, 2 * n + 7))
        rows = np.arange(4 * n)
        pt = rows // 4
        J[rows, 2 * pt] = Jp[0].reshape(-1, 2)[:, 0]
        J[rows, 2 * pt + 1] = Jp[0].reshape(-1, 2)[:, 1]
        J[:, 2 * n:] = Jg[0].reshape(-1, 7)
        return J

    z0 = np.concatenate([p0.ravel(), t0])
    return least_squares(fun, z0, jac=jac, method="lm", xtol=1e-13, ftol=1e-15, gtol=1e-15)


def _time(f, repeat: int = 3) -> float:
    """Best CPU time of this process over ``repeat`` calls (single-threaded work: CPU time
    is steadier than wall time on a shared machine; executors are timed by wall clock)."""
    best = np.inf
    for _ in range(repeat):
        t = time.process_time()
        f()
        best = min(best, time.process_time() - t)
    return best


def pivot_chunk(rng: np.random.Generator, n: int, *, pts: np.ndarray, theta: np.ndarray) -> dict:
    """The 25-point ``pivot`` case as a streaming chunk: per-trial rows, per-chunk sums."""
    P = np.broadcast_to(pts, (n,) + pts.shape)
    obs = ml.simulate_ranges(P, np.broadcast_to(theta, (n, 7)), rng, setting_sigma_um=1.0,
                             settings=1)
    t0 = theta.copy()
    t0[5:] = 0.0
    res = ml.adjust(obs, "pivot", t0)
    e = (res.points - pts)[res.converged] * 1e3
    return {"rows.sigma0_um": res.sigma0 * 1e3, "rows.converged": res.converged,
            "rows.iterations": res.iterations, "sum.n": np.array([len(e)], float),
            "sum.e2": (e * e).sum(0)[None]}


def _pivot_fn():
    from functools import partial

    k = 5
    return partial(pivot_chunk, pts=grid_points(k, 220.0 / (k - 1)), theta=ml.design_theta(167.5, 0.5, 1.0))


def executors(trials: int, chunk: int) -> list[tuple[str, int, float]]:
    """Trials per second of the streaming pivot case for each executor."""
    from .runner import make_executor, run_chunks
    from .studies import RunContext

    rows = []
    for kind, workers in (("local", 1), ("local", 2), ("dask", 2)):
        try:
            ex = make_executor(kind, workers)
        except RuntimeError as e:
            print(f"{kind}: skipped ({e})")
            continue
        try:
            run_chunks(_pivot_fn(), 2 * chunk, 1, chunk, ctx=RunContext(quiet=True, executor=ex))  # warm
            t = time.perf_counter()
            run_chunks(_pivot_fn(), trials, 1, chunk, ctx=RunContext(quiet=True, executor=ex))
            rows.append((kind, workers, trials / (time.perf_counter() - t)))
        finally:
            ex.close()
        print(f"{kind:>6} workers={workers} {rows[-1][2]:10.0f} trials/s")
    return rows


def million(out: Path, trials: int, chunk: int) -> None:
    """Child process: stream ``trials`` pivot trials through the chunk store."""
    import shutil

    from .runner import ChunkStore, run_chunks
    from .studies import RunContext

    store_dir = out / "million_trials.tmp"
    shutil.rmtree(store_dir, ignore_errors=True)
    res = run_chunks(_pivot_fn(), trials, 1, chunk, ctx=RunContext(quiet=True, store=ChunkStore(store_dir)))
    assert int(res["sum.n"].sum()) <= trials
    shutil.rmtree(store_dir, ignore_errors=True)


def _peak_rss_mib() -> float:
    """This process's peak resident memory (VmHWM, MiB). Unlike ``ru_maxrss`` it belongs to
    the process image, so it does not inherit the parent's size across fork and exec."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024.0
    import resource  # not Linux: the (possibly inherited) maximum

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def peak_memory(out: Path, trials: int, chunk: int) -> tuple[float, float]:
    """Run :func:`million` in a child process; its peak memory (MiB, as the child reports it)
    and wall time (s)."""
    import subprocess
    import sys

    t = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "sim.bench", "--million-child", str(trials),
                           "--chunk", str(chunk), "--out", str(out)], check=True,
                          capture_output=True, text=True)
    return float(done.stdout.split()[-1]), time.perf_counter() - t


# ---------------------------------------------------------------- engine rows (issue 12)
def _lsq_scipy(fun, z0, jac=None, sparsity=None):
    return least_squares(fun, z0, jac=jac if jac is not None else "2-point",
                         jac_sparsity=sparsity, method="trf", x_scale="jac",
                         xtol=1e-12, ftol=1e-14, gtol=1e-14)


def _pposition(T: int, seed: int = 3):
    """P-position design cell: 6 positions, 5 x 5 points over 220 mm, pivot model."""
    from . import positions as po

    rng = np.random.default_rng(seed)
    pts = grid_points(5, 55.0)
    th = po.design_theta(6, 155.0, 0.5, 1.0)
    TH = np.broadcast_to(th, (T, th.size))
    r = po.ranges(np.broadcast_to(pts, (T,) + pts.shape), TH) + rng.normal(0, 1e-3, (T, 25, 6))
    t0 = th.copy()
    t0[-2:] = 0.0

    def engine():
        return po.adjust(r, "pivot", t0, "inner").sigma0

    def one(t):  # minimal datum X_1, Y_1, X_2 held; sigma0 is datum-invariant
        n, q = 25, th.size
        keep = np.r_[3:q]
        z0 = np.concatenate([po.initial_points(r[t:t + 1], t0[None])[0].ravel(), t0[keep]])
        model = po.RangeModel(r[t:t + 1])

        def unpack(z):
            full = t0.copy()
            full[keep] = z[2 * n:]
            return z[:2 * n].reshape(1, n, 2), full[None]

        def fun(z):
            return model.linearize(*unpack(z), False).r.ravel()

        def jac(z):
            lin = model.linearize(*unpack(z), True)
            J = np.zeros((n * 6, 2 * n + keep.size))
            rows = np.arange(6 * n)
            J[rows, 2 * (rows // 6)] = -lin.Jp[0].reshape(-1, 2)[:, 0]
            J[rows, 2 * (rows // 6) + 1] = -lin.Jp[0].reshape(-1, 2)[:, 1]
            J[:, 2 * n:] = -lin.Jg[0].reshape(-1, q)[:, keep]
            return J

        f = _lsq_scipy(fun, z0, jac)
        return np.sqrt(2 * f.cost / (6 * n - 2 * n - q + 3))

    return 25, engine, one


def _gridplate(T: int, seed: int = 4):
    """Two-grid-plate combined adjustment of one coordinate, 7 x 7 points, P_cx = 4."""
    from . import gridplate as gp

    rng = np.random.default_rng(seed)
    g = grid_points(7, 36.0)
    N = len(g)
    true = g + rng.normal(0, 1e-3, (T, N, 2))
    comp = 1.00002 * true[..., 0] + 3e-5 * true[..., 1] + 2.0 + rng.normal(0, 1e-3, (T, N))

    def engine():
        return gp.combined_adjustment(comp, g, 1.0, 4.0).params

    def one(t):
        def fun(z):
            u = z[3:].reshape(N, 2)
            return np.concatenate([comp[t] - (z[0] * u[:, 0] + z[1] * u[:, 1] + z[2]),
                                   2.0 * (g - u).ravel()])
        return _lsq_scipy(fun, np.r_[1.0, 0.0, 0.0, g.ravel()]).x[:3]

    return N, engine, one


def _block(T: int, seed: int = 5):
    """Independent-model block of 2 strips x 3 models, 40 ground points, control on the
    pattern "full" (the SciPy loop differentiates numerically on the sparsity pattern)."""
    from . import independent_models as im
    from .block_layout import make_block, select_control

    rng = np.random.default_rng(seed)
    b = make_block(2, 3, n_ground=40, pass_rows=3)
    xl, xr = b.image_coords(b.obs_left, b.obs_point), b.image_coords(b.obs_right, b.obs_point)
    G = im.form_models(xl, xr, b.focal_mm, b.base_m) + b.photos.reshape(-1, 3)[b.obs_left]
    G = G[None] + rng.normal(0, 0.05, (T,) + G.shape)
    s, R, t = im.random_similarities(rng, (T, b.n_models))
    xm = im.to_model_frame(G, b.obs_model, s, R, t)
    ctrl = select_control(b, "full")
    st = im.BlockStructure(b.obs_model, b.obs_point, ctrl, b.n_models, b.n_points)
    X0 = b.points + rng.normal(0, 2.0, (T,) + b.points.shape)
    s0, R0, t0 = im.initial_values(st, xm, X0)
    cx = np.broadcast_to(b.points[ctrl], (T, ctrl.size, 3))
    wc = np.full((ctrl.size, 3), 25.0)

    def engine():
        return im.adjust_block(st, xm, np.ones(3), cx, wc, s0, R0, t0, X0).X

    def one(i):
        M, P, K, C = b.n_models, b.n_points, b.obs_model.size, ctrl.size
        om, op = b.obs_model, b.obs_point

        def fun(z):
            g = z[:7 * M].reshape(M, 7)
            X = z[7 * M:].reshape(P, 3)
            Rm = im.rodrigues(g[:, 1:4]) @ R0[i]
            y = (s0[i] * (1 + g[:, 0]))[om, None] * np.einsum("kij,kj->ki", Rm[om], xm[i])
            return np.concatenate([(y + t0[i][om] + g[om, 4:7] - X[op]).ravel(),
                                   (5.0 * (X[ctrl] - cx[i])).ravel()])

        sp = np.zeros((3 * K + 3 * C, 7 * M + 3 * P), bool)
        for k in range(K):
            sp[3 * k:3 * k + 3, 7 * om[k]:7 * om[k] + 7] = True
            sp[3 * k:3 * k + 3, 7 * M + 3 * op[k]:7 * M + 3 * op[k] + 3] = True
        for c, j in enumerate(ctrl):
            sp[3 * K + 3 * c:3 * K + 3 * c + 3, 7 * M + 3 * j:7 * M + 3 * j + 3] = True
        return _lsq_scipy(fun, np.r_[np.zeros(7 * M), X0[i].ravel()],
                          sparsity=sp).x[7 * M:].reshape(P, 3)

    return b.n_points, engine, one


def engine_rows(quick: bool) -> list[tuple[str, int, int, float, float]]:
    """Per engine: (name, points, trials, engine seconds, scipy seconds per the same number
    of trials) and the largest difference of the solutions (printed)."""
    out = []
    for name, make, T, Ts in (("pposition", _pposition, 400, 10), ("gridplate", _gridplate, 400, 10),
                              ("block", _block, 40, 2)):
        T, Ts = (max(T // 10, 4), max(Ts // 2, 1)) if quick else (T, Ts)
        n, engine, one = make(T)
        eng = engine()
        te = _time(engine, 1 if quick else 3)
        ts = _time(lambda: [one(t) for t in range(Ts)], 1) * T / Ts
        diff = max(float(np.abs(np.asarray(one(t)) - eng[t]).max()) for t in range(min(Ts, 2)))
        print(f"{name:>10}: engine {T / te:10.1f} trials/s, scipy loop {T / ts:8.2f} trials/s, "
              f"x{ts / te:.0f}; solutions differ by {diff:.1e}")
        out.append((name, n, T, te, ts))
    return out


def run(out: Path, quick: bool = False) -> dict:
    rows: dict[str, list] = {k: [] for k in ("case", "n_points", "trials", "seconds",
                                             "trials_per_s", "us_per_trial_per_point")}

    def add(case, n, T, sec):
        rows["case"].append(case)
        rows["n_points"].append(n)
        rows["trials"].append(T)
        rows["seconds"].append(sec)
        rows["trials_per_s"].append(T / sec)
        rows["us_per_trial_per_point"].append(sec / T / n * 1e6)
        print(f"{case:>16} n={n:>6} trials={T:>6} {T / sec:12.1f} trials/s")

    # 1. batched vs scipy loop, 25 points, pivot model
    T = 1000 if quick else 4000
    Ts = 20 if quick else 100
    B = 500  # trials per call, as the runner's chunks use it (cache-friendly)
    pts, theta, obs, t0 = _obs(25, T, 1)
    ml.adjust(obs[:B], "pivot", t0)  # compile (or load) the kernel before timing
    p0 = ml.initial_points(obs[:Ts], np.broadcast_to(t0, (Ts, 7)))
    res = ml.adjust(obs[:Ts], "pivot", t0)

    def loop():
        for t in range(Ts):
            _scipy_one(obs[t], t0, p0[t])

    # the machine's speed drifts: time the three side by side, in rounds, and keep each
    # one's best (the ratio of bests is what the figure and README quote)
    tb, tn, ts = [], [], []
    for _ in range(1 if quick else 3):
        tb.append(_time(lambda: [ml.adjust(obs[i:i + B], "pivot", t0) for i in range(0, T, B)], 3))
        tn.append(_time(lambda: [ml.adjust(obs[i:i + B], "pivot", t0, engine="numpy")
                                 for i in range(0, T, B)], 1))
        ts.append(_time(loop, 1))
    add("batched", 25, T, min(tb))
    add("batched_numpy", 25, T, min(tn))
    add("scipy_loop", 25, Ts, min(ts))
    z = np.concatenate([res.points[0].ravel(), res.theta[0]])
    zs = _scipy_one(obs[0], t0, p0[0]).x
    agree = float(np.abs(z - zs).max())
    # 2. cost against the number of points
    for n in ([25, 100, 400, 1600] if quick else [25, 100, 400, 1600, 4900, 10000]):
        Tn = max(2 * ml.jit.LANES, 40000 // n)  # whole SIMD blocks at every size
        _, _, o, tt = _obs(n, Tn, 2)
        add("batched_points", n, Tn, _time(lambda: ml.adjust(o, "pivot", tt), 2))
    # 3. the engines of sim.lsq against per-trial SciPy loops of the same adjustments
    for name, n, Te, te, ts in engine_rows(quick):
        add(f"engine_{name}", n, Te, te)
        add(f"scipy_{name}", n, Te, ts)
    # 4. executors, and the memory of a million-trial streamed run
    n_ex = 20000 if quick else 100000
    for kind, workers, tps in executors(n_ex, 5000):
        add(f"{kind}_{workers}w", 25, n_ex, n_ex / tps)
    n_mil = 50000 if quick else 1_000_000
    rss, wall = peak_memory(out, n_mil, 10000)
    print(f"{n_mil} trials streamed: peak memory {rss:.0f} MiB, {wall:.0f} s")
    prov = provenance({"study": "bench", "seed": 1, "quick": quick},
                      solutions_agree_mm=agree, million_trials=n_mil, peak_memory_mib=rss,
                      million_wall_s=wall)
    write_table(out / "bench.parquet", rows, prov)
    _figure(rows, out / "bench.png", agree)
    return rows


def _figure(rows, path, agree):
    from .plotting import plt, save

    case = np.array(rows["case"])
    tps = np.array(rows["trials_per_s"])
    n = np.array(rows["n_points"])
    fig, axs = plt.subplots(1, 3, figsize=(15, 4))
    b, s = tps[case == "batched"][0], tps[case == "scipy_loop"][0]
    bn = tps[case == "batched_numpy"][0]
    axs[0].bar(["batched\n(compiled, SIMD)", "batched\n(NumPy)", "scipy loop"], [b, bn, s],
               color=["tab:blue", "tab:cyan", "tab:gray"])
    axs[0].set_yscale("log")
    axs[0].set_ylabel("trials per second (25 points, pivot)")
    axs[0].set_title(f"speed-up {b / s:.0f}x; solutions agree to {agree:.1e} mm")
    sel = case == "batched_points"
    cost = 1.0 / tps[sel]
    axs[1].loglog(n[sel], cost * 1e3, "o-", label="measured")
    axs[1].loglog(n[sel], cost[0] * 1e3 * n[sel] / n[sel][0], "--", color="0.5", label="linear")
    slope = np.polyfit(np.log(n[sel]), np.log(cost), 1)[0]
    axs[1].set_title(f"cost per trial vs points (log-log slope {slope:.2f})")
    axs[1].set_xlabel("points per plate")
    axs[1].set_ylabel("ms per trial")
    axs[1].legend()
    ex = [c for c in case if c.startswith(("local_", "dask_"))]
    axs[2].bar(ex, [tps[case == c][0] for c in ex], color="tab:green")
    axs[2].set_ylabel("trials per second (streamed)")
    axs[2].set_title("executors on this machine")
    save(fig, path)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m sim.bench", description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="results/bench")
    ap.add_argument("--quick", action="store_true", help="small sizes (a smoke run)")
    ap.add_argument("--million-child", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--chunk", type=int, default=10000, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.million_child:
        million(Path(a.out), a.million_child, a.chunk)
        print(f"{_peak_rss_mib():.1f}")
        return 0
    rows = run(Path(a.out), a.quick)
    case = np.array(rows["case"])
    tps = np.array(rows["trials_per_s"])
    print(f"speed-up over the scipy loop: {tps[case == 'batched'][0] / tps[case == 'scipy_loop'][0]:.0f}x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
