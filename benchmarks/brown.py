"""Benchmark rows of Brown's multilateration (``bench.parquet``, seed ``004``).

1. Trials per second of the 25-point ``pivot`` adjustment, batched (compiled SIMD kernel and
   the NumPy engine), against a per-trial loop of ``scipy.optimize.least_squares`` given the
   analytic Jacobian, on the same simulated observations and tolerance (both stop on
   corrections below ~1e-10 mm): rows ``batched``, ``batched_numpy``, ``scipy_loop``.
2. Cost per trial against the number of points (25 to 10,000): linear if the point blocks are
   eliminated (reduced normals), cubic for a dense solve (rows ``batched_points``).
3. Trials per second of the streamed pivot case for 1 and 2 local workers and Dask with 2
   workers (rows ``local_1w``, ``local_2w``, ``dask_2w``), and the peak memory of a
   million-trial streamed run (a child process; the table's provenance).
"""

from __future__ import annotations

import resource
import shutil
import subprocess
import sys
import time
from functools import partial
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from benchmarks.timing import cpu_time
from sim.instruments.plates import grid_points, random_points
from sim.instruments.ranges import multilateration as ml
from sim.mc.children import ended
from sim.mc.runner import ChunkStore, make_executor, run_chunks
from sim.studies import RunContext

__all__ = ["brown_rows", "pivot_chunk", "executors", "million", "peak_memory", "peak_rss_mib"]


def _obs(n_pts: int, trials: int, seed: int, h: float = 167.5):
    rng = np.random.default_rng(seed)
    k = int(round(np.sqrt(n_pts)))
    pts = grid_points(k, 220.0 / (k - 1)) if k * k == n_pts else random_points(n_pts, 110.0, rng)
    theta = ml.design_theta(h, 0.5, 1.0)
    P = np.broadcast_to(pts, (trials,) + pts.shape)
    obs = ml.simulate_ranges(
        P, np.broadcast_to(theta, (trials, 7)), rng, setting_sigma_um=1.0, settings=1
    )
    t0 = theta.copy()
    t0[5:] = 0.0
    return pts, theta, obs, t0


def _scipy_one(obs1: np.ndarray, t0: np.ndarray, p0: np.ndarray):
    """One trial with scipy: unknowns [points (2n), globals (7)], analytic Jacobian."""
    n = obs1.shape[0]

    def unpack(z):
        return z[: 2 * n].reshape(1, n, 2), z[2 * n :][None]

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
        J[:, 2 * n :] = Jg[0].reshape(-1, 7)
        return J

    z0 = np.concatenate([p0.ravel(), t0])
    return least_squares(fun, z0, jac=jac, method="lm", xtol=1e-13, ftol=1e-15, gtol=1e-15)


def pivot_chunk(rng: np.random.Generator, n: int, *, pts: np.ndarray, theta: np.ndarray) -> dict:
    """The 25-point ``pivot`` case as a streaming chunk: per-trial rows, per-chunk sums."""
    P = np.broadcast_to(pts, (n,) + pts.shape)
    obs = ml.simulate_ranges(
        P, np.broadcast_to(theta, (n, 7)), rng, setting_sigma_um=1.0, settings=1
    )
    t0 = theta.copy()
    t0[5:] = 0.0
    res = ml.adjust(obs, "pivot", t0)
    e = (res.points - pts)[res.converged] * 1e3
    return {
        "rows.sigma0_um": res.sigma0 * 1e3,
        "rows.converged": res.converged,
        "rows.iterations": res.iterations,
        "sum.n": np.array([len(e)], float),
        "sum.e2": (e * e).sum(0)[None],
    }


def _pivot_fn():
    k = 5
    return partial(
        pivot_chunk, pts=grid_points(k, 220.0 / (k - 1)), theta=ml.design_theta(167.5, 0.5, 1.0)
    )


def executors(trials: int, chunk: int) -> list[tuple[str, int, float]]:
    """Trials per second of the streaming pivot case for each executor."""
    rows = []
    for kind, workers in (("local", 1), ("local", 2), ("dask", 2)):
        try:
            ex = make_executor(kind, workers)
        except RuntimeError as e:
            print(f"{kind}: skipped ({e})")
            continue
        try:
            run_chunks(
                _pivot_fn(), 2 * chunk, 1, chunk, ctx=RunContext(quiet=True, executor=ex)
            )  # warm
            t = time.perf_counter()
            run_chunks(_pivot_fn(), trials, 1, chunk, ctx=RunContext(quiet=True, executor=ex))
            rows.append((kind, workers, trials / (time.perf_counter() - t)))
        finally:
            ex.close()
        print(f"{kind:>6} workers={workers} {rows[-1][2]:10.0f} trials/s")
    return rows


def million(out: Path, trials: int, chunk: int) -> None:
    """Child process: stream ``trials`` pivot trials through the chunk store."""
    store_dir = out / "million_trials.tmp"
    shutil.rmtree(store_dir, ignore_errors=True)
    res = run_chunks(
        _pivot_fn(), trials, 1, chunk, ctx=RunContext(quiet=True, store=ChunkStore(store_dir))
    )
    assert int(res["sum.n"].sum()) <= trials
    shutil.rmtree(store_dir, ignore_errors=True)


def peak_rss_mib() -> float:
    """This process's peak resident memory (VmHWM, MiB). Unlike ``ru_maxrss`` it belongs to
    the process image, so it does not inherit the parent's size across fork and exec."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024.0
    # not Linux: the (possibly inherited) maximum
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def peak_memory(out: Path, trials: int, chunk: int) -> tuple[float, float]:
    """Run :func:`million` in a child process; its peak memory (MiB, as the child reports it)
    and wall time (s)."""
    t = time.perf_counter()
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "benchmarks",
            "--million-child",
            str(trials),
            "--chunk",
            str(chunk),
            f"--out={out}",  # an --out that begins with "-" is its value, not an option
        ],
        capture_output=True,
        text=True,
    )
    if done.returncode != 0:  # its chunk store could not be written (a full disk), or it was
        # killed (the OOM killer): a CalledProcessError traceback, exit 1
        last = [ln for ln in done.stderr.splitlines() if ln.strip()][-1:]
        why = f": {last[0].removeprefix('benchmarks: error: ')}" if last else ""
        raise RuntimeError(
            f"the {trials:,}-trial streamed run (a child process) {ended(done.returncode)}{why}"
        )
    return float(done.stdout.split()[-1]), time.perf_counter() - t


def brown_rows(out: Path, quick: bool = False) -> tuple[dict, dict]:
    """The rows of ``bench.parquet`` (columns ``case``, ``n_points``, ``trials``, ``seconds``,
    ``trials_per_s``, ``us_per_trial_per_point``) and the provenance extras (agreement of
    the two solutions in mm, the million-trial run's peak memory and wall time)."""
    rows: dict[str, list] = {
        k: []
        for k in ("case", "n_points", "trials", "seconds", "trials_per_s", "us_per_trial_per_point")
    }

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
    z = np.concatenate([res.points[0].ravel(), res.theta[0]])
    agree = float(np.abs(z - _scipy_one(obs[0], t0, p0[0]).x).max())
    if not agree < 1e-6:  # the same adjustment: both stop on corrections of ~1e-10 mm
        raise RuntimeError(f"bench: the batched and the scipy solutions differ by {agree:.1e} mm")

    def loop():
        for t in range(Ts):
            _scipy_one(obs[t], t0, p0[t])

    # the machine's speed drifts: time the three side by side, in rounds, and keep each
    # one's best (the ratio of bests is what the figure and README quote)
    tb, tn, ts = [], [], []
    for _ in range(1 if quick else 3):
        tb.append(
            cpu_time(lambda: [ml.adjust(obs[i : i + B], "pivot", t0) for i in range(0, T, B)], 3)
        )
        tn.append(
            cpu_time(
                lambda: [
                    ml.adjust(obs[i : i + B], "pivot", t0, engine="numpy") for i in range(0, T, B)
                ],
                1,
            )
        )
        ts.append(cpu_time(loop, 1))
    add("batched", 25, T, min(tb))
    add("batched_numpy", 25, T, min(tn))
    add("scipy_loop", 25, Ts, min(ts))
    # 2. cost against the number of points
    for n in [25, 100, 400, 1600] if quick else [25, 100, 400, 1600, 4900, 10000]:
        Tn = max(2 * ml.jit.LANES, 40000 // n)  # whole SIMD blocks at every size
        _, _, o, tt = _obs(n, Tn, 2)
        add("batched_points", n, Tn, cpu_time(lambda: ml.adjust(o, "pivot", tt), 2))
    # 3. executors, and the memory of a million-trial streamed run
    n_ex = 20000 if quick else 100000
    for kind, workers, tps in executors(n_ex, 5000):
        add(f"{kind}_{workers}w", 25, n_ex, n_ex / tps)
    n_mil = 50000 if quick else 1_000_000
    rss, wall = peak_memory(out, n_mil, 10000)
    print(f"{n_mil} trials streamed: peak memory {rss:.0f} MiB, {wall:.0f} s")
    return rows, {
        "solutions_agree_mm": agree,
        "million_trials": n_mil,
        "peak_memory_mib": rss,
        "million_wall_s": wall,
    }
