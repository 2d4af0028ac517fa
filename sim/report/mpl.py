"""matplotlib, loaded on first use: the suite's one door to it.

A process that draws no figure (``sim check``, ``sim show``, a run with ``--no-figures``, a
pool or Dask worker, ``make verify``'s re-runs) never pays for importing matplotlib, about
0.5 s of CPU per process. The first attribute read from :data:`pyplot` (or any other module
here) imports matplotlib and sets the suite's style (:data:`STYLE`); after that, every read
is a dictionary lookup in the imported module.

The suite's figures never go through ``matplotlib.pyplot``: :data:`pyplot` is the part of it
the suite uses (``subplots``, ``figure``, ``close``, ``Rectangle``), built on
``matplotlib.figure.Figure`` with an Agg canvas of its own. Called from the Python API inside
a user's notebook or script, a run so leaves the user's backend and open figures alone
(``matplotlib.use("Agg")`` switched the caller's pyplot to Agg and closed every figure it had
open), and :func:`kept` puts the user's ``rcParams`` back after the run.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import sys
import threading
from types import ModuleType, SimpleNamespace
from typing import Any, Iterator

__all__ = ["pyplot", "ticker", "collections", "lazy", "STYLE", "kept"]

#: the suite's figure style: deterministic PNGs (no hash salt from the run), small fonts
STYLE = {
    # one resolution for the layout pass, the legend placement and the figure check and for
    # the PNG: at 100 against 110 a legend placed with 4 px to spare could touch a point
    "figure.dpi": 110,
    "savefig.dpi": 110,
    "font.size": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "svg.hashsalt": "sim",
}

_lock = threading.Lock()  # brown_design draws its figures from threads
_set_up = False


def _setup() -> None:
    """:data:`STYLE`, once per process, before any matplotlib module loads. The user's
    ``MPLBACKEND`` is set aside while matplotlib loads (and put back): the suite draws only
    PNG files through an Agg canvas of its own, and a value matplotlib does not know
    (``nosuch``) failed a run at its first figure, after every trial was computed. A value it
    knows stays the backend of the caller's own pyplot. No backend is chosen here."""
    global _set_up
    with _lock:
        if not _set_up:
            backend = os.environ.pop("MPLBACKEND", None)
            try:
                import matplotlib  # heavy: loaded here, on a figure's first use
            finally:
                if backend is not None:
                    os.environ["MPLBACKEND"] = backend
            if backend and matplotlib.rcParams._get_backend_or_none() is None:
                with contextlib.suppress(ValueError):  # nosuch: the suite draws through Agg
                    matplotlib.rcParams["backend"] = backend
            matplotlib.rcParams.update({**_defaults(matplotlib), **STYLE})
            _set_up = True


def _defaults(m: ModuleType) -> dict:
    """matplotlib's own defaults, the backend aside: what the suite draws over, never a
    ``matplotlibrc`` of the user's (in the working directory, ``MATPLOTLIBRC`` or
    ``~/.config/matplotlib``), which changed every PNG of ``sim run`` and of the API."""
    return {k: v for k, v in m.rcParamsDefault.items() if k != "backend"}


def _figure(**kw: Any):
    """``pyplot.figure(**kw)`` without pyplot: a Figure on an Agg canvas of its own, in no
    figure list of pyplot's (so never shown, and left to the garbage collector)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(**kw)
    FigureCanvasAgg(fig)
    return fig


#: the keywords of ``pyplot.subplots`` that go to ``Figure.subplots``; the rest make the figure
_GRID = (
    "sharex",
    "sharey",
    "squeeze",
    "width_ratios",
    "height_ratios",
    "subplot_kw",
    "gridspec_kw",
)


def _subplots(nrows: int = 1, ncols: int = 1, **kw: Any):
    """``pyplot.subplots(...)`` without pyplot (:func:`_figure`)."""
    fig = _figure(**{k: v for k, v in kw.items() if k not in _GRID})
    return fig, fig.subplots(nrows, ncols, **{k: v for k, v in kw.items() if k in _GRID})


def _close(fig: Any = None) -> None:
    """``pyplot.close``: a figure of :func:`_figure` is in no list; nothing to do."""


def _rectangle(*args: Any, **kw: Any):
    from matplotlib.patches import Rectangle

    return Rectangle(*args, **kw)


_runs: list = []  # the runs inside :func:`kept` in this process (threads of the API)
_restore: list = []  # what puts the caller's rcParams back when the last of them ends


@contextlib.contextmanager
def kept() -> Iterator[None]:
    """The caller's ``rcParams`` as they were before, whatever the suite set inside (a run of
    the Python API in a user's process: :data:`STYLE` is the suite's, not the user's next
    plot's). Inside, the suite's figures are drawn in :data:`STYLE` over matplotlib's
    defaults, whatever the caller had set, so a PNG is the same as ``sim run``'s. Runs in
    several threads at once share one such state, put back when the last of them ends."""
    with _lock:
        _runs.append(None)
        if len(_runs) == 1:
            _restore[:] = [_take_over()]
    try:
        yield
    finally:
        with _lock:
            _runs.pop()
            if not _runs:
                _restore.pop()()


def _take_over():
    """Set the suite's style (if matplotlib is loaded; else :func:`_setup` sets it on the first
    figure) and return the function that puts the caller's state back. Under :data:`_lock`."""
    global _set_up
    m = sys.modules.get("matplotlib")
    if m is None:  # nothing of the caller's to keep: after the run, matplotlib's defaults

        def back() -> None:
            global _set_up
            loaded = sys.modules.get("matplotlib")
            if loaded is not None and _set_up:  # as matplotlib loaded them (a matplotlibrc)
                loaded.rcParams.update(
                    {k: v for k, v in loaded.rcParamsOrig.items() if k != "backend"}
                )
                _set_up = False

        return back
    context = m.rc_context({**_defaults(m), **STYLE})
    context.__enter__()
    _set_up = True  # the style is set here, for the runs only

    def back() -> None:
        global _set_up
        context.__exit__(None, None, None)
        _set_up = False

    return back


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


class _Pyplot:
    """The part of ``matplotlib.pyplot`` the suite uses, without pyplot's global state; the
    first use loads matplotlib (:func:`_setup`)."""

    def _load(self) -> SimpleNamespace:
        _setup()
        return _PYPLOT

    def __getattr__(self, attr: str) -> Any:
        return getattr(self._load(), attr)

    def __repr__(self) -> str:
        return "<the suite's pyplot: subplots, figure, close, Rectangle>"


_PYPLOT = SimpleNamespace(subplots=_subplots, figure=_figure, close=_close, Rectangle=_rectangle)
#: ``matplotlib.pyplot``'s ``subplots``, ``figure``, ``close`` and ``Rectangle``, without pyplot
pyplot = _Pyplot()
#: ``matplotlib.ticker``
ticker = lazy("matplotlib.ticker")
#: ``matplotlib.collections``
collections = lazy("matplotlib.collections")
