"""Matplotlib set-up shared by all figures: Agg backend, deterministic PNG output."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from sim.mc.storage import atomic_path  # noqa: E402

__all__ = ["plt", "save"]

plt.rcParams.update(
    {
        "figure.dpi": 100,
        "savefig.dpi": 110,
        "font.size": 9,
        "axes.grid": True,
        "grid.alpha": 0.3,
        "svg.hashsalt": "sim",
    }
)


def save(fig, path: str | Path) -> Path:
    """Save ``fig`` as PNG without a timestamp or version stamp, then close it."""
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", metadata={"Software": None}, bbox_inches="tight")
    plt.close(fig)
    return path
