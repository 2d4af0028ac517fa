"""Figures of ``salsig_encoders``: residuals of one simulated calibration, recovery of the B8
scales and angle, detection power, and the vertical ratio against relief over the consistent
region. Salsig 1985 (seed ``002``); grid and model coordinates in mm, residuals in µm."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.report.plotting import hist_bins, place_legend, plain_log, plt, save
from sim.studies.salsig.schema import UM
from sim.studies.salsig.wording import level_text


def fig_residuals(ex: dict, cfg: dict, path: Path) -> None:
    fig, axs = plt.subplots(1, 2, figsize=(10, 4.8), layout="constrained")
    G, r2 = ex["grid"], ex["res2"][0] / UM
    mg, r3 = ex["marks_grid"][0], ex["res3"][0]
    sig = cfg["b8.sx_mm_per_digit"]
    a = axs[0].quiver(
        G[:, 0],
        G[:, 1],
        r2[:, 0],
        r2[:, 1],
        angles="xy",
        scale_units="xy",
        scale=5.0 / 12.5,
        color="k",
    )
    axs[0].quiverkey(a, 0.85, 1.02, 5, "5 µm", labelpos="E", coordinates="axes")
    axs[0].set_title("FIG. 2 analogue: comparator residuals on the grid", pad=16)
    r3um = r3 * sig / UM
    b = axs[1].quiver(
        mg[:, 0],
        mg[:, 1],
        r3um[:, 0],
        r3um[:, 1],
        angles="xy",
        scale_units="xy",
        scale=50.0 / 12.5,
        color="tab:red",
    )
    axs[1].quiverkey(b, 0.85, 1.02, 50, "50 µm", labelpos="E", coordinates="axes")
    axs[1].set_title("FIG. 3 analogue: B8 residuals at the marks (model µm)", pad=16)
    for ax in axs:
        ax.set_aspect("equal")
        ax.set_xlabel("grid x (mm)")
        ax.set_ylabel("grid y (mm)")
    save(fig, path)


def fig_recovery(res: dict, cfg: dict, path: Path) -> None:
    """The recovered B8 scales (in ppm of the true SX, so the true SY - SX, 153 ppm in the
    paper's FIG. 3, reads directly) and non-perpendicularity E (arcsec) over the simulated calibrations."""
    fig, axs = plt.subplots(1, 3, figsize=(12, 4.0), layout="constrained")
    sx, sy = cfg["b8.sx_mm_per_digit"], cfg["b8.sy_mm_per_digit"]
    ppm = lambda v: (np.asarray(v, float) / sx - 1.0) * 1e6  # noqa: E731
    items = (
        (ppm(res["SX"]), ppm(sx), "SX / true SX - 1 (ppm)", "SX", ("true SY", ppm(sy))),
        (ppm(res["SY"]), ppm(sy), "SY / true SX - 1 (ppm)", "SY", ("true SX", 0.0)),
        (
            np.asarray(res["E_arcsec"]),
            cfg["b8.e_arcsec"],
            "E (arcsec)",
            "E",
            ("perpendicular", 0.0),
        ),
    )
    for ax, (v, tr, lab, name, (olab, ov)) in zip(axs, items):
        ax.hist(v, bins=hist_bins(v, 60), color="tab:blue", alpha=0.7)
        ax.axvline(tr, color="tab:green", lw=2, label="truth")
        ax.axvline(ov, color="tab:orange" if name != "E" else "k", ls="--", label=olab)
        ax.set_xlabel(lab)
        ax.set_ylabel("calibrations")
        ax.set_title(f"recovered {name}", fontsize=9)
        ax.ticklabel_format(useOffset=False)
        place_legend(ax)
    save(fig, path)


def fig_power(sw: dict, cfg: dict, path: Path) -> None:
    """Detection power of E and SY - SX against the number of marks, per B8 sigma: the run's
    true E and scale difference (``b8.*``) at its level ``analysis.alpha``."""
    sx, sy = cfg["b8.sx_mm_per_digit"], cfg["b8.sy_mm_per_digit"]
    fig, axs = plt.subplots(1, 2, figsize=(11, 3.8), sharey=True, layout="constrained")
    sig = sorted(set(sw["sigma_um"]))
    for ax, key, title in (
        (axs[0], "power_E", f'non-perpendicularity E = {cfg["b8.e_arcsec"]:g}"'),
        (axs[1], "power_scale", f"scale difference SY - SX ({100 * (sy - sx) / sx:.3g} %)"),
    ):
        for s in sig:
            idx = [i for i, v in enumerate(sw["sigma_um"]) if v == s]
            ax.plot(
                [sw["n_marks"][i] for i in idx],
                [sw[key][i] for i in idx],
                "o-",
                label=f"B8 σ {s:g} µm",
            )
        ax.axhline(0.95, color="k", lw=0.8)
        ax.set_xlabel("number of marks")
        ax.set_title(f"power to detect {title}")
    axs[0].set_ylabel(f"detection rate at the {level_text(cfg)} level")
    for ax in axs:
        place_legend(ax)
    save(fig, path)


def fig_vertical(relief_mm, ratio: dict, zone: tuple[float, float], path: Path) -> None:
    """Ratio after/before of the vertical rms (median and 95 % of models at each explored
    input vector) against the control relief; the other inputs vary across the region. Salsig 1985 (seed ``002``); grid and model coordinates in mm, residuals in µm."""
    relief_mm = np.asarray(relief_mm, float)
    o = np.argsort(relief_mm)
    fig, ax = plt.subplots(figsize=(5.5, 3.8), layout="constrained")
    ax.vlines(relief_mm[o], ratio["low"][o], ratio["high"][o], color="0.8", lw=0.8,
              label="95 % of models")  # fmt: skip
    ax.plot(relief_mm[o], ratio["value"][o], ".", color="tab:blue", label="median over models")
    ax.axhspan(*zone, color="tab:orange", alpha=0.15, label="'cut roughly in half' (zone)")
    ax.set_xscale("log")
    plain_log(ax)
    ax.set_xlabel("relief of the control heights, rms (model mm)")
    ax.set_ylabel("rms vertical residual after / before (ratio)")
    ax.set_title("vertical residual 'cut roughly in half'?")
    place_legend(ax)
    save(fig, path)
