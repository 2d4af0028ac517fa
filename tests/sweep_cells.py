"""The columns every cell row of a sweep's ``sweep.parquet`` holds (as ``sim run`` writes them
for feasible cells of one replicate), for tests that build a sweep's results by hand."""

from __future__ import annotations


def cell_columns(values: dict[str, list]) -> dict[str, list]:
    """``values`` (a list per swept key, one entry per cell) with the columns of the cells'
    identity: number, replicate 0, label, seed, feasible, no reason."""
    n = len(next(iter(values.values())))
    return {
        "cell": list(range(n)),
        "replicate": [0] * n,
        "label": [f"cell{i:04d}_r0" for i in range(n)],
        "seed": list(range(1, n + 1)),
        "feasible": [True] * n,
        "reason": [""] * n,
        **values,
    }
