"""Figures of ``agnard_block`` (seed ``003_5ce730a990a7ebc5.txt``): one drawn scanner field
before and after calibration, the block layout, check-point error vectors, the trade-offs,
and the five-point layouts of the consistent region."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.instruments.block import scanner as sc
from sim.instruments.block.layout import Block
from sim.mc.runner import chunk_rng
from sim.report.plotting import plt, save


def fig_scanner(cfg: dict, path: Path) -> None:
    """One drawn scanner (stream part 97) before and after the grid calibration."""
    rng = chunk_rng(cfg["seed"], 97, 0)  # a stream of its own, for the figure
    half = cfg["block.format_mm"] / 2
    f = sc.random_field(
        rng,
        1,
        max_x_um=cfg["scan.max_x_um"],
        max_y_um=cfg["scan.max_y_um"],
        stepper_share=cfg["scan.stepper_share"],
        wavelength_mm=cfg["scan.wavelength_mm"],
        half_mm=half,
    )
    pix = sc.pixel_um(cfg["scan.dpi"])
    nodes, disp = sc.scan_grid(f, rng, cfg["scan.grid_mm"], cfg["scan.grid_sigma_px"] * pix)
    g = np.linspace(-half, half, 11)
    xy = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    d = sc.evaluate(f, xy)[0]
    r = d - sc.interpolate(nodes, disp, xy)[0]
    gg = np.linspace(-half, half, 60)
    XY = np.stack(np.meshgrid(gg, gg), -1).reshape(-1, 2)
    D = sc.evaluate(f, XY)[0]
    fig, axs = plt.subplots(1, 3, figsize=(15.5, 4.4))
    fig.subplots_adjust(wspace=0.45)
    for ax, c, lab in ((axs[0], 0, "dx"), (axs[1], 1, "dy")):
        cs = ax.contourf(gg, gg, D[:, c].reshape(60, 60), levels=15, cmap="RdBu_r")
        fig.colorbar(cs, ax=ax, label=f"{lab} (um)")
        ax.set_title(f"scanner deformation {lab}\n(max |{lab}| = {np.abs(D[:, c]).max():.0f} um)")
    axs[2].quiver(
        xy[:, 0],
        xy[:, 1],
        d[:, 0],
        d[:, 1],
        angles="xy",
        scale_units="xy",
        scale=0.5,
        color="tab:red",
        label="before calibration",
    )
    axs[2].quiver(
        xy[:, 0],
        xy[:, 1],
        r[:, 0],
        r[:, 1],
        angles="xy",
        scale_units="xy",
        scale=0.5,
        color="tab:blue",
        label="after grid calibration",
    )
    axs[2].set_title("deformation vectors\n(1 um drawn as 2 mm)")
    axs[2].legend(loc="lower right", fontsize=7)
    for ax in axs:
        ax.set_aspect("equal")
        ax.set_xlabel("x on the photo (mm)")
        ax.set_ylabel("y on the photo (mm)")
    save(fig, path)


def fig_layout(block: Block, ctrl5, ctrl21, path: Path, sweep_ctrl=(), insets=()) -> None:
    fig, ax = plt.subplots(figsize=(12, 5.6))
    w = block.half_format_mm * 1e-3 * block.scale
    for s in range(block.strips):
        for m in range(block.models):
            x0 = (m + 1) * block.base_m - w
            x1 = m * block.base_m + w
            y = s * block.strip_spacing_m
            ax.add_patch(
                plt.Rectangle(
                    (x0, y - w),
                    x1 - x0,
                    2 * w,
                    fill=False,
                    ec=f"C{(s * block.models + m) % 2 + 4}",
                    lw=0.6,
                    alpha=0.7,
                )
            )
    P = block.points
    g = np.arange(block.n_ground)
    chk = np.setdiff1d(g, ctrl21)
    ax.plot(
        P[chk, 0], P[chk, 1], ".", color="0.5", ms=4, label=f"check ({chk.size} with 21 control)"
    )
    ax.plot(
        P[block.is_pass, 0],
        P[block.is_pass, 1],
        "x",
        color="tab:green",
        ms=5,
        label=f"pass points ({int(block.is_pass.sum())})",
    )
    ax.plot(
        P[ctrl21, 0],
        P[ctrl21, 1],
        "^",
        mfc="none",
        color="tab:red",
        ms=9,
        label=f"control, second pass ({ctrl21.size})",
    )
    ax.plot(
        P[ctrl5, 0],
        P[ctrl5, 1],
        "s",
        color="tab:blue",
        ms=6,
        label=f"control, third pass ({ctrl5.size})",
    )
    for i, (c, u) in enumerate(zip(sweep_ctrl, insets)):
        ax.plot(
            P[c, 0],
            P[c, 1],
            "o",
            mfc="none",
            color=plt.cm.viridis(i / max(len(insets) - 1, 1)),
            ms=12 + 3 * i,
            lw=0.8,
            label=f"region five, inset {u:.2f}",
        )
    ax.set_aspect("equal")
    ax.set_xlabel("X along the strips (m)")
    ax.set_ylabel("Y across the strips (m)")
    ax.set_title(f"block of {block.strips} x {block.models} models (rectangles: stereo areas)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=5, fontsize=7)
    save(fig, path)


def fig_residuals(vec: dict, path: Path) -> None:
    fig, axs = plt.subplots(1, 2, figsize=(14, 4.6))
    for ax, lay in zip(axs, ("few", "many")):
        sel = np.asarray(vec["layout"]) == lay
        x, y = np.asarray(vec["x_m"])[sel], np.asarray(vec["y_m"])[sel]
        ex, ey = np.asarray(vec["ex_m"])[sel], np.asarray(vec["ey_m"])[sel]
        mx, my = np.asarray(vec["mean_ex_m"])[sel], np.asarray(vec["mean_ey_m"])[sel]
        ctrl = np.asarray(vec["is_control"])[sel]
        q = ax.quiver(
            x[~ctrl],
            y[~ctrl],
            ex[~ctrl],
            ey[~ctrl],
            angles="xy",
            scale_units="xy",
            scale=1 / 1000,
            color="tab:red",
            width=0.002,
        )
        ax.quiver(
            x[~ctrl],
            y[~ctrl],
            mx[~ctrl],
            my[~ctrl],
            angles="xy",
            scale_units="xy",
            scale=1 / 1000,
            color="k",
            width=0.003,
        )
        ax.quiverkey(q, 0.9, 1.04, 0.3, "0.3 m", labelpos="E")
        ax.plot(x[ctrl], y[ctrl], "^", color="tab:blue", ms=7)
        ax.set_aspect("equal")
        nm = int(np.asarray(vec["mean_over_trials"])[sel][0])
        ax.set_title(
            f"{int(ctrl.sum())} control: check-point errors (red: trial 1, black: mean "
            f"of {nm} trials)",
            fontsize=9,
            loc="left",
        )
        ax.set_xlabel("X (m)")
        ax.set_ylabel("Y (m)")
    save(fig, path)


def fig_tradeoffs(scan_t: dict, lay_t: dict, size_t: dict, path: Path) -> None:
    fig, axs = plt.subplots(1, 3, figsize=(15, 4.3))
    ax = axs[0]
    dpi = np.asarray(scan_t["dpi"])
    for cal, mk in (("raw", "o--"), ("corrected", "s-")):
        sel = np.asarray(scan_t["calibration"]) == cal
        for q, c in (("check_xy_m", "tab:blue"), ("check_z_m", "tab:orange")):
            ax.errorbar(
                dpi[sel],
                np.asarray(scan_t[q])[sel],
                yerr=np.asarray(scan_t[q + "_se"])[sel],
                fmt=mk,
                color=c,
                label=f"{q.split('_')[1].upper()}, "
                f"{'calibrated' if cal == 'corrected' else 'not calibrated'}",
            )
    ax.set_xscale("log", base=2)
    ax.set_xticks(dpi[::2], [f"{d:g}" for d in dpi[::2]])
    ax.set_xlabel("scan resolution (DPI)")
    ax.set_ylabel("rms error at check points (m)")
    ax.set_title("scanner resolution and calibration (21 control)")
    ax.legend(fontsize=7)
    ax = axs[1]
    x = np.arange(len(lay_t["layout"]))
    ax.bar(x - 0.2, lay_t["check_xy_m"], 0.4, yerr=lay_t["check_xy_m_se"], label="XY")
    ax.bar(x + 0.2, lay_t["check_z_m"], 0.4, yerr=lay_t["check_z_m_se"], label="Z")
    ax.set_xticks(x, [f"{a}\n({n})" for a, n in zip(lay_t["layout"], lay_t["n_control"])])
    ax.set_ylabel("rms error at check points (m)")
    ax.set_title("control layout (number of control points)")
    ax.legend()
    ax = axs[2]
    nm = np.asarray(size_t["n_models"])
    o = np.argsort(nm)
    for q, c, lab in (
        ("centre_xy_m", "tab:blue", "XY at centre"),
        ("centre_z_m", "tab:orange", "Z at centre"),
        ("check_xy_m", "tab:blue", "XY, all check"),
        ("check_z_m", "tab:orange", "Z, all check"),
    ):
        ax.errorbar(
            nm[o],
            np.asarray(size_t[q])[o],
            yerr=np.asarray(size_t[q + "_se"])[o],
            fmt="o-" if "centre" in q else "s:",
            color=c,
            label=lab,
        )
    for i in o:
        ax.annotate(
            f"{size_t['strips'][i]}x{size_t['models'][i]}",
            (nm[i], size_t["centre_z_m"][i]),
            textcoords="offset points",
            xytext=(3, 4),
            fontsize=7,
        )
    ax.set_xscale("log")
    ax.set_xlabel("models in the block")
    ax.set_ylabel("rms error (m)")
    ax.set_title("block size (perimeter control)")
    ax.legend(fontsize=7)
    save(fig, path)
