"""How the texts of ``salsig_encoders`` name the run's own numbers: the level of its detection
tests (``analysis.alpha``), its vertical correction factor (``zscale.s_mm_per_digit`` over
``b8.sx_mm_per_digit``: the paper's 12.500/12.700), its true B8 affine (FIG. 3's where
``b8.*`` is) and its unprinted error sigmas, never the paper's where the run changed them."""

from __future__ import annotations

from sim.studies.salsig.printed import FIG3_PRINTED
from sim.studies.salsig.schema import SCHEMA


def level_text(cfg: dict) -> str:
    """``"95 %"`` at ``analysis.alpha = 0.05``."""
    return f"{100 * (1 - cfg['analysis.alpha']):g} %"


def correction(cfg: dict) -> str:
    """The factor z is multiplied by after the calibration, as the paper writes it
    (``"12.500/12.700"`` for its z and x scales)."""
    return f"{cfg['zscale.s_mm_per_digit']:.3f}/{cfg['b8.sx_mm_per_digit']:.3f}"


def b8_printed(cfg: dict) -> bool:
    """The run's true B8 affine (SX, SY, E) is FIG. 3's printed one."""
    run = (cfg["b8.sx_mm_per_digit"], cfg["b8.sy_mm_per_digit"], cfg["b8.e_arcsec"])
    return run == FIG3_PRINTED


def sigma_set(cfg: dict, key: str, target: str) -> str:
    """Why ``key`` (an unprinted error sigma, um) has its value: its default is set to
    reproduce the paper's ``target``; a run with another value says so."""
    if cfg[key] == SCHEMA[key].default:
        return f"{key} is not printed: set to reproduce the {target} (an input)"
    return (
        f"{key} is not printed: this run's {cfg[key]:g} um (the default "
        f"{SCHEMA[key].default:g} reproduces the {target})"
    )
