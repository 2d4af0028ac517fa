"""Figures of study ``brown_design`` (seed ``004``): Pareto front, error budget, datum,
coverage, the emcee corner plot and the two-plate ratio (the region of the unprinted inputs
is drawn once for the paper, by brown_table1). σ in µm, times in minutes. Log axes carry a
few labelled ticks only (plain numbers), so labels never overlap; legends go where they hide
no data (:func:`sim.report.plotting.place_legend`).
"""

from __future__ import annotations

import numpy as np

from sim.instruments.ranges import multilateration as ml
from sim.lsq import distributions as D
from sim.report.mpl import ticker
from sim.report.plotting import place_legend, plt, save, times_ten
from sim.studies.design.cells import pareto_front
from sim.studies.design.claims import load_book

__all__ = ["figure_jobs"]


def _log_ticks(ax, axis: str, lo: float, hi: float) -> None:
    """Plain-number major ticks on a log axis: the coarsest of 1-2-5, 1-2-3-5-7 or finer
    mantissas that gives at least three ticks between ``lo`` and ``hi``, at most eight; no
    minor labels (so labels never overlap)."""
    e0, e1 = int(np.floor(np.log10(lo))), int(np.ceil(np.log10(hi)))
    for mant in (
        (1, 2, 5),
        (1, 2, 3, 5, 7),
        (1, 1.2, 1.4, 1.6, 1.8, 2, 2.5, 3, 4, 5, 6, 7, 8, 9),
        tuple(np.round(np.arange(1.0, 10.0, 0.05), 2)),
    ):
        ticks = [m * 10.0**e for e in range(e0, e1 + 1) for m in mant]
        ticks = [t for t in ticks if lo <= t <= hi]
        if len(ticks) >= 3:
            break
    while len(ticks) > 8:
        ticks = ticks[::2]
    a = ax.xaxis if axis == "x" else ax.yaxis
    a.set_major_locator(ticker.FixedLocator(ticks))
    a.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    a.set_minor_locator(ticker.NullLocator())
    a.set_minor_formatter(ticker.NullFormatter())


def _pareto_all(ax, cols, t, a, ok, P) -> None:
    """Left panel: every cell, the front of all cells and one front per setting sigma."""
    pf = np.array(cols["pareto"])
    ax.scatter(
        t[~ok], a[~ok], s=6, marker="x", c="0.55", label="infeasible (scale, format or pivot)"
    )
    for p, mk in zip(sorted(set(P.tolist())), "osD^v<>"):
        sel = ok & (P == p)
        ax.scatter(t[sel], a[sel], s=10, marker=mk, alpha=0.6, label=f"{p} positions")
    o = np.argsort(t[pf])
    ax.plot(t[pf][o], a[pf][o], "k-", lw=1.5, label="Pareto front (all cells)")
    ss = np.array(cols["setting_sigma_um"])
    for s_, ls in zip(sorted(set(ss.tolist())), ("--", ":", "-.")):
        f = pareto_front(t, a, ok & (ss == s_))
        o = np.argsort(t[f])
        ax.step(
            t[f][o],
            a[f][o],
            where="post",
            color="0.3",
            ls=ls,
            lw=1,
            label=f"front, setting σ {s_:g} µm",
        )
    ax.set_title("all designs (any number of points)")


def _pareto_same(ax, cols, t, a, P, same_n, j) -> None:
    """Right panel: the cells of the paper's plate by positions and settings, and their front."""
    L = np.array(cols["settings"])
    for p, mk in zip(sorted(set(P.tolist())), "osD^v<>"):
        for l_, c in zip(
            sorted(set(L.tolist())), ("tab:blue", "tab:orange", "tab:green", "tab:red")
        ):
            sel = same_n & (P == p) & (L == l_)
            if sel.any():
                ax.scatter(
                    t[sel],
                    a[sel],
                    s=18,
                    marker=mk,
                    color=c,
                    alpha=0.7,
                    label=f"P = {p}, {l_} setting(s)",
                )
    f = pareto_front(t, a, same_n)
    o = np.argsort(t[f])
    ax.step(t[f][o], a[f][o], where="post", color="k", lw=1.2, label="Pareto front")
    ax.set_title(
        f"the paper's plate: {cols['n_points'][j]} points at ±{cols['extent_mm'][j]:g} mm,\n"
        f"setting σ {cols['setting_sigma_um'][j]:g} µm (feasible only)"
    )


def fig_pareto(cols, path, same_n):
    """Worst-point sigma (um) against measuring time (min): all cells, and the paper's plate."""
    t = np.array(cols["time_min"])
    a = np.array(cols["worst_sigma_um"])
    ok = np.array(cols["feasible"])
    P = np.array(cols["positions"])
    j = int(np.flatnonzero(cols["paper_design"])[0])
    fig, axs = plt.subplots(1, 2, figsize=(15, 6), layout="constrained")
    _pareto_all(axs[0], cols, t, a, ok, P)
    _pareto_same(axs[1], cols, t, a, P, same_n, j)
    fin = np.isfinite(a) & (a > 0)
    for ax, sel in zip(axs, (fin, fin & same_n)):
        ax.plot(t[j], a[j], "r*", ms=16, label="paper's design (Table 1)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        _log_ticks(ax, "x", t[sel].min() * 0.9, t[sel].max() * 1.1)
        _log_ticks(ax, "y", a[sel].min() * 0.95, a[sel].max() * 1.05)
        ax.set_xlabel("measuring time of one plate (min)")
        ax.set_ylabel("worst-point σ, datum-free (µm)")
    for ax in axs:
        place_legend(ax)
    save(fig, path)


def fig_budget(b, path, ref):
    fig, ax = plt.subplots(figsize=(9, 5), layout="constrained")
    y = np.arange(len(b["source"]))
    ax.barh(
        y,
        b["rms_um"],
        xerr=1.96 * np.array(b["se_um"]),
        color=["tab:gray" if s else "tab:blue" for s in b["settings"]],
    )
    # each source's value in its label: a bar of 3e-5 um (the wobble as a first harmonic) was
    # not drawn at this scale, read as a source left out
    labels = [
        f"{s} ({d}): {times_ten(r, 3)} µm"
        for s, d, r in zip(b["source"], b["description"], b["rms_um"])
    ]
    ax.set_yticks(y, labels, fontsize=7)
    ax.axvline(ref, color="tab:red", ls="--", lw=1, label=f"paper: {ref:g} µm (Zeiss grid)")
    ax.set_xlabel("rms coordinate error after a rigid fit (µm)")
    ax.set_ylabel("error source (grey: setting errors)")
    ax.set_title("error budget of the comparator (bars: 95 % Monte-Carlo interval)")
    ax.invert_yaxis()
    place_legend(ax, fontsize=8)
    save(fig, path)


def fig_datum(cfg, d, path):
    model = np.array(d["model"])
    dn = np.array(d["datum"])
    fig, axs = plt.subplots(1, 2, figsize=(12, 4.5), layout="constrained")
    for ax, m in zip(axs, ("stations", "pivot")):
        for name, mk in (("brown", "o"), ("inner", "s"), ("corners", "^")):
            sel = (model == m) & (dn == name) & ~np.array(d["corner"])
            ax.plot(np.array(d["point"])[sel], np.array(d["dilution_pct"])[sel], mk, label=name)
        ax.axhspan(5, 15, color="tab:orange", alpha=0.15, label="Brown's 5-15 % (his datum)")
        ax.set_xlabel("point number (row by row from the top left)")
        ax.set_ylabel(f"dilution of '{m}' over 'known' (%)")
        ax.set_title(f"model '{m}': dilution by datum")
    for ax in axs:
        place_legend(ax)
    save(fig, path)


def fig_coverage(c, path):
    model = np.array(c["model"])
    scen = np.array(c["scenario"])
    fig, axs = plt.subplots(1, 3, figsize=(15, 4.5), layout="constrained")
    for ax, (s, xkey, xl) in zip(
        axs,
        (
            ("noise", "sigma_um", "range σ (µm)"),
            ("points", "grid", "points per side"),
            ("beta", "beta_mm", "β (mm)"),
        ),
    ):
        sel = (scen == s) & (model == "pivot")
        x = np.array(c[xkey], float)[sel]
        N = np.array(c["trials"])[sel]
        for key, lab in (
            ("coverage_known", "ellipses, known σ"),
            ("coverage_f", "ellipses, s0 and F"),
            ("b_coverage", "b = β² interval"),
            ("beta_coverage", "β interval (delta method)"),
        ):
            ax.plot(
                np.where(x > 0, x, x[x > 0].min() / 3 if (x > 0).any() else 1),
                np.array(c[key])[sel],
                "o-",
                label=lab,
            )
        se = np.sqrt(0.95 * 0.05 / max(int(N[N > 0].min()) if (N > 0).any() else 1, 1))
        ax.axhspan(0.95 - 1.96 * se, 0.95 + 1.96 * se, color="0.8", label="nominal 95 % ± MC error")
        ax.set_xscale("log" if s != "points" else "linear")
        ax.set_xlabel(xl + (" (0 drawn at left edge)" if s == "beta" else ""))
        ax.set_ylabel("empirical coverage")
        ax.set_ylim(0.0, 1.02)
        ax.set_title(f"pivot model: {s}")
    for ax in axs:
        place_legend(ax)
    save(fig, path)


def fig_corner(samples, mean, Q, names, path):
    d = samples.shape[1]
    fig = plt.figure(figsize=(10, 10))
    sd = np.sqrt(np.diag(Q))
    z = (samples - mean) / sd
    t = np.linspace(0, 2 * np.pi, 100)
    for i in range(d):
        for j in range(i + 1):  # the lower triangle only (the upper one stays empty)
            ax = fig.add_subplot(d, d, i * d + j + 1)
            if i == j:
                ax.hist(z[:, i], bins=40, density=True, color="tab:blue", alpha=0.7)
                xx = np.linspace(-4, 4, 100)
                ax.plot(xx, D.norm_pdf(xx), "r-", lw=1)
            else:
                ax.plot(
                    z[:: max(1, len(z) // 4000), j],
                    z[:: max(1, len(z) // 4000), i],
                    ",",
                    color="tab:blue",
                    alpha=0.5,
                )
                C = Q[np.ix_([j, i], [j, i])] / np.outer(sd[[j, i]], sd[[j, i]])
                w, v = np.linalg.eigh(C)
                e = v @ (np.sqrt(w)[:, None] * np.vstack([np.cos(t), np.sin(t)])) * 2.45
                ax.plot(e[0], e[1], "r-", lw=1)
            ax.set_xlim(-4, 4)
            if i < d - 1:
                ax.set_xticklabels([])
            else:
                ax.set_xlabel(names[j], fontsize=7)
            if j > 0 or i == 0:
                ax.set_yticklabels([])
            else:
                ax.set_ylabel(names[i], fontsize=7)
    fig.suptitle(
        "posterior samples (blue) in units of the least-squares σ about the LS "
        "estimate; red: LS Gaussian / 95 % ellipses",
        y=0.92,
    )
    save(fig, path)


def fig_twoplate(cols, samples, path):
    fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
    bins = np.logspace(-6, 6, 121)
    for name, rho in samples.items():
        h = ax.hist(rho, bins=bins, histtype="step", lw=1.5, label=f"chains, {name} prior")
        j = cols["prior"].index(name)
        for c in ("rho_q025", "rho_q975"):  # the posterior's 95 % interval by quadrature
            ax.axvline(cols[c][j], color=h[2][0].get_edgecolor(), ls=":", lw=1.2)
    ax.plot([], [], color="grey", ls=":", label="95 % interval by quadrature")
    ax.axvline(cols["rw_ratio_mean"][0], color="tab:red", ls="--", label="chi-square re-weighting")
    ax.set_xscale("log")
    ax.set_xlabel("σ²(comparator) / σ²(grid) (ratio, = P_cx / P_x)")
    ax.set_ylabel("samples")
    ax.set_title("two-plate weight ratio: posterior against re-weighting")
    place_legend(ax, fontsize=8)
    save(fig, path)


def figure_jobs(stage: str, out, *data) -> list:
    """The figure jobs ``(fn, args)`` of one stage of the run, for
    :func:`sim.report.plotting.draw` as soon as the stage's tables exist: ``design`` (cols), ``datum`` (cfg, dcols),
    ``budget`` (bcols), ``coverage`` (ccols), ``bayes`` (samples, values), ``twoplate``
    (tcols, tsamples)."""
    if stage == "design":
        (cols,) = data
        jp = int(np.flatnonzero(cols["paper_design"])[0])
        same_n = (
            np.array(cols["feasible"])
            & np.isclose(np.array(cols["setting_sigma_um"]), cols["setting_sigma_um"][jp])
            & (np.array(cols["n_points"]) == cols["n_points"][jp])
            & np.isclose(np.array(cols["extent_mm"]), cols["extent_mm"][jp])
        )
        return [(fig_pareto, (cols, out / "pareto.png", same_n))]
    if stage == "datum":
        cfg, dcols = data
        return [(fig_datum, (cfg, dcols, out / "datum.png"))]
    if stage == "budget":
        ref = float(load_book().spec("brown.results.zeiss_comparator_um")["ref"])
        return [(fig_budget, (data[0], out / "budget.png", ref))]
    if stage == "coverage":
        return [(fig_coverage, (data[0], out / "coverage.png"))]
    if stage == "bayes":
        samples, bay = data
        return [
            (fig_corner, (samples, bay["theta_ls"], bay["Q"], ml.PARAM_NAMES, out / "corner.png"))
        ]
    if stage == "twoplate":
        tcols, tsamples = data
        return (
            [] if tcols is None else [(fig_twoplate, (tcols, tsamples, out / "twoplate_ratio.png"))]
        )
    raise ValueError(f"no figure stage {stage!r}")
