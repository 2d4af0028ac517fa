"""Chunk functions of ``agnard_block`` (seed ``003_5ce730a990a7ebc5.txt``).

Each is a module-level function ``f(cfg, block, ..., rng, n)``; the run hands the runner
``functools.partial(f, cfg, block, ...)`` (plain, picklable arguments), so chunks go to
process pools and Dask workers and are stored for resumption. Everything a chunk produces
leaves it through its returned arrays: per-trial values (leading axis ``n``) and per-chunk
sums or examples (leading axis 1, keys ``chunk.*``). Lengths in metres.
"""

from __future__ import annotations

from dataclasses import replace
from functools import partial

import numpy as np

from sim.instruments.block.centres import with_centres
from sim.instruments.block.data_snooping import snoop
from sim.instruments.block.layout import Block
from sim.lsq import distributions as D
from sim.studies.agnard.schema import five_control, model_sigmas, paper_weights, snoop_weights
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


def _snoop(cfg: dict, block: Block, st, ctrl: np.ndarray, sim: Simulated, key, start):
    """Baarda's data snooping of the pass points (``snoop.*``: alpha two-sided, at most
    ``snoop.max_reject`` rejections, w- or tau-test) on the model coordinates ``sim.xm[key]``
    with the control ``ctrl``, started from the adjustment ``start``; returns what
    :func:`sim.instruments.block.data_snooping.snoop` returns (rejections first)."""
    crit = float(D.norm_ppf(1 - cfg["snoop.alpha"] / 2))
    ws, wsc = snoop_weights(cfg)
    return snoop(
        st,
        sim.xm[key],
        ws,
        sim.ctrl_obs[:, ctrl],
        np.broadcast_to(wsc, (ctrl.size, 3)),
        start.s,
        start.R,
        start.t,
        start.X,
        block.is_pass,
        crit,
        cfg["snoop.max_reject"],
        cfg["snoop.test"] == "tau",
    )


def _layout_passes(cfg: dict, block: Block, adj: Adjuster, sim: Simulated, out: dict) -> dict:
    """The pass without scanner correction (``control.table1``) and the corrected pass of
    every layout; per chunk, trial 0's and the summed check-point errors (m) of the 5- and
    21-control passes. Returns the corrected adjustments by layout."""
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
    return done


def _first_pass(cfg: dict, block: Block, adj: Adjuster, sim: Simulated, res21, out: dict):
    """The first pass with weak control (started from the 21-control solution of the same
    blocks): rms of the pass-point residuals (m)."""
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


def _snooping(cfg: dict, block: Block, adj: Adjuster, sim: Simulated, res21, n: int, out: dict):
    """Data snooping under digital and mechanical pugging: pass points rejected (count and
    share), sigma0, gross errors planted and found."""
    ctrl, st = adj.structure(cfg["control.many"])
    n_pass = int(block.is_pass.sum())
    for mode in ("digital", "mechanical"):
        rej, s0, _, _ = _snoop(cfg, block, st, ctrl, sim, (mode, "corrected"), res21)
        out[f"snoop_{mode}.rejected"] = rej[:, block.is_pass].sum(1)
        out[f"snoop_{mode}.share_pct"] = 100.0 * out[f"snoop_{mode}.rejected"] / n_pass
        out[f"snoop_{mode}.sigma0"] = s0
        g = np.zeros((n, block.n_points), bool)
        for_t, for_k = np.nonzero(sim.gross[mode])
        g[for_t, block.obs_point[for_k]] = True
        out[f"snoop_{mode}.gross_points"] = g.sum(1)
        out[f"snoop_{mode}.gross_found"] = (g & rej).sum(1)


def main_chunk(cfg: dict, block: Block, rng: np.random.Generator, n: int) -> dict:
    """The 2 x 8 block: every adjustment of the paper on the same trials, the control
    layouts, the first pass, data snooping under digital and mechanical pugging; and, per
    chunk, trial 0's and the summed check-point errors of the 5- and 21-control passes (for
    the figures)."""
    adj = Adjuster(block)
    sim = Simulated(cfg, block, rng, n, cfg["scan.dpi"], mechanical=True)
    out: dict[str, np.ndarray] = {}
    done = _layout_passes(cfg, block, adj, sim, out)
    res21 = done[cfg["control.many"]]
    _first_pass(cfg, block, adj, sim, res21, out)
    _snooping(cfg, block, adj, sim, res21, n, out)
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
    sim = Simulated(c2, block, rng, n, cfg["scan.dpi"], mechanical=True, uncorrected=False)
    key = ("mechanical", "corrected")
    ctrl, st, res0 = adj.adjust(sim, key, cfg["control.many"], *paper_weights(cfg))
    rej = _snoop(cfg, block, st, ctrl, sim, key, res0)[0]
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


def sweep_chunk(
    cfg: dict, block: Block, insets, rng: np.random.Generator, n: int, centres=(False,)
) -> dict:
    """The unprinted five-point layout at each of ``insets`` (the region's input vectors): the
    5-control pass adjusted once per layout on the same simulated blocks, for each option of
    ``centres``: without (keys ``inset<i>.*``) and with the models' projection centres as
    model points (keys ``centres.inset<i>.*``; :mod:`sim.instruments.block.centres`, an
    error of a model point's size, the model points' weight). The centres' errors are drawn
    after the blocks, so the blocks are the same either way (common random numbers)."""
    key = ("digital", "corrected")
    wo, wc = paper_weights(cfg)
    sim = Simulated(cfg, block, rng, n, cfg["scan.dpi"], uncorrected=False)
    out: dict[str, np.ndarray] = {}
    adj = Adjuster(block)
    _, _, start = adj.adjust(sim, key, cfg["control.many"], wo, wc)
    if True in centres:
        sxy, sz = model_sigmas(cfg)
        cb = with_centres(block)
        sim_c = sim.centred(cb, rng, np.array([sxy, sxy, sz]), key)
        adj_c = Adjuster(cb.block)
        _, _, start_c = adj_c.adjust(
            sim_c, key, cfg["control.many"], wo, wc, start=replace(start, X=cb.extend(start.X))
        )
    for c in centres:
        a, s, s0, pre = (adj_c, sim_c, start_c, "centres.") if c else (adj, sim, start, "")
        for i, u in enumerate(insets):
            ctrl, _, res = a.adjust(s, key, five_control(block, u), wo, wc, start=s0)
            accuracy(s.block, ctrl, res, out, f"{pre}inset{i}")
    return out


def table1_chunk(
    cfg: dict,
    block: Block,
    scanners,
    rng: np.random.Generator,
    n: int,
    five=(),
    pairs=(),
    rejections: bool = False,
) -> dict:
    """Table 1 and Tables 2-3's 21-control pass at each of ``scanners`` (the scanner region's
    input vectors: dicts of ``scan.*`` overrides): ``n`` blocks adjusted with the
    ``control.table1`` layout without and with the grid correction, and (corrected) with the
    ``control.many`` layout (the same adjustment when the two layouts agree). The rms (m) at
    control and check points, keys ``s<i>.without.*``, ``s<i>.with.*`` (X, Y) and
    ``s<i>.many.*`` (X, Y, XY, Z), the first pass's pass-point rms (XY, Z) started from it,
    ``s<i>.first.*``; and the configured scanner's ``control.many`` and first passes on the
    same blocks, keys ``cfg.many.*``, ``cfg.first.*``. Every vector draws its blocks from the same two seeds
    (common random numbers, the grid's node noise on a stream of its own:
    :class:`~sim.studies.agnard.simulate.Simulated`), so the vectors differ by their inputs,
    not by their luck, and each is paired block by block with the configured scanner
    (:mod:`sim.studies.agnard.paired`). On the same blocks, started from each scanner's
    21-control solution: with ``rejections``, the pass points digital pugging's data snooping removes (keys
    ``cfg.snoop.rejected``, ``s<i>.snoop.rejected``: :mod:`sim.studies.agnard.paired_count`),
    and the 5-control pass at the layout points ``five`` ((inset, with centres) pairs; the
    configured scanner at every one, keys ``cfg.five<l>.*``, vector ``i`` at the indices
    ``pairs[i]``, keys ``s<i>.five<l>.*``; the projection centres' errors from a seed of their
    own, the same for every scanner: :mod:`sim.studies.agnard.joint`)."""
    adj = Adjuster(block)
    wo, wc = paper_weights(cfg)
    seed, grid_seed = (int(s) for s in rng.integers(2**63, size=2))
    centre_seed = int(rng.integers(2**63))  # drawn after: the two seeds above stay as they were
    out: dict[str, np.ndarray] = {}
    cen = _CentredPasses(cfg, block, five, centre_seed)

    def blocks(over: dict) -> Simulated:
        return Simulated(
            {**cfg, **over},
            block,
            np.random.default_rng(seed),
            n,
            cfg["scan.dpi"],
            grid_rng=np.random.default_rng(grid_seed),
        )

    def keep(tag: str, ctrl, res) -> None:
        acc: dict[str, np.ndarray] = {}
        accuracy(block, ctrl, res, acc, "a")
        for w in ("ctrl", "check"):
            for ax in ("x", "y", "xy", "z"):
                out[f"{tag}.{w}_{ax}_m"] = acc[f"a.{w}_{ax}_m"]

    def first(tag: str, sim: Simulated, res21) -> None:  # the first pass on the same blocks
        acc: dict[str, np.ndarray] = {}
        _first_pass(cfg, block, adj, sim, res21, acc)
        for ax in ("xy", "z"):
            out[f"{tag}.first.pass_{ax}_m"] = acc[f"first.pass_{ax}_m"]

    base = blocks({})
    ctrl, _, res = adj.adjust(base, ("digital", "corrected"), cfg["control.many"], wo, wc)
    keep("cfg.many", ctrl, res)
    first("cfg", base, res)
    more = partial(_more, cfg, block, adj, cen, rejections, out)
    more("cfg", base, res, range(len(five)))
    for i, over in enumerate(scanners):
        sim = blocks(over)
        res = None
        passes = [("raw", "without", cfg["control.table1"])]
        passes.append(("corrected", "with", cfg["control.table1"]))
        if cfg["control.many"] != cfg["control.table1"]:
            passes.append(("corrected", "many", cfg["control.many"]))
        for key, tag, lay in passes:
            ctrl, _, res = adj.adjust(sim, ("digital", key), lay, wo, wc, res)
            keep(f"s{i}.{tag}", ctrl, res)
            if tag == "with" and len(passes) == 2:
                keep(f"s{i}.many", ctrl, res)
        first(f"s{i}", sim, res)  # res: the control.many pass
        more(f"s{i}", sim, res, pairs[i] if pairs else ())
    return out


def _more(cfg, block, adj, cen, rejections: bool, out: dict, tag: str, sim, res21, which):
    """On the blocks ``sim`` of one scanner of :func:`table1_chunk`, started from its
    21-control solution ``res21``: the digital snooping's rejected pass points (with
    ``rejections``) and the 5-control pass at the layout points ``which`` (``cen``)."""
    if rejections:
        ctrl, st = adj.structure(cfg["control.many"])
        rej = _snoop(cfg, block, st, ctrl, sim, ("digital", "corrected"), res21)[0]
        out[f"{tag}.snoop.rejected"] = rej[:, block.is_pass].sum(1)
    for j in which:
        b, ctrl, r = cen.adjust(adj, sim, res21, j)
        acc: dict[str, np.ndarray] = {}
        accuracy(b, ctrl, r, acc, "a")
        for w in ("ctrl", "check"):
            for ax in ("x", "y", "xy", "z"):
                out[f"{tag}.five{j}.{w}_{ax}_m"] = acc[f"a.{w}_{ax}_m"]


class _CentredPasses:
    """The 5-control passes of :func:`table1_chunk` at the layout points ``five`` ((inset,
    with centres)), started from a scanner's 21-control solution; with centres, the blocks
    get their projection centres as model points (:mod:`sim.instruments.block.centres`),
    the centres' errors drawn from ``seed`` for every scanner alike (common random numbers)."""

    def __init__(self, cfg: dict, block: Block, five, seed: int):
        self.cfg, self.block, self.five, self.seed = cfg, block, tuple(five), seed
        self.w = paper_weights(cfg)
        self.sigma = np.array(model_sigmas(cfg))[[0, 0, 1]]
        self._cb = self._adj = None

    def adjust(self, adj: Adjuster, sim: Simulated, res21, j: int):
        """Layout point ``j`` on ``sim``: (the block adjusted, control indices, result)."""
        inset, centres = self.five[j]
        key = ("digital", "corrected")
        ctrl = five_control(self.block, float(inset))
        if not centres:
            _, _, r = adj.adjust(sim, key, ctrl, *self.w, start=res21)
            return self.block, ctrl, r
        if self._cb is None:
            self._cb = with_centres(self.block)
            self._adj = Adjuster(self._cb.block)
        cb = self._cb
        sc = sim.centred(cb, np.random.default_rng(self.seed), self.sigma, key)
        start = replace(res21, X=cb.extend(res21.X))
        _, _, r = self._adj.adjust(sc, key, ctrl, *self.w, start=start)
        return cb.block, ctrl, r
