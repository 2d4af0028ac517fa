"""Simulation core of ``agnard_block`` (seed ``003_5ce730a990a7ebc5.txt``): one chunk of
simulated blocks (scanner, grid calibration, image measurements under digital and
mechanical pugging, model formation, random model frames) and the block adjustments of
that chunk with a chosen control layout, and the rms and maximum errors per trial (m).
The numerics live in :mod:`sim.instruments.block.layout`, :mod:`sim.instruments.block.scanner` and
:mod:`sim.instruments.block.independent_models`.
"""

from __future__ import annotations

import copy

import numpy as np

from sim.instruments.block import independent_models as im
from sim.instruments.block import scanner as sc
from sim.instruments.block.centres import Centred, centre_models
from sim.instruments.block.layout import Block, select_control


def _scans(
    cfg: dict,
    b: Block,
    rng: np.random.Generator,
    n: int,
    pix: float,
    uncorrected: bool,
    grid_rng: np.random.Generator | None = None,
):
    """One scanner field per trial, the scanned calibration grid (its nodes' centring noise
    from ``grid_rng`` when given, else from ``rng``) and the fiducial centring noise; returns the image coordinates of the left and right observations (mm) and their
    scanner errors (um) after the fiducial affine, ``corrected`` by the grid and, when
    ``uncorrected``, ``raw``."""
    n_ph = b.photos.shape[0] * b.photos.shape[1]
    field = sc.random_field(
        rng,
        n,
        max_x_um=cfg["scan.max_x_um"],
        max_y_um=cfg["scan.max_y_um"],
        stepper_share=cfg["scan.stepper_share"],
        wavelength_mm=cfg["scan.wavelength_mm"],
        half_mm=cfg["block.format_mm"] / 2,
    )
    grid = sc.scan_grid(
        field, grid_rng or rng, cfg["scan.grid_mm"], cfg["scan.grid_sigma_px"] * pix
    )
    xl = b.image_coords(b.obs_left, b.obs_point)
    xr = b.image_coords(b.obs_right, b.obs_point)
    xy = np.vstack([xl, xr])
    ph = np.concatenate([b.obs_left, b.obs_right])
    fid = sc.corner_fiducials(cfg["scan.fiducial_mm"])
    fid_noise = rng.normal(0.0, cfg["scan.fiducial_sigma_px"] * pix, (n, n_ph) + fid.shape)
    scan = {"corrected": sc.image_errors(field, xy, ph, fid, fid_noise, grid)}
    if uncorrected:
        scan["raw"] = sc.image_errors(field, xy, ph, fid, fid_noise)
    return xl, xr, scan


def _pugging_modes(cfg: dict, b: Block, pix: float, mechanical: bool) -> dict:
    """The pointing-error options of digital pugging and, when ``mechanical``, of mechanical
    pugging (drilled holes on the pass points, re-centring, gross errors; um)."""
    modes = {"digital": {}}
    if mechanical:
        modes["mechanical"] = dict(
            mechanical=b.is_pass,
            transfer_um=cfg["pugging.transfer_um"],
            recentre_um=cfg["pugging.recentre_px"] * pix,
            gross_rate=cfg["pugging.gross_rate"],
            gross_um=tuple(g * pix for g in cfg["pugging.gross_px"]),
        )
    return modes


class Simulated:
    """One chunk of simulated blocks: model coordinates in their own frames and the truth.

    ``grid_rng``: a stream of its own for the calibration grid's node noise, whose count
    depends on ``scan.grid_mm``; with it, every other draw of a block (scanner shape,
    fiducials, pointing, model frames, control) takes the same numbers from ``rng`` whatever
    the scanner's inputs, so blocks of two scanners drawn from equal seeds are paired
    (common random numbers). Without it (the default) the grid noise comes from ``rng``."""

    def __init__(
        self,
        cfg: dict,
        block: Block,
        rng: np.random.Generator,
        n: int,
        dpi: float,
        mechanical: bool = False,
        uncorrected: bool = True,
        grid_rng: np.random.Generator | None = None,
    ):
        pix = sc.pixel_um(dpi)
        b = self.block = block
        self.n = n
        xl, xr, scan = _scans(cfg, b, rng, n, pix, uncorrected, grid_rng)
        modes = _pugging_modes(cfg, b, pix, mechanical)
        self.s, self.R, self.t = im.random_similarities(rng, (n, b.n_models))
        self.xm = {}
        self.gross = {}
        for mode, kw in modes.items():
            self._measure(cfg, rng, n, pix, mode, kw, xl, xr, scan)
        self.ctrl_obs = b.points + rng.normal(
            0.0, cfg["measure.control_sigma_m"], (n,) + b.points.shape
        )
        self.X0 = b.points + rng.normal(0.0, 1.0, (n,) + b.points.shape)
        st = im.BlockStructure(
            b.obs_model, b.obs_point, np.zeros(0, np.intp), b.n_models, b.n_points
        )
        self.init = im.initial_values(st, self.xm[("digital", "corrected")], self.X0)

    def centred(self, cb: Centred, rng: np.random.Generator, sigma_m, key) -> "Simulated":
        """The same blocks with their projection centres as model points
        (:mod:`sim.instruments.block.centres`): the models ``xm[key]`` merged with the
        centres' model coordinates (error ``sigma_m`` per axis, m), the points' starting
        values extended; the other measurements are left out."""
        out = copy.copy(self)
        out.block = cb.block
        xc = centre_models(cb, rng, self.s, self.R, self.t, sigma_m)
        out.xm = {key: cb.merge(self.xm[key], xc)}
        out.X0 = cb.extend(self.X0)
        return out

    def _measure(self, cfg, rng, n, pix, mode, kw, xl, xr, scan) -> None:
        """The pointing errors of one pugging ``mode`` (options ``kw``), then the models
        formed from the image coordinates with each scan's errors (mechanical pugging only
        on corrected scans), in their random model frames: ``xm[(mode, scan)]`` (m)."""
        b = self.block
        el, er, g = im.pointing_errors(
            rng,
            n,
            b.obs_left,
            b.obs_right,
            b.obs_point,
            b.models + 1,
            b.strips,
            b.n_points,
            mark_um=cfg["measure.pointing_px"] * pix,
            parallax_um=cfg["measure.parallax_px"] * pix,
            digital=b.is_pass if mode == "digital" else None,
            **kw,
        )
        self.gross[mode] = g
        K = b.obs_model.size
        centre = b.photos.reshape(-1, 3)[b.obs_left]
        for which, e in scan.items():
            if mode == "mechanical" and which == "raw":
                continue
            G = (
                im.form_models(
                    xl + 1e-3 * (e[:, :K] + el),
                    xr + 1e-3 * (e[:, K:] + er),
                    b.focal_mm,
                    b.base_m,
                )
                + centre
            )
            self.xm[(mode, which)] = im.to_model_frame(G, b.obs_model, self.s, self.R, self.t)


class Adjuster:
    """Block structures per control layout, and the adjustments of one simulated chunk."""

    def __init__(self, block: Block):
        self.block = block
        self._st: dict = {}

    def structure(self, pattern):
        """Control indices and block structure of a named pattern or an index array."""
        key = pattern if isinstance(pattern, str) else tuple(int(i) for i in pattern)
        if key not in self._st:
            ctrl = (
                select_control(self.block, pattern)
                if isinstance(pattern, str)
                else np.asarray(pattern, np.intp)
            )
            b = self.block
            self._st[key] = (
                ctrl,
                im.BlockStructure(b.obs_model, b.obs_point, ctrl, b.n_models, b.n_points),
            )
        return self._st[key]

    def adjust(self, sim: Simulated, key, pattern: str, w_obs, w_ctrl, start=None):
        """Adjust the models ``sim.xm[key]`` with control ``pattern``; ``start`` (a previous
        result on the same trials) only shortens the iterations."""
        ctrl, st = self.structure(pattern)
        s, R, t, X = sim.init + (sim.X0,) if start is None else (start.s, start.R, start.t, start.X)
        res = im.adjust_block(
            st,
            sim.xm[key],
            np.asarray(w_obs, float),
            sim.ctrl_obs[:, ctrl],
            np.broadcast_to(w_ctrl, (ctrl.size, 3)),
            s,
            R,
            t,
            X,
        )
        return ctrl, st, res


def _rms(a: np.ndarray, axis) -> np.ndarray:
    return np.sqrt(np.mean(a**2, axis=axis))


def accuracy(
    block: Block,
    ctrl: np.ndarray,
    res: im.AdjustResult,
    out: dict,
    prefix: str,
    centre: np.ndarray | None = None,
) -> None:
    """rms per trial at control and check points, X Y XY Z, in m.

    Control (``ctrl``): the model-point residuals at control points (transformed model
    coordinates minus adjusted, i.e. nearly the given, coordinates), the residuals an
    independent-model program lists per point and model; ``ctrl_given``: adjusted minus
    given control coordinates. Check: adjusted minus true coordinates.
    """
    check = np.setdiff1d(np.arange(block.n_ground), ctrl)
    err = res.X[:, check] - block.points[check]
    vc = res.v_obs[:, np.isin(block.obs_point, ctrl)]
    for name, e in (("ctrl", vc), ("check", err), ("ctrl_given", res.v_ctrl)):
        out[f"{prefix}.{name}_x_m"] = _rms(e[..., 0], 1)
        out[f"{prefix}.{name}_y_m"] = _rms(e[..., 1], 1)
        out[f"{prefix}.{name}_xy_m"] = np.sqrt(np.mean(e[..., 0] ** 2 + e[..., 1] ** 2, 1))
        out[f"{prefix}.{name}_z_m"] = _rms(e[..., 2], 1)
        if name != "check":
            out[f"{prefix}.{name}_max_xy_m"] = np.hypot(e[..., 0], e[..., 1]).max(1)
            out[f"{prefix}.{name}_max_z_m"] = np.abs(e[..., 2]).max(1)
    if centre is not None:
        c = np.isin(check, centre)
        out[f"{prefix}.centre_xy_m"] = np.sqrt(np.mean(err[:, c, 0] ** 2 + err[:, c, 1] ** 2, 1))
        out[f"{prefix}.centre_z_m"] = _rms(err[:, c, 2], 1)


def centre_points(block: Block, ctrl: np.ndarray, k: int) -> np.ndarray:
    """The ``k`` check points nearest the block centre."""
    x0, x1, y0, y1 = block.extent()
    check = np.setdiff1d(np.arange(block.n_ground), ctrl)
    d = np.hypot(block.points[check, 0] - 0.5 * (x0 + x1), block.points[check, 1] - 0.5 * (y0 + y1))
    return check[np.argsort(d)[:k]]
