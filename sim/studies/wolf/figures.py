"""Figures of ``wolf_polynomial``, drawn from its Parquet files alone. Wolf & Pearsall 1976
(seed ``000_668e60e68f004f98.txt``); positions mm, discrepancies um."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from sim.mc.storage import read_table
from sim.report.mpl import ticker
from sim.report.plotting import draw, place_legend, plt, save
from sim.studies.wolf.model import ls_map
from sim.studies.wolf.wording import polynomial

_UM_PER_MM = 2.5  # vector plots: 1 mm of plot = 2.5 µm of discrepancy (50 µm = 20 mm)
_AFTER_UM_PER_MM = 1.0  # the corrected vectors drawn _UM_PER_MM / this times longer
#: the scale of the Table 1 plot, as its title says it: 10 µm of discrepancy drawn as 20 mm
_TABLE1_KEY_UM, _TABLE1_KEY_MM = 10.0, 20.0


def _quiver(ax, x, y, dx, dy, title, key_um=20.0, um_per_mm=_UM_PER_MM):
    ax.quiver(
        x, y, dx, dy, angles="xy", scale_units="xy", scale=um_per_mm, width=0.004, color="tab:blue"
    )
    ax.plot(x, y, ".", color="0.5", ms=2)
    ax.quiver(
        [x.min()],
        [y.max() + 25],
        [key_um],
        [0],
        angles="xy",
        scale_units="xy",
        scale=um_per_mm,
        width=0.004,
        color="tab:red",
    )
    ax.text(
        x.min() + key_um / um_per_mm + 3,
        y.max() + 25,
        f"{key_um:g} µm",
        va="center",
        fontsize=7,
        color="tab:red",
    )
    ax.set_aspect("equal")
    ax.set_xlim(x.min() - 25, x.max() + 25)
    ax.set_ylim(y.min() - 20, y.max() + 35)
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")


def figures(cfg: dict, out: Path) -> None:
    """Every figure of the study from its Parquet files."""
    draw(
        [
            (components_figure, (out,)),
            (vectors_figure, (cfg, out)),
            (readings_figure, (out,)),
            (stability_figure, (cfg, out)),
            (degree_figure, (out,)),
            (table1_figure, (out,)),
        ]
    )


def vectors_figure(cfg: dict, out: Path) -> None:
    """Discrepancy vectors of one simulated instrument, before and after the run's
    correction polynomial (``calib.degree``), one column per calibration set."""
    v = read_table(out / "vectors.parquet").to_pydict()
    v = {k: np.asarray(a) for k, a in v.items()}
    sets = np.unique(v["set"])
    fig, axs = plt.subplots(
        2, len(sets), figsize=(4.2 * len(sets), 6.4), squeeze=False, constrained_layout=True
    )
    for j, st in enumerate(sets):
        m = v["set"] == st
        rb = np.sqrt(np.mean(v["dx_before_um"][m] ** 2 + v["dy_before_um"][m] ** 2) / 2)
        ra = np.sqrt(np.mean(v["dx_after_um"][m] ** 2 + v["dy_after_um"][m] ** 2) / 2)
        _quiver(
            axs[0, j],
            v["x_mm"][m],
            v["y_mm"][m],
            v["dx_before_um"][m],
            v["dy_before_um"][m],
            f"set {st}: before (rms {rb:.1f} µm)",
            50.0,
        )
        _quiver(
            axs[1, j],
            v["x_mm"][m],
            v["y_mm"][m],
            v["dx_after_um"][m],
            v["dy_after_um"][m],
            f"set {st}: after the {polynomial(cfg['calib.degree'])} (rms {ra:.1f} µm, "
            f"arrows ×{_UM_PER_MM / _AFTER_UM_PER_MM:g})",
            20.0,
            _AFTER_UM_PER_MM,
        )
    dates = f"{len(sets)} date{'s' * (len(sets) != 1)}"
    fig.suptitle(
        f"Discrepancy vectors of one simulated instrument, {dates} (cf. the paper's Figure 2)",
        fontsize=10,
    )
    save(fig, out / "vectors.png")


def components_figure(out: Path) -> None:
    c = read_table(out / "components.parquet").to_pydict()
    c = {k: np.asarray(a) for k, a in c.items()}
    names = list(dict.fromkeys(c["component"]))
    fig, axs = plt.subplots(2, 4, figsize=(16, 6.6), constrained_layout=True)

    def auto(ax, x, y, dx, dy, title):
        big = max(float(np.hypot(dx, dy).max()), 1e-9)
        key = float(10 ** math.floor(math.log10(big)))
        key = next(k * key for k in (5, 2, 1) if k * key <= big)
        _quiver(ax, x, y, dx, dy, title + f", {big / 15:.2g} µm/mm", key, big / 15)

    for ax, nm in zip(axs.ravel(), names):
        m = c["component"] == nm
        r = np.sqrt(np.mean(c["dx_um"][m] ** 2 + c["dy_um"][m] ** 2) / 2)
        auto(
            ax,
            c["x_mm"][m],
            c["y_mm"][m],
            c["dx_um"][m],
            c["dy_um"][m],
            f"{nm}\nA = {c['amplitude_um'][m][0]:g} µm, rms {r:.1f} µm",
        )
    sel = c["component"] == names[0]
    P = np.column_stack([c["x_mm"][sel], c["y_mm"][sel]])
    tot = np.column_stack(
        [sum(c[k][c["component"] == nm] for nm in names) for k in ("dx_um", "dy_um")]
    )
    moved = P[None] + tot[None] * 1e-3  # what a similarity removes
    rest = (ls_map("similarity", moved, P, moved)[0] - P) * 1000.0
    auto(
        axs.ravel()[-1],
        P[:, 0],
        P[:, 1],
        rest[:, 0],
        rest[:, 1],
        "sum, less its best similarity\n(scale, rotation, shift are absorbed)",
    )
    fig.suptitle(
        "Error-field components of one random draw at the configured amplitudes (inputs); "
        "each panel has its own arrow scale",
        fontsize=10,
    )
    save(fig, out / "components.png")


def degree_figure(out: Path) -> None:
    d = read_table(out / "degree.parquet").to_pydict()
    d = {k: np.asarray(a) for k, a in d.items()}
    sps = list(dict.fromkeys(d["spacing_mm"]))
    fig, axs = plt.subplots(
        1, len(sps), figsize=(4.2 * len(sps), 4), squeeze=False, sharey=True, layout="constrained"
    )
    for ax, sp in zip(axs[0], sps):
        for k, ns in enumerate(dict.fromkeys(d["n_sets"])):
            m = (d["spacing_mm"] == sp) & (d["n_sets"] == ns)
            col = f"C{k}"
            ax.plot(d["degree"][m], d["fit_rms_um"][m], "o--", color=col, alpha=0.7)
            ax.plot(d["degree"][m], d["check_rms_um"][m], "s-", color=col, label=f"{ns} set(s)")
        ax.set_title(f"{sp:g} mm grid ({d['n_points'][d['spacing_mm'] == sp][0]} points)")
        ax.set_xlabel("polynomial degree")
        ax.set_yscale("log")
        degs = sorted(set(d["degree"].tolist()))
        ax.set_xticks(degs)
        ax.set_xlim(min(degs) - 0.3, max(degs) + 0.3)
        ax.yaxis.set_major_formatter(ticker.ScalarFormatter())
        ax.yaxis.set_minor_formatter(ticker.ScalarFormatter())
    axs[0, 0].set_ylabel("median rms (µm): dashed fit data, solid independent plate")
    for ax in axs[0]:
        place_legend(ax, fontsize=8)
    save(fig, out / "degree.png")


def readings_figure(out: Path) -> None:
    r = read_table(out / "readings.parquet").to_pydict()
    r = {k: np.asarray(a) for k, a in r.items()}
    fig, axs = plt.subplots(1, 2, figsize=(11, 4), sharey=True, layout="constrained")
    for ax, appr in zip(axs, ("one_side", "random")):
        for k, sg in enumerate(dict.fromkeys(r["pointing_sigma_um"])):
            m = (r["approach"] == appr) & (r["pointing_sigma_um"] == sg)
            ax.plot(
                r["readings"][m],
                r["after_plate_rms_um"][m],
                "o-",
                color=f"C{k}",
                label=f"σ {sg:g} µm: independent plate, corrected",
            )
            ax.plot(
                r["readings"][m],
                r["reading_error_um"][m],
                "x:",
                color=f"C{k}",
                label=f"σ {sg:g} µm: the averaged reading alone",
            )
        ax.set_xscale("log")
        ax.set_xticks(sorted(set(r["readings"].tolist())))
        ax.xaxis.set_major_formatter(ticker.ScalarFormatter())
        ax.xaxis.set_minor_formatter(ticker.NullFormatter())
        ax.set_xlabel("readings per point")
        ax.set_title(f"approach: {appr.replace('_', ' ')}")
    axs[0].set_ylabel("rms per coordinate (µm)")
    for ax in axs:
        place_legend(ax)
    save(fig, out / "readings.png")


def stability_figure(cfg: dict, out: Path) -> None:
    s = read_table(out / "stability.parquet").to_pydict()
    s = {k: np.asarray(a) for k, a in s.items()}
    fig, ax = plt.subplots(figsize=(6.5, 4.2), layout="constrained")
    for k, f in enumerate(dict.fromkeys(s["drift_fraction"])):
        m = s["drift_fraction"] == f
        x = np.maximum(s["age_weeks"][m], 0.5)
        ax.plot(
            x, s["after_rms_um"][m], "o-", color=f"C{k}", label=f"corrected, drifting share {f:g}"
        )
        ax.plot(x, s["before_rms_um"][m], ":", color=f"C{k}")
    ax.set_xscale("log")
    ax.set_xlabel("age of the calibration (weeks; 0 plotted at 0.5)")
    ax.set_ylabel("median rms on an independent plate (µm)")
    ax.set_title(f"drift time constant {cfg['field.drift_tau_weeks']:g} weeks; dotted: uncorrected")
    place_legend(ax)
    save(fig, out / "stability.png")


def table1_figure(out: Path) -> None:
    t = read_table(out / "table1_real.parquet").to_pydict()
    t = {k: np.asarray(a) for k, a in t.items()}
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    for ax, plate in zip(axs, ("003", "005")):
        m = t["plate"] == plate
        _quiver(
            ax,
            t["x_set1_mm"][m],
            t["y_set1_mm"][m],
            t["dx_sets_um"][m],
            t["dy_sets_um"][m],
            f"plate {plate}: Set 1 - Set 2 (Table 1, {_TABLE1_KEY_UM:g} µm = {_TABLE1_KEY_MM:g} mm)",
            _TABLE1_KEY_UM,
            _TABLE1_KEY_UM / _TABLE1_KEY_MM,
        )
        for x, y, p in zip(t["x_set1_mm"][m], t["y_set1_mm"][m], t["point"][m]):
            ax.annotate(str(p), (x, y), textcoords="offset points", xytext=(3, -8), fontsize=7)
    save(fig, out / "table1_real.png")
