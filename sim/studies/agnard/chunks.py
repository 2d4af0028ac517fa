"""Chunk functions of ``agnard_block`` (seed ``003_5ce730a990a7ebc5.txt``).

Each is a module-level function ``f(cfg, block, ..., rng, n)``; the run hands the runner
``functools.partial(f, cfg, block, ...)`` (plain, picklable arguments), so chunks go to
process pools and Dask workers and are stored for resumption. Everything a chunk produces
leaves it through its returned arrays: per-trial values (leading axis ``n``) and per-chunk
sums or examples (leading axis 1, keys ``chunk.*``). Lengths in metres.
"""

from __future__ import annotations

import numpy as np

from sim.instruments.block.data_snooping import snoop
from sim.instruments.block.layout import Block
from sim.lsq import distributions as D
from sim.studies.agnard.schema import five_control, paper_weights, snoop_weights
from sim.studies.agnard.simulate import Adjuster, Simulated, _rms, accuracy

#: keys of per-chunk (not per-trial) arrays
CHUNK = "chunk."


def _layouts(cfg: dict) -> list[str]:
    return list(
        dict.fromkeys(
            [
                cfg["control.table1"],
                cfg["control.few"],
                cfg["control.many"],
                *cfg["tradeoff.layouts"],
            ]
        )
    )


def main_chunk(cfg: dict, block: Block, rng: np.random.Generator, n: int) -> dict:
    """The 2 x 8 block: every adjustment of the paper on the same trials, the control
    layouts, the first pass, data snooping under digital and mechanical pugging; and, per
    chunk, trial 0's and the summed check-point errors of the 5- and 21-control passes (for
    the figures)."""
    adj = Adjuster(block)
    crit = float(D.norm_ppf(1 - cfg["snoop.alpha"] / 2))
    sim = Simulated(cfg, block, rng, n, cfg["scan.dpi"], mechanical=True)
    out: dict[str, np.ndarray] = {}
    wo, wc = paper_weights(cfg)
    ctrl, _, res0 = adj.adjust(sim, ("digital", "raw"), cfg["control.table1"], wo, wc)
    accuracy(block, ctrl, res0, out, "without")
    out["without.converged"] = res0.converged
    done = {}
    for lay in _layouts(cfg):
        ctrl, _, res = adj.adjust(sim, ("digital", "corrected"), lay, wo, wc, start=res0)
        accuracy(block, ctrl, res, out, f"layout_{lay}")
        done[lay] = res
        out[f"layout_{lay}.converged"] = res.converged
    ng = block.n_ground
    for tag, lay in (("few", cfg["control.few"]), ("many", cfg["control.many"])):
        e = done[lay].X[:, :ng] - block.points[:ng]
        out[f"{CHUNK}{tag}_first_e_m"] = e[:1]
        out[f"{CHUNK}{tag}_sum_e_m"] = e.sum(0, keepdims=True)
    # first pass: weak control (started from the 21-control solution of the same blocks)
    res21 = done[cfg["control.many"]]
    wo1, wc1 = paper_weights(cfg, first_pass=True)
    _, _, res = adj.adjust(
        sim, ("digital", "corrected"), cfg["control.many"], wo1, wc1, start=res21
    )
    pas = block.is_pass[block.obs_point]
    v = res.v_obs[:, pas]
    out["first.pass_xy_m"] = np.sqrt(np.mean(v[..., 0] ** 2 + v[..., 1] ** 2, 1))
    out["first.pass_z_m"] = _rms(v[..., 2], 1)
    out["first.pass_x_m"] = _rms(v[..., 0], 1)
    out["first.pass_y_m"] = _rms(v[..., 1], 1)
    out["first.converged"] = res.converged
    # data snooping, digital and mechanical pugging
    ws, wsc = snoop_weights(cfg)
    ctrl, st = adj.structure(cfg["control.many"])
    n_pass = int(block.is_pass.sum())
    for mode in ("digital", "mechanical"):
        rej, s0, _, _ = snoop(
            st,
            sim.xm[(mode, "corrected")],
            ws,
            sim.ctrl_obs[:, ctrl],
            np.broadcast_to(wsc, (ctrl.size, 3)),
            res21.s,
            res21.R,
            res21.t,
            res21.X,
            block.is_pass,
            crit,
            cfg["snoop.max_reject"],
            cfg["snoop.test"] == "tau",
        )
        out[f"snoop_{mode}.rejected"] = rej[:, block.is_pass].sum(1)
        out[f"snoop_{mode}.share_pct"] = 100.0 * out[f"snoop_{mode}.rejected"] / n_pass
        out[f"snoop_{mode}.sigma0"] = s0
        g = np.zeros((n, block.n_points), bool)
        for_t, for_k = np.nonzero(sim.gross[mode])
        g[for_t, block.obs_point[for_k]] = True
        out[f"snoop_{mode}.gross_points"] = g.sum(1)
        out[f"snoop_{mode}.gross_found"] = (g & rej).sum(1)
    return out


def scanner_chunk(cfg: dict, block: Block, dpi: float, rng: np.random.Generator, n: int) -> dict:
    """The 21-control block at another scan resolution, with and without the calibration."""
    adj = Adjuster(block)
    wo, wc = paper_weights(cfg)
    sim = Simulated(cfg, block, rng, n, dpi)
    out: dict[str, np.ndarray] = {}
    res = None
    for key in ("raw", "corrected"):
        ctrl, _, res = adj.adjust(sim, ("digital", key), cfg["control.many"], wo, wc, res)
        accuracy(block, ctrl, res, out, key)
    out["gain_xy_pct"] = 100 * (1 - out["corrected.check_xy_m"] / out["raw.check_xy_m"])
    return out


def pugging_chunk(
    cfg: dict, block: Block, recentre_px: float, rng: np.random.Generator, n: int
) -> dict:
    """Data snooping under mechanical pugging with another re-centring error (px)."""
    c2 = {**cfg, "pugging.recentre_px": recentre_px}
    adj = Adjuster(block)
    crit = float(D.norm_ppf(1 - cfg["snoop.alpha"] / 2))
    ws, wsc = snoop_weights(cfg)
    sim = Simulated(c2, block, rng, n, cfg["scan.dpi"], mechanical=True, uncorrected=False)
    ctrl, st, res0 = adj.adjust(
        sim, ("mechanical", "corrected"), cfg["control.many"], *paper_weights(cfg)
    )
    rej = snoop(
        st,
        sim.xm[("mechanical", "corrected")],
        ws,
        sim.ctrl_obs[:, ctrl],
        np.broadcast_to(wsc, (ctrl.size, 3)),
        res0.s,
        res0.R,
        res0.t,
        res0.X,
        block.is_pass,
        crit,
        cfg["snoop.max_reject"],
        cfg["snoop.test"] == "tau",
    )[0]
    return {"share_pct": 100.0 * rej[:, block.is_pass].sum(1) / block.is_pass.sum()}


def size_chunk(
    cfg: dict, block: Block, centre: np.ndarray, rng: np.random.Generator, n: int
) -> dict:
    """Another block size at the same point density (``tradeoff.block_control`` layout)."""
    adj = Adjuster(block)
    wo, wc = paper_weights(cfg)
    sim = Simulated(cfg, block, rng, n, cfg["scan.dpi"], uncorrected=False)
    out: dict[str, np.ndarray] = {}
    ctrl, _, res = adj.adjust(sim, ("digital", "corrected"), cfg["tradeoff.block_control"], wo, wc)
    accuracy(block, ctrl, res, out, "size", centre=centre)
    return out


def sweep_chunk(cfg: dict, block: Block, insets, rng: np.random.Generator, n: int) -> dict:
    """The unprinted five-point layout at each of ``insets`` (the region's input vectors): the
    5-control pass adjusted once per layout on the same simulated blocks."""
    adj = Adjuster(block)
    wo, wc = paper_weights(cfg)
    sim = Simulated(cfg, block, rng, n, cfg["scan.dpi"], uncorrected=False)
    out: dict[str, np.ndarray] = {}
    _, _, start = adj.adjust(sim, ("digital", "corrected"), cfg["control.many"], wo, wc)
    for i, u in enumerate(insets):
        ctrl, _, res = adj.adjust(
            sim, ("digital", "corrected"), five_control(block, u), wo, wc, start=start
        )
        accuracy(block, ctrl, res, out, f"inset{i}")
    return out
