"""Figures of the benchmark, drawn from its row tables (:mod:`benchmarks.cli` writes both).

``bench.png``: Brown's batched adjustment against the SciPy loop, cost per trial against the
number of points, the executors. ``engines.png``: speed-up of each engine over its per-trial
SciPy loop (log scale, the 50x target drawn), and, when measured, the wall time of ``make
rerun`` per worker count, stacked by study, against the 90 s target.
"""

from __future__ import annotations

import numpy as np

from sim.report.plotting import plt, save, times_ten

__all__ = ["brown_figure", "engines_figure"]


def brown_figure(rows, path, agree):
    """``rows``: columns of ``bench.parquet``; ``agree``: the two solutions' difference (mm)."""
    case = np.array(rows["case"])
    tps = np.array(rows["trials_per_s"])
    n = np.array(rows["n_points"])
    fig, axs = plt.subplots(1, 3, figsize=(15, 4.4), layout="constrained")
    b, s = tps[case == "batched"][0], tps[case == "scipy_loop"][0]
    bn = tps[case == "batched_numpy"][0]
    axs[0].bar(
        ["batched\n(compiled, SIMD)", "batched\n(NumPy)", "scipy loop"],
        [b, bn, s],
        color=["tab:blue", "tab:cyan", "tab:gray"],
    )
    axs[0].set_yscale("log")
    axs[0].set_ylabel("trials per second (25 points, pivot)")
    axs[0].set_title(f"speed-up {b / s:.0f}×; solutions agree to {times_ten(agree)} mm")
    axs[0].set_xlabel("engine")
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
    axs[2].set_xlabel("executor")
    save(fig, path)


def engines_figure(eng, rerun, path):
    """``eng``: columns of ``engines.parquet``, ``rerun``: of ``rerun.parquet`` (either None
    when not measured)."""
    k = bool(eng) + bool(rerun)
    wide = 6.5 if not eng else max(6.5, 1.6 * len(eng["engine"]))  # room for every engine's name
    fig, axs = plt.subplots(
        1, k, figsize=(wide + 6.5 * (k - 1), 5.2), squeeze=False, layout="constrained"
    )
    if eng:
        _speedups(axs[0, 0], eng)
    if rerun:
        _rerun(axs[0, k - 1], rerun)
    save(fig, path)


#: the engines as a reader knows them (their names in engines.parquet are module names)
_ENGINE = {
    "pposition": "Brown\nP-position cell",
    "gridplate": "grid plate",
    "block": "Agnard\nblock",
    "polynomial": "Wolf\npolynomial",
    "polynomial_shared": "Wolf\npolynomial,\nshared design",
    "multilateration": "Brown\nmulti-\nlateration",
    "stress_field": "stress field",
    "stress_sincos": "stress field,\nsin/cos",
    "selinv": "selected\ninversion",
    "sparse_solve": "sparse\nsolves",
    "block_sparse": "Agnard block,\nsparse",
    "network_gradient": "network\ngradient",
}


#: study colours of the timeline, no two alike (the pale halves of tab20 are not)
_DISTINCT = [f"tab:{c}" for c in ("blue", "orange", "green", "red", "purple", "brown", "pink")]
_DISTINCT += ["tab:gray", "tab:olive", "tab:cyan", "black", "gold", "navy"]


def _speedups(ax, eng):
    names = [_ENGINE.get(e, e) for e in eng["engine"]]
    x = np.asarray(eng["speedup"], float)
    target = float(eng["target_speedup"][0]) if names else 50.0
    ax.bar(names, x, color=["tab:blue" if v >= target else "tab:orange" for v in x])
    ax.axhline(target, color="0.3", ls="--", label=f"target {target:.0f}×")
    ax.set_yscale("log")
    ax.set_ylabel("speed-up over the per-trial SciPy loop (CPU time)")
    ax.set_title("engines of sim.lsq against SciPy on the same observations")
    for i, v in enumerate(x):
        ax.annotate(f"{v:.0f}×", (i, v), ha="center", va="bottom", fontsize=9)
    ax.set_xlabel("engine (study)")
    ax.tick_params(axis="x", labelsize=8)
    ax.legend()


def _rerun(ax, rerun):
    """A timeline per worker count: each study's run from its start to its end (two lanes
    when the studies run side by side), the report after them, the 90 s target."""
    study = np.asarray(rerun["study"])
    workers = np.asarray(rerun["workers"])
    wall = np.asarray(rerun["wall_s"], float)
    start = np.asarray(rerun.get("start_s", np.zeros(len(study))), float)
    ws = sorted(set(workers.tolist()))
    parts = [s for s in dict.fromkeys(study.tolist()) if s != "total"]
    color = {s: _DISTINCT[k % len(_DISTINCT)] for k, s in enumerate(parts)}
    jobs = rerun.get("jobs")
    gap = (int(max(jobs)) if jobs else 1) + 1  # rows per worker count: a lane per job
    yt, yl = [], []
    for g, w in enumerate(ws):
        lanes: list[float] = []  # each lane: when its last bar ends
        sel = [i for i in range(len(study)) if workers[i] == w and study[i] != "total"]
        for i in sorted(sel, key=lambda i: start[i]):
            k = next((k for k, end in enumerate(lanes) if end <= start[i] + 1e-6), None)
            if k is None:  # every lane busy: a new one
                lanes.append(0.0)
                k = len(lanes) - 1
            lanes[k] = start[i] + wall[i]
            y = g * gap + k
            ax.barh(
                y,
                wall[i],
                left=start[i],
                color=color[study[i]],
                edgecolor="white",
                label=study[i] if g == 0 else None,
            )
        tot = wall[(study == "total") & (workers == w)]
        if tot.size:
            ax.annotate(
                f"total {tot[0]:.0f} s",
                (tot[0], g * gap + (gap - 2) / 2),
                xytext=(4, 0),
                textcoords="offset points",
                va="center",
                fontsize=8,
            )
        yt.append(g * gap + (gap - 2) / 2)
        yl.append(f"{w} worker{'s' if w > 1 else ''}")
    tgt = np.asarray(rerun["target_s"], float)
    ax.axvline(np.nanmax(tgt), color="0.3", ls="--", label=f"target {np.nanmax(tgt):.0f} s")
    ax.set_yticks(yt, yl)
    ax.invert_yaxis()
    tmax = np.nanmax(wall[study == "total"]) if np.any(study == "total") else np.nanmax(wall)
    ax.set_xlim(0.0, 1.2 * max(tmax, np.nanmax(tgt)))  # room for the "total" labels
    ax.set_xlabel("wall time since make rerun started (s)")
    ax.set_title("make rerun, study by study" + (f" ({jobs[0]} side by side)" if jobs else ""))
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
