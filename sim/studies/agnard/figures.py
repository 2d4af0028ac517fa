"""Figures of ``agnard_block`` (seed ``003_5ce730a990a7ebc5.txt``): one drawn scanner field
before and after calibration, the block layout, check-point error vectors, the trade-offs,
and the five-point layouts of the consistent region."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sim.instruments.block import scanner as sc
from sim.instruments.block.layout import Block
from sim.mc.runner import chunk_rng
from sim.report.plotting import place_legend, plain_log, plt, save


def _scanner_draw(cfg: dict):
    """One drawn scanner field (stream part 97): the deformation on a 60 x 60 grid ``(gg,
    D)``, and on an 11 x 11 grid before and after the grid calibration ``(xy, d, r)``, µm."""
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
    return gg, sc.evaluate(f, XY)[0], xy, d, r


def fig_scanner(cfg: dict, path: Path) -> None:
    """One drawn scanner (stream part 97) before and after the grid calibration: the
    deformation's two components (µm) and its vectors on the photo (mm)."""
    gg, D, xy, d, r = _scanner_draw(cfg)
    fig, axs = plt.subplots(1, 3, figsize=(15.5, 5.0), layout="constrained")
    for ax, c, lab in ((axs[0], 0, "dx"), (axs[1], 1, "dy")):
        cs = ax.contourf(gg, gg, D[:, c].reshape(60, 60), levels=15, cmap="RdBu_r")
        fig.colorbar(cs, ax=ax, label=f"{lab} (µm)")
        ax.set_title(f"scanner deformation {lab}\n(max |{lab}| = {np.abs(D[:, c]).max():.0f} µm)")
    kw = dict(angles="xy", scale_units="xy", scale=0.5)
    axs[2].quiver(*xy.T, *d.T, color="tab:red", label="before calibration", **kw)
    axs[2].quiver(*xy.T, *r.T, color="tab:blue", label="after grid calibration", **kw)
    axs[2].set_title("deformation vectors\n(1 µm drawn as 2 mm)")
    axs[2].legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=7, ncol=2)
    for ax in axs:
        ax.set_aspect("equal")
        ax.set_xlabel("x on the photo (mm)")
        ax.set_ylabel("y on the photo (mm)")
    save(fig, path)


def _stereo_areas(ax, block: Block) -> None:
    """The stereo area of each model, as a rectangle in alternating colours."""
    w = block.half_format_mm * 1e-3 * block.scale
    for s in range(block.strips):
        for m in range(block.models):
            x0 = (m + 1) * block.base_m - w
            x1 = m * block.base_m + w
            y = s * block.strip_spacing_m
            ec = f"C{(s * block.models + m) % 2 + 4}"
            rect = plt.Rectangle((x0, y - w), x1 - x0, 2 * w, fill=False, ec=ec, lw=0.6, alpha=0.7)
            ax.add_patch(rect)


def fig_layout(block: Block, ctrl5, ctrl21, path: Path, sweep_ctrl=(), insets=()) -> None:
    """The block (m): stereo areas, check, pass and control points of the second and third
    pass, and the five-point layouts the consistent region explores."""
    fig, ax = plt.subplots(figsize=(12, 6.2), layout="constrained")
    _stereo_areas(ax, block)
    P = block.points
    chk = np.setdiff1d(np.arange(block.n_ground), ctrl21)
    ax.plot(
        *P[chk, :2].T,
        ".",
        color="0.45",
        ms=4,
        label=f"check ({chk.size} with {ctrl21.size} control)",
    )
    npass = int(block.is_pass.sum())
    ax.plot(*P[block.is_pass, :2].T, "x", color="tab:green", ms=5, label=f"pass points ({npass})")
    ax.plot(
        *P[ctrl21, :2].T,
        "^",
        mfc="none",
        color="tab:red",
        ms=9,
        label=f"control, second pass ({ctrl21.size})",
    )
    ax.plot(
        *P[ctrl5, :2].T, "s", color="tab:blue", ms=6, label=f"control, third pass ({ctrl5.size})"
    )
    if len(insets):
        span = (
            f"insets {min(insets):.2f}–{max(insets):.2f}"
            if len(insets) > 1
            else f"inset {insets[0]:.2f}"
        )
        for i, c in enumerate(sweep_ctrl):  # one colour, rings growing with the inset
            lab = f"five-point layouts of the consistent region ({len(insets)}, {span})"
            ax.plot(
                *P[c, :2].T,
                "o",
                mfc="none",
                color="tab:purple",
                ms=10 + 14 * insets[i],
                lw=0.8,
                label=None if i else lab,
            )
    ax.set_aspect("equal")
    ax.set_xlabel("X along the strips (m)")
    ax.set_ylabel("Y across the strips (m)")
    ax.set_title(f"block of {block.strips} × {block.models} models (rectangles: stereo areas)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=4, fontsize=7)
    save(fig, path)


def fig_residuals(vec: dict, path: Path) -> None:
    """Check-point error vectors (m) of the two control layouts: trial 1 and the mean."""
    fig, axs = plt.subplots(1, 2, figsize=(14, 4.8), layout="constrained")
    for ax, lay in zip(axs, ("few", "many")):
        sel = np.asarray(vec["layout"]) == lay
        col = {
            k: np.asarray(vec[k])[sel]
            for k in ("x_m", "y_m", "ex_m", "ey_m", "mean_ex_m", "mean_ey_m")
        }
        ctrl = np.asarray(vec["is_control"])[sel]
        xy = (col["x_m"][~ctrl], col["y_m"][~ctrl])
        kw = dict(angles="xy", scale_units="xy", scale=1 / 1000)
        q = ax.quiver(
            *xy, col["ex_m"][~ctrl], col["ey_m"][~ctrl], color="tab:red", width=0.002, **kw
        )
        ax.quiver(
            *xy, col["mean_ex_m"][~ctrl], col["mean_ey_m"][~ctrl], color="k", width=0.003, **kw
        )
        ax.quiverkey(q, 0.9, 1.04, 0.3, "0.3 m", labelpos="E")
        ax.plot(col["x_m"][ctrl], col["y_m"][ctrl], "^", color="tab:blue", ms=7)
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


def _scan_panel(ax, scan_t: dict, n_many: int) -> None:
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
    ax.minorticks_off()
    ax.set_xlabel("scan resolution (DPI)")
    ax.set_ylabel("rms error at check points (m)")
    ax.set_title(f"scanner resolution and calibration ({n_many} control)")


def _layout_panel(ax, lay_t: dict) -> None:
    x = np.arange(len(lay_t["layout"]))
    ax.bar(x - 0.2, lay_t["check_xy_m"], 0.4, yerr=lay_t["check_xy_m_se"], label="XY")
    ax.bar(x + 0.2, lay_t["check_z_m"], 0.4, yerr=lay_t["check_z_m_se"], label="Z")
    ax.set_xticks(x, [f"{a}\n({n})" for a, n in zip(lay_t["layout"], lay_t["n_control"])])
    ax.set_xlabel("control layout (number of control points)")
    ax.set_ylabel("rms error at check points (m)")
    ax.set_title("control layout")


def _size_panel(ax, size_t: dict) -> None:
    """rms error against the number of models; each block's shape (strips × models) labels
    its point at the centre (Z), left of it when the next block has as many models."""
    nm = np.asarray(size_t["n_models"])
    o = np.argsort(nm, kind="stable")
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
    ax.set_xscale("log")
    ax.set_xlim(nm.min() / 1.4, nm.max() * 1.4)
    plain_log(ax)
    ax.set_xlabel("number of models in the block")
    ax.set_ylabel("rms error (m)")
    ax.set_title("block size (perimeter control)")
    ax.figure.canvas.draw()
    for n_i, i in enumerate(o):
        twin = n_i + 1 < len(o) and nm[o[n_i + 1]] == nm[i]
        ax.annotate(
            f"{size_t['strips'][i]}×{size_t['models'][i]}",
            (nm[i], size_t["centre_z_m"][i]),
            textcoords="offset points",
            xytext=(-8, 0) if twin else (8, 0),
            ha="right" if twin else "left",
            va="center",
            fontsize=7,
        )


def fig_tradeoffs(scan_t: dict, lay_t: dict, size_t: dict, n_many: int, path: Path) -> None:
    """The trade-offs (rms errors in m, with their Monte-Carlo standard errors): scanner
    resolution and calibration (on the ``n_many`` control points of ``control.many``), control
    layout, block size."""
    fig, axs = plt.subplots(1, 3, figsize=(15, 4.6), layout="constrained")
    _scan_panel(axs[0], scan_t, n_many)
    _layout_panel(axs[1], lay_t)
    _size_panel(axs[2], size_t)
    for ax in axs:
        place_legend(ax)
    save(fig, path)
