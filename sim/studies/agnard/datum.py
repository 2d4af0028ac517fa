"""Whether the control weights hold the block's datum well enough for the engine to solve it
(``sim check`` of ``agnard_block``, seed ``003_5ce730a990a7ebc5.txt``).

The block of independent models has no datum of its own: a similarity of the whole block
(and, the residuals being in ground units, a shrinking of it) is held by the control alone.
As the control weight falls against the pass weight (paper: 3 and 2 against 0.1) the
smallest eigenvalue of the reduced normals falls with it, in proportion (measured on the
2 x 8 block, 21 control: a scaled reciprocal condition number of 4.8e-2 times the ratio, from
a ratio of 1e-2 down to 1e-14). Down to the engine's singularity rule the adjustment is a
legitimate if weak one (the block shrinks towards its control: check errors of metres at a
ratio of 1e-4, of a kilometre at 1e-8, large but finite and growing as the weight falls);
below it the engine flags every trial singular and leaves its starting values, which a chunk
would then publish as the block's accuracy: noise of a metre (the starting points' error),
not an adjustment. So :func:`check_datum` applies the engine's own rule
(:func:`sim.lsq.normals.scaled_rcond` against :data:`sim.lsq.normals.RCOND`) to the reduced
normals of the noise-free block, for every control layout and weight pair the study adjusts
the block with, and refuses a configuration the engine could not solve.

The linearisation is taken at the truth with every model in the ground frame: the engine's
corrections (``R <- R(dtheta) R``, ``t' <- t' + dt``) act in the ground frame, so its
reduced normals do not depend on the models' random frames. For the configured layouts the
trials' own condition numbers lie within 1 % of this one (measured); the factor
:data:`MARGIN` keeps them clear of the rule. The region's five-point layouts are checked
too (:func:`region_insets`): with the outer points moved in (inset 0.45) the noise-free
block is far weaker than a noisy trial (2.5e-12 against 1.1e-10 at a ratio of 1e-8,
measured): there the models' 5 cm of noise, not the control, holds the weakest direction,
so a trial that passes the rule publishes a datum held by noise, and the noise-free block
decides.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np

from sim.instruments.block.independent_models import BlockStructure, SimilarityModel
from sim.instruments.block.layout import Block
from sim.lsq import groups
from sim.lsq.group_solve import dense, scaled
from sim.lsq.normals import RCOND, scaled_rcond
from sim.mc.config import ConfigError
from sim.studies.agnard.strips import tie_words

__all__ = ["MARGIN", "DENSE_MAX", "datum_rcond", "region_insets", "check_datum"]

#: a configuration is refused when its noise-free block's scaled reciprocal condition number
#: is not above MARGIN x RCOND (the trials' own numbers lie within 1 % of it, measured)
MARGIN = 2.0

#: largest reduced normals (unknowns) whose condition number a refusal prints (a dense
#: eigenvalue problem; 200 models)
DENSE_MAX = 1400


def datum_rcond(block: Block, ctrl: np.ndarray, w_pass, w_ctrl, rcond: float = RCOND):
    """The engine's singularity rule (its own solve, dense or sparse, at ``rcond``) on the
    reduced normals of the noise-free ``block`` with control points ``ctrl``, model-point
    weights ``w_pass`` (3,) and control weights ``w_ctrl`` (3,): ``(regular, rc)``, ``rc``
    the scaled reciprocal condition number where the block is not regular and has at most
    :data:`DENSE_MAX` reduced unknowns, else None."""
    st = BlockStructure(block.obs_model, block.obs_point, ctrl, block.n_models, block.n_points)
    X = block.points[None]
    xm = X[:, block.obs_point]  # every model in the ground frame: s = 1, R = I
    c = groups.scatter(st.S_model, xm) / np.maximum(
        groups.scatter(st.S_model, np.ones(xm.shape[:2] + (1,))), 1
    )
    K = block.obs_point.size
    model = SimilarityModel(
        st,
        xm,
        c,
        np.broadcast_to(np.asarray(w_pass, float), (1, K, 3)),
        X[:, ctrl],
        np.broadcast_to(np.asarray(w_ctrl, float), (ctrl.size, 3)),
    )
    theta = np.concatenate(
        [np.ones((1, st.n_models, 1)), np.tile(np.eye(3).ravel(), (1, st.n_models, 1)), c], -1
    )
    red = groups.reduce(st, model.linearize(X, theta), rcond)
    _, ok = groups.solve(st, red, "auto", rcond)
    if ok.all() or st.n_models * 7 > DENSE_MAX:
        return bool(ok.all()), None
    Ns, _ = scaled(dense(st, red.blocks))
    return False, float(scaled_rcond(Ns)[0]) if red.ok.all() else 0.0


def region_insets() -> list[float]:
    """The ends and the middle of the five-point layout's inset that ``region.toml``
    explores (the datum weakens as the outer points move in: at its far end, 0.45, the
    condition number is under half the ``five`` layout's)."""
    with open(Path(__file__).with_name("region.toml"), "rb") as f:
        u = tomllib.load(f)["inputs"]["five_inset_1"]
    return [u["low"], 0.5 * (u["low"] + u["high"]), u["high"]]


def _weight_sets(cfg: dict, layouts: dict) -> list[tuple[str, dict, dict]]:
    """(pass key, {control key: its weight per axis (3,)}, layouts) of every weighting the
    study adjusts its block with: the paper's weights on every layout, the first pass's on
    the 21-control layout."""
    xy, z = cfg["weights.control_xy"], cfg["weights.control_z"]
    fc = cfg["weights.first_pass_control"]
    many = cfg["control.many"]
    return [
        (
            "weights.pass",
            {"weights.control_xy": [xy, xy, 0.0], "weights.control_z": [0.0, 0.0, z]},
            layouts,
        ),
        (
            "weights.first_pass_pass",
            {"weights.first_pass_control": [fc] * 3},
            {many: layouts[many]},
        ),
    ]


def _geometry(cfg, block: Block, paper: dict, parts: dict, kp: str, ctrl, lay: str, rule) -> None:
    """Blame the strips, not the weights, when the layout ``lay`` leaves a block of several
    strips singular even at 1000 times the paper's control weights
    (:mod:`sim.studies.agnard.strips`)."""
    axes = [np.asarray(v, float) / cfg[k] * paper[k] for k, v in parts.items()]  # the paper's
    strong = 1e3 * np.sum(axes, axis=0) / paper[kp]
    if block.strips >= 2 and not datum_rcond(block, ctrl, np.ones(3), strong, rule)[0]:
        raise ConfigError("block.sidelap", tie_words(cfg, block, lay))


def check_datum(cfg: dict, block: Block, paper: dict, layouts: dict) -> None:
    """Refuse control weights so small against the pass weight that the engine would find
    the block's normals singular (see the module doc): one line naming the control weight,
    its ratio to the pass weight (``paper``: the defaults of the weights) and the smallest
    ratio the engine solves. ``layouts``: {name: control point indices} of every layout the
    block is adjusted with, ``control.many`` among them."""
    rule = MARGIN * RCOND
    for kp, parts, lays in _weight_sets(cfg, layouts):
        wp = cfg[kp]
        with np.errstate(over="ignore"):  # a ratio beyond a double: named below, not warned
            w_ctrl = np.sum([np.asarray(v, float) for v in parts.values()], axis=0) / wp
        if not np.all(np.isfinite(w_ctrl)):  # blamed on the weakest weight ("next to nothing")
            big = max(parts, key=lambda k: cfg[k])
            raise ConfigError(
                big,
                f"{cfg[big]:g} over {kp} ({wp:g}) is a weight ratio beyond a 64-bit float: "
                "make it smaller",
            )
        kc = min(parts, key=lambda k: cfg[k])  # the weakest control weight
        ratio = cfg[kc] / wp
        bad = []
        for lay, ctrl in lays.items():
            ok, rc = datum_rcond(block, ctrl, np.ones(3), w_ctrl, rule)
            if not ok:
                bad.append((-1.0 if rc is None else rc, lay))
        if not bad:
            continue
        rc, lay = min(bad)  # the weakest layout names the limit
        rc = None if rc < 0 else rc
        _geometry(cfg, block, paper, parts, kp, lays[lay], lay, rule)
        what = (
            "fail the engine's singularity rule"
            if rc is None
            else f"have a reciprocal condition number of {rc:.2g}"
        )
        # the condition number falls in proportion to the ratio (module doc)
        keep = "" if not rc else f"; keep the ratio above about {ratio * rule / rc:.2g}"
        raise ConfigError(
            kc,
            f"{cfg[kc]:g} is {ratio:.3g} times {kp} ({wp:g}; paper: "
            f"{paper[kc] / paper[kp]:g} times): the block's datum would rest on control "
            f"({lay}) that weighs next to nothing; its reduced normals scaled to unit "
            f"diagonal {what}, not above {MARGIN:g} x the engine's singularity limit "
            f"{RCOND:g}: the engine would flag adjustments singular and leave them at their "
            f"starting values, a metre off, published as check errors{keep}",
        )
