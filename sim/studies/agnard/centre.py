"""The blocks of the block-size trade-off (``tradeoff.block_strips`` x ``tradeoff.block_models``,
at the main block's density of signalised points) and the rule on their 'centre':
``tradeoff.centre_points`` check points nearest a block's centre are a centre only while they
are at most half of its check points (the signalised points not in its
``tradeoff.block_control`` layout). At ``tradeoff.centre_points = 10000`` the 'centre' of every
block compared was all of its check points, and its accuracy 'at the centre' the same numbers
as the whole block's, printed in two columns of ``tradeoff_block.parquet`` and README.md. A
compared block of fewer than 2 check points (``block.ground_points = 22``: the 1 x 8 block's
every point in its control) has no centre at all and is named as such."""

from __future__ import annotations

from functools import lru_cache

from sim.instruments.block.layout import Block, select_control
from sim.mc.config import ConfigError

__all__ = ["check_centre_points", "ground_density"]

#: the keys of block_of that shape a compared block (its strips and models are its own)
BLOCK_KEYS = (
    "block.scale",
    "block.focal_mm",
    "block.base_mm",
    "block.format_mm",
    "block.sidelap",
    "block.usable",
    "block.ground_points",
    "block.pass_rows",
    "block.relief_m",
    "block.layout_seed",
)


def ground_density(block: Block) -> float:
    """Signalised points per km^2 of ``block`` (the compared blocks have the same)."""
    x0, x1, y0, y1 = block.extent()
    return block.n_ground / ((x1 - x0) * (y1 - y0) * 1e-6)


@lru_cache(maxsize=64)
def _check_points(values: tuple, strips: int, models: int, density: float, control: str) -> int:
    """Check points of a compared block (built as the run builds it)."""
    from sim.studies.agnard.schema import block_of  # the schema calls this module

    b = block_of(dict(zip(BLOCK_KEYS, values)), strips, models, density=density)
    return b.n_ground - len(set(select_control(b, control).tolist()))


def check_centre_points(cfg: dict, block: Block) -> None:
    """Refuse a ``tradeoff.centre_points`` above half the check points of a compared block."""
    k, control = cfg["tradeoff.centre_points"], cfg["tradeoff.block_control"]
    values, d = tuple(cfg[x] for x in BLOCK_KEYS), ground_density(block)
    counts = []
    for s, m in zip(cfg["tradeoff.block_strips"], cfg["tradeoff.block_models"]):
        try:
            counts.append((_check_points(values, s, m, d, control), s, m))
        except ValueError as e:  # the builder's, of a block compared: named as the main block's
            raise ConfigError(
                "block.relief_m",
                f"the {s} x {m} block compared (tradeoff.block_strips, tradeoff.block_models): "
                f"{e} (or raise block.sidelap)",
            ) from None
    n, s, m = min(counts)
    if n < 2:  # no centre of at most half its check points: the block, not the centre
        raise ConfigError(
            "tradeoff.block_models",
            f"the {s} x {m} block compared (tradeoff.block_strips, tradeoff.block_models) has "
            f"{n} check points at the main block's density of signalised points "
            f"(block.ground_points), the rest in its {control!r} control "
            "(tradeoff.block_control): it needs at least 2 to state an accuracy at the centre; "
            "compare larger blocks or raise block.ground_points",
        )
    if 2 * k > n:  # the block of the fewest check points, so that the bound given is one
        raise ConfigError(
            "tradeoff.centre_points",
            f"{k} check points nearest the centre of the {s} x {m} block compared "
            f"(tradeoff.block_strips, tradeoff.block_models) are more than half of its {n} "
            f"check points ({control!r} control, tradeoff.block_control): its accuracy "
            f"'at the centre' would be that of most of the block; give at most {n // 2}",
        )
