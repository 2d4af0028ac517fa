"""matplotlib, loaded on first use: the suite's one door to it.

A process that draws no figure (``sim check``, ``sim show``, a run with ``--no-figures``, a
pool or Dask worker, ``make verify``'s re-runs) never pays for importing matplotlib, about
0.5 s of CPU per process. The first attribute read from :data:`pyplot` (or any other module
here) sets the Agg backend and the suite's style (:data:`STYLE`), then imports the module;
after that, every read is a dictionary lookup in the imported module.
"""

from __future__ import annotations

import importlib
import os
import threading
from types import ModuleType
from typing import Any

__all__ = ["pyplot", "ticker", "collections", "lazy", "STYLE"]

#: the suite's figure style: deterministic PNGs (no hash salt from the run), small fonts
STYLE = {
    "figure.dpi": 100,
    "savefig.dpi": 110,
    "font.size": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "svg.hashsalt": "sim",
}

_lock = threading.Lock()  # brown_design draws its figures from threads
_set_up = False


def _setup() -> None:
    """Agg backend and :data:`STYLE`, once per process, before any matplotlib module loads.
    The user's ``MPLBACKEND`` is set aside while matplotlib loads (and put back): the suite
    draws only PNG files through Agg, and a value matplotlib does not know (``nosuch``)
    failed a run at its first figure, after every trial was computed."""
    global _set_up
    with _lock:
        if not _set_up:
            backend = os.environ.pop("MPLBACKEND", None)
            try:
                import matplotlib  # heavy: loaded here, on a figure's first use
            finally:
                if backend is not None:
                    os.environ["MPLBACKEND"] = backend
            matplotlib.use("Agg")
            matplotlib.rcParams.update(STYLE)
            _set_up = True


class lazy:
    """A stand-in for the module ``name`` that imports it (after :func:`_setup`) when an
    attribute is first read: ``lazy("matplotlib.ticker").FixedLocator``."""

    __slots__ = ("_name", "_module")

    def __init__(self, name: str) -> None:
        self._name = name
        self._module: ModuleType | None = None

    def _load(self) -> ModuleType:
        if self._module is None:
            _setup()
            self._module = importlib.import_module(self._name)
        return self._module

    def __getattr__(self, attr: str) -> Any:
        return getattr(self._load(), attr)

    def __repr__(self) -> str:
        return f"<lazy {self._name}>"


#: ``matplotlib.pyplot``
pyplot = lazy("matplotlib.pyplot")
#: ``matplotlib.ticker``
ticker = lazy("matplotlib.ticker")
#: ``matplotlib.collections``
collections = lazy("matplotlib.collections")
