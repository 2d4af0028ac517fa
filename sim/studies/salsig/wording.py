"""How the texts of ``salsig_encoders`` name the run's own numbers: the level of its detection
tests (``analysis.alpha``) and its vertical correction factor (``zscale.s_mm_per_digit`` over
``b8.sx_mm_per_digit``: the paper's 12.500/12.700), never the paper's where the run changed them."""

from __future__ import annotations


def level_text(cfg: dict) -> str:
    """``"95 %"`` at ``analysis.alpha = 0.05``."""
    return f"{100 * (1 - cfg['analysis.alpha']):g} %"


def correction(cfg: dict) -> str:
    """The factor z is multiplied by after the calibration, as the paper writes it
    (``"12.500/12.700"`` for its z and x scales)."""
    return f"{cfg['zscale.s_mm_per_digit']:.3f}/{cfg['b8.sx_mm_per_digit']:.3f}"
