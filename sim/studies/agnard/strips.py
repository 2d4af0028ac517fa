"""Whether a block's strips overlap and are tied (``agnard_block``, seed
``003_5ce730a990a7ebc5.txt``): rules of ``sim check`` that name ``block.sidelap``.

Strip ``s`` is flown ``s * D`` across, ``D = W (1 - block.sidelap)`` with ``W`` the ground
width of the format, and a point belongs to a model when it images inside ``block.usable`` of
the half format: adjacent strips' measured areas overlap by ``W (sidelap + usable - 1)``. At
``sidelap + usable <= 1`` they share no band, and the signalised points between them lie in
no model (:func:`check_strip_overlap`; the block builder refused it naming
``block.relief_m``, a key at its default, and the trade-off's blocks of several strips
reached it with ``block.strips = 1`` as a bare ``ValueError``). With a narrow band the strips
overlap but no pass-point row (they reach 0.85 of the usable half width) lies in both: each
strip's datum then rests on its own control, and a layout of few points (the region's five)
leaves it singular at any control weight (:func:`tie_words`; it was refused naming
``weights.control_z`` at the paper's weights, "keep the ratio above about 6.8e+07").
"""

from __future__ import annotations

import numpy as np

from sim.mc.config import ConfigError

__all__ = ["check_strip_overlap", "tie_words"]


def _several_strips(cfg: dict) -> str | None:
    """The key that asks for a block of two strips or more, if any."""
    if cfg["block.strips"] >= 2:
        return "block.strips"
    if max(cfg["tradeoff.block_strips"]) >= 2:
        return "tradeoff.block_strips"
    return None


def check_strip_overlap(cfg: dict) -> None:
    """Refuse strips whose measured areas do not overlap (a gap of points in no model)."""
    key, s, u = _several_strips(cfg), cfg["block.sidelap"], cfg["block.usable"]
    if key is not None and s + u <= 1.0:
        raise ConfigError(
            "block.sidelap",
            f"{s:g} with block.usable {u:g}: adjacent strips' measured areas do not overlap "
            f"(sidelap + usable = {s + u:g}, not above 1), so the signalised points between "
            f"them lie in no model; raise block.sidelap above {1.0 - u:g} (the blocks of "
            f"several strips: {key})",
        )


def tie_words(cfg: dict, block, layout: str) -> str:
    """The refusal of a block of several strips (``block``) singular at any control weight."""
    strip = block.obs_model // block.models
    both = np.zeros(block.n_points, bool)
    for s in range(block.strips - 1):  # pass points seen from strip s and from strip s + 1
        seen = [np.isin(np.arange(block.n_points), block.obs_point[strip == t]) for t in (s, s + 1)]
        both |= seen[0] & seen[1]
    n = int((both & block.is_pass).sum())
    tied = (
        "no pass-point row (they reach 0.85 of the usable half width) lies in two strips"
        if n == 0
        else f"only {n} pass points lie in two strips"
    )
    return (
        f"{cfg['block.sidelap']:g} with block.usable {cfg['block.usable']:g}: {tied}, so "
        f"adjacent strips are barely tied, and with the control of {layout} the block's normals are "
        "singular even at 1000 times the paper's control weights (not a matter of "
        "weights); raise block.sidelap"
    )
