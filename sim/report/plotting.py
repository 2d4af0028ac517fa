"""Matplotlib set-up shared by all figures: Agg backend, deterministic PNG output, and the
layout check a figure can run on itself before it is saved (:func:`layout_problems`: text
over text, text over a data area, additive offset tick labels, missing titles, axis labels
or units), which the tests run on every figure a study draws (:func:`checking_figures`)."""

from __future__ import annotations

import json
import os
import re
import warnings
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from typing import Callable, Iterator, Sequence

import numpy as np

from sim.mc.config import ConfigError
from sim.mc.storage import atomic_path
from sim.report.drawing import DRAWING, drawing
from sim.report.figcheck import data_points, figure_facts, points_inside, reader_problems
from sim.report.mpl import pyplot as plt
from sim.report.mpl import ticker
from sim.standard_error import say

__all__ = [
    "plt",
    "save",
    "draw",
    "DRAWING",
    "layout_problems",
    "checking_figures",
    "without_figures",
    "figures_off",
    "figure_facts",
    "hist_bins",
    "UNITLESS",
]


#: words that mark an axis label as a dimensionless quantity (no unit needed)
UNITLESS = (
    "ratio",
    "count",
    "number",
    "share",
    "proportion",
    "probability",
    "fraction",
    "rate",
    "trials",
    "points",
    "index",
    "degree",
    "sets",
    "cells",
    "density",
    "frequency",
    "coverage",
    "factor",
    "speedup",
    "dilution",
    "p-value",
    "chi",
    "sigma0",
    "σ0",
    "z-score",
    "order",
    "rank",
    "claim",
    "step",
    "iteration",
    "plates",
    "samples",
    " per ",
    "readings",
    "observation",
)
_UNIT = re.compile(r"\(.+\)|\[.+\]|%|/|(?:\b|_)(mm2?|um|µm|m|cm|s|ppm|pct|arcsec|gon|deg|rad|px)\b")
_NUMBER = re.compile(r"^[\s$]*[-−+]?[\d.,]*\d(?:[eE][-−+]?\d+)?\s*(?:%|°|×10.*)?[\s$]*$")
_SLACK = 1.0  # pixels two boxes may share before they overlap


def _texts(fig, renderer) -> list[tuple[str, object, str]]:
    """``(what, Text, role)`` of every visible, non-empty text: role ``layout`` (titles, axis
    and tick labels, figure texts: placed by the layout, outside any data area) or ``label``
    (legend entries and texts placed in the data)."""
    out = []

    def add(what, t, role):
        if t is not None and t.get_visible() and t.get_text().strip():
            out.append((what, t, role))

    add("suptitle", getattr(fig, "_suptitle", None), "layout")
    add("supxlabel", getattr(fig, "_supxlabel", None), "layout")
    add("supylabel", getattr(fig, "_supylabel", None), "layout")
    sup = {id(getattr(fig, n, None)) for n in ("_suptitle", "_supxlabel", "_supylabel")}
    for t in fig.texts:
        if id(t) not in sup:  # the suptitle is one of the figure's texts
            add("figure text", t, "layout")
    for i, ax in enumerate(fig.axes):
        if not ax.get_visible():
            continue
        for t in (ax.title, ax._left_title, ax._right_title):
            add(f"axes {i} title", t, "layout")
        add(f"axes {i} x label", ax.xaxis.label, "layout")
        add(f"axes {i} y label", ax.yaxis.label, "layout")
        for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            lo, hi = sorted(axis.get_view_interval())
            locs = [*axis.get_majorticklocs(), *axis.get_minorticklocs()]
            labels = [*axis.get_majorticklabels(), *axis.get_minorticklabels()]
            for loc, t in zip(locs, labels):
                if lo - 1e-9 * (abs(lo) + abs(hi)) <= loc <= hi + 1e-9 * (abs(lo) + abs(hi)):
                    add(f"axes {i} {name} tick label", t, "layout")
        leg = ax.get_legend()
        if leg is not None and leg.get_visible():
            for t in leg.get_texts():
                add(f"axes {i} legend", t, "label")
            add(f"axes {i} legend title", leg.get_title(), "label")
        for t in ax.texts:
            add(f"axes {i} text", t, "label")
    return out


def _overlap(a, b, slack: float = _SLACK) -> bool:
    return min(a.x1, b.x1) - max(a.x0, b.x0) > slack and min(a.y1, b.y1) - max(a.y0, b.y0) > slack


def _has_data(ax) -> bool:
    """An axes that draws data (not a colour bar, which is labelled by its own label)."""
    if getattr(ax, "_colorbar", None) is not None:
        return False
    return bool(ax.lines or ax.collections or ax.images or ax.patches or ax.containers)


def _labels_problems(fig) -> list[str]:
    """Titles, axis labels and units: each rectilinear axes with data has a title (or the
    figure a suptitle), and an x and y label (or a neighbour in its column/row has one) that
    names a unit or a dimensionless quantity."""
    probs = []
    axes = [a for a in fig.axes if a.get_visible() and a.name == "rectilinear" and _has_data(a)]
    sup = getattr(fig, "_suptitle", None)
    has_sup = sup is not None and sup.get_text().strip()
    for i, ax in enumerate(fig.axes):
        if ax not in axes:
            continue
        if not (has_sup or ax.get_title() or ax.get_title("left") or ax.get_title("right")):
            probs.append(f"axes {i}: no title")
        box = ax.get_position()
        for name, axis, near in (
            ("x", ax.xaxis, lambda o: abs(o.get_position().x0 - box.x0) < 1e-6),
            ("y", ax.yaxis, lambda o: abs(o.get_position().y0 - box.y0) < 1e-6),
        ):
            ticks = [t.get_text() for t in axis.get_majorticklabels() if t.get_visible()]
            if not any(ticks):
                continue  # no tick labels (an image, a map drawn without axes)
            label = axis.label.get_text().strip()
            if not label:
                others = [o for o in axes if o is not ax and near(o)]
                if not any((o.xaxis if name == "x" else o.yaxis).label.get_text() for o in others):
                    probs.append(f"axes {i}: no {name} label")
                continue
            low = label.lower()
            categorical = any(t and not (_NUMBER.match(t) or "mathdefault" in t) for t in ticks)
            if not (categorical or _UNIT.search(label) or any(w in low for w in UNITLESS)):
                probs.append(f"axes {i}: {name} label {label!r} names no unit")
    return probs


def layout_problems(fig) -> list[str]:
    """What a reader would trip over in ``fig``, as it will be drawn, in short sentences:

    - a text over another text (titles, axis and tick labels, legend entries, texts placed
      in the data), where the layout engine can tell from the drawn boxes;
    - a title, axis label or tick label over the data area of an axes;
    - an additive offset on the tick labels (``1e-6+2.4353e-1``): the ticks should say the
      numbers;
    - an axes with data but no title, an axis without a label, a label without a unit (or a
      word of :data:`UNITLESS`);
    - the checks of :func:`sim.report.figcheck.reader_problems`: legends over data, texts
      over markers or cut off, tiny fonts, ASCII units, tick labels with too many digits,
      comb histograms, pale or look-alike legend colours.

    Empty when the figure reads cleanly. Lays the figure out once, without rasterising it (no
    file is written: every check reads the artists' boxes, not pixels)."""
    fig.draw_without_rendering()
    renderer = fig.canvas.get_renderer()
    drawn = _texts(fig, renderer)
    texts = [(w, t.get_window_extent(renderer), r) for w, t, r in drawn]
    probs = []
    for i in range(len(texts)):
        for j in range(i + 1, len(texts)):
            (wa, a, _), (wb, b, _) = texts[i], texts[j]
            if wa.rsplit(" ", 1)[0] == wb.rsplit(" ", 1)[0] and "legend" in wa:
                continue  # the entries of one legend are placed by the legend
            if _overlap(a, b):
                probs.append(f"{wa} overlaps {wb}")
    areas = [
        (k, ax.get_window_extent(renderer))
        for k, ax in enumerate(fig.axes)
        if ax.get_visible() and ax.name == "rectilinear" and _has_data(ax)
    ]
    for w, box, role in texts:
        if role != "layout":
            continue
        for k, area in areas:
            if _overlap(box, area, slack=2.0):
                probs.append(f"{w} lies over the data area of axes {k}")
    for i, ax in enumerate(fig.axes):
        for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            off = axis.get_offset_text()
            if ax.get_visible() and off.get_visible() and "+" in off.get_text():
                probs.append(f"axes {i}: {name} tick labels carry an offset {off.get_text()!r}")
    seen = {}
    for w, t, _ in drawn:  # one sentence per artist kind and text (tick labels repeat)
        seen.setdefault((w, t.get_text()), t)
    style = reader_problems(fig, renderer, [(w, t) for (w, _), t in seen.items()])
    return probs + _labels_problems(fig) + list(dict.fromkeys(style))


_RECORDER: Callable[[Path, object], None] | None = None


@contextmanager
def checking_figures(facts: dict | None = None) -> Iterator[dict[str, list[str]]]:
    """Within the block, every figure :func:`save` writes in this process is checked by
    :func:`layout_problems` first; yields ``{file name: problems}``, filled as they are
    saved (the tests run a study at a tiny size inside it). ``facts``, when given, is filled
    with ``{file name: figure_facts(fig)}`` (:func:`sim.report.figcheck.figure_facts`).
    Outside the block, the environment variable ``SIM_FIGURE_CHECK=FILE`` does the same in
    any process (a test hook: a ``sim run`` subprocess, its pool workers): one JSON line
    ``{"file", "problems", "facts"}`` per figure appended to FILE."""
    global _RECORDER
    found: dict[str, list[str]] = {}
    old = _RECORDER

    def record(path, fig):
        found[Path(path).name] = layout_problems(fig)
        if facts is not None:
            facts[Path(path).name] = figure_facts(fig)

    _RECORDER = record
    try:
        yield found
    finally:
        _RECORDER = old


#: True while a run draws no figures (:func:`without_figures`): a context variable, so that
#: it holds for that run alone (a process-wide flag of the Python API's ``run(figures=False)``
#: in one thread took the figures of a run in another thread, whose ``run.json`` said drawn)
_SKIP: ContextVar[bool] = ContextVar("sim_without_figures", default=False)


@contextmanager
def without_figures() -> Iterator[None]:
    """Inside, no figure is drawn or written (``sim run --no-figures``, and the re-runs of
    ``make verify``, which compares tables only): :func:`draw` skips its jobs, :func:`save`
    closes the figure without a file, and :func:`place_legend` skips its layout pass. The
    tables are the same: no figure function writes a table from its drawing. It holds in this
    thread's context (and in the threads a study runs its parts in, which take a copy of it:
    :func:`sim.studies.design.parts.side_by_side`), never in another run's thread."""
    token = _SKIP.set(True)
    try:
        yield
    finally:
        _SKIP.reset(token)


def figures_off() -> bool:
    """True inside :func:`without_figures`: a figure function called outside :func:`draw`
    returns before it builds anything (building a figure only to close it unsaved would
    import pyplot and lay out every panel for nothing)."""
    return _SKIP.get()


#: matplotlib's warning for a character its font cannot draw (a network named "日本")
_GLYPH = re.compile(r"Glyph (\d+) .*missing from font")


def _glyph_note(path: Path, caught: list) -> None:
    """One line for the characters of a figure that its font could not draw (they are boxes
    in the PNG), instead of matplotlib's two lines per character and draw; any other warning
    is shown as it was."""
    missing = []
    for w in caught:
        m = _GLYPH.match(str(w.message))
        if m is None:
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)
        elif chr(int(m.group(1))) not in missing:
            missing.append(chr(int(m.group(1))))
    if missing:
        say(
            f"sim: note: {path.name}: its font has no glyph for {''.join(missing)!r} "
            "(drawn as boxes)",
        )


def save(fig, path: str | Path) -> Path:
    """Save ``fig`` as PNG without a timestamp or version stamp, then close it. Inside
    :func:`checking_figures` (or with ``SIM_FIGURE_CHECK`` set) the saved figure is then
    checked by :func:`layout_problems`: after the file is written, since the check draws the
    figure once more and a layout drawn twice can settle elsewhere (the PNG is the same with
    the check on or off). The check, :func:`place_legend` and the PNG share one resolution
    (the style's ``figure.dpi`` is its ``savefig.dpi``), so the boxes the check measures are
    the PNG's."""
    path = Path(path)
    if _SKIP.get():  # a run without figures (:func:`without_figures`)
        plt.close(fig)
        return path
    with atomic_path(path) as tmp, warnings.catch_warnings(record=True) as caught:
        warnings.filterwarnings("always", _GLYPH.pattern, UserWarning)
        fig.savefig(tmp, format="png", metadata={"Software": None}, bbox_inches="tight")
    _glyph_note(path, caught)
    if _RECORDER is not None:
        _RECORDER(path, fig)
    elif os.environ.get("SIM_FIGURE_CHECK"):  # the same check in a `sim run` process (tests)
        line = {"file": path.name, "problems": layout_problems(fig), "facts": figure_facts(fig)}
        log = os.environ["SIM_FIGURE_CHECK"]
        try:
            with open(log, "a", encoding="utf-8") as f:  # one short line per write
                f.write(json.dumps(line) + "\n")
        except OSError as e:  # the variable's file, named (not a bare "Is a directory")
            raise ConfigError("SIM_FIGURE_CHECK", f"cannot append to {log}: {e.strerror}") from None
    plt.close(fig)
    return path


def draw(jobs: Sequence[tuple[Callable, tuple]]) -> None:
    """Draw every figure job ``fn(*args)`` (``fn`` draws one figure and saves it) in this
    process, one at a time under :data:`DRAWING` (:mod:`sim.report.drawing`). (Figures once went to the pool's idle
    workers; ``make bench`` found that it saved under 20 % of any study's time, so it went.)
    Nothing is drawn inside :func:`without_figures`."""
    if _SKIP.get():
        return
    for fn, args in jobs:
        with drawing():
            fn(*args)


def hist_bins(values, n: int = 50) -> np.ndarray:
    """Histogram bin edges for ``values`` with about ``n`` bins that never comb: when the
    values lie on a lattice (counts, shares of a fixed total, rounded readings), every bin
    holds the same number of lattice values (edges halfway between them)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return np.linspace(0.0, 1.0, n + 1)
    lo, hi = float(v.min()), float(v.max())
    if hi <= lo:
        return np.array([lo - 0.5, lo + 0.5])
    u = np.unique(v)
    step = float(np.min(np.diff(u))) if u.size > 1 else hi - lo
    on_lattice = u.size > 1 and np.allclose((u - lo) / step, np.round((u - lo) / step), atol=1e-6)
    if not on_lattice or (hi - lo) / step > 20 * n:
        return np.linspace(lo, hi, n + 1)
    k = max(1, int(np.ceil((hi - lo) / step / n)))  # lattice values per bin
    width = k * step
    return np.arange(lo - step / 2, hi + width, width)


_INSIDE = ("upper right", "upper left", "lower right", "lower left", "center right")
_INSIDE += ("center left", "upper center", "lower center", "center")


def place_legend(ax, *args, **kw):
    """``ax.legend(*args, **kw)`` at the first place inside the axes where it hides no data
    (markers, lines, bars: :func:`sim.report.figcheck.data_points`), else outside on the
    right. Call it once the axes' data and limits are final."""
    if _SKIP.get():  # no figure will be saved: no layout pass to place it
        return ax.legend(*args, **kw)
    ax.figure.draw_without_rendering()  # the layout and text extents, no pixels
    return _place(ax, args, kw)[0]


def place_legends(axes, **kw) -> None:
    """:func:`place_legend` on each of ``axes`` (of one figure, every panel drawn): one layout
    pass for them all (a pass per legend cost about a second each on a sweep's 12 panels), and
    a new one after a legend placed outside its axes (that legend moves the panels)."""
    laid_out = _SKIP.get()
    for ax in axes:
        if _SKIP.get():
            ax.legend(**kw)
            continue
        if not laid_out:
            ax.figure.draw_without_rendering()
        laid_out = _place(ax, (), dict(kw))[1]


def _place(ax, args, kw):
    """The legend of ``ax`` at the first free place inside (``(legend, True)``) or outside on
    the right (``(legend, False)``); the figure's layout is current."""
    renderer = ax.figure.canvas.get_renderer()
    pts = data_points(ax)
    kw.setdefault("fontsize", 7)
    for loc in _INSIDE:
        leg = ax.legend(*args, loc=loc, **kw)
        box = leg.get_window_extent(renderer)
        if not points_inside(pts, box, shrink=-4.0):  # with 4 px to spare
            return leg, True
    leg = ax.legend(*args, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0, **kw)
    return leg, False


def readable_limits(ax, axis: str = "y", rel: float = 1e-3) -> None:
    """Widen a linear axis whose data span is below ``rel`` of its centre (values equal to
    four digits): its tick labels then say the value in at most five digits instead of an
    offset or seven digits (:data:`sim.report.figcheck.MAX_DIGITS`)."""
    lo, hi = ax.get_ylim() if axis == "y" else ax.get_xlim()
    centre, span = (lo + hi) / 2, hi - lo
    if centre == 0 or span >= rel * abs(centre):
        return
    half = rel * abs(centre) / 2
    (ax.set_ylim if axis == "y" else ax.set_xlim)(centre - half, centre + half)


def plain_log(ax, axis: str = "x") -> None:
    """Tick labels of a log axis as plain numbers at 1, 2 and 5 of each decade (``2``,
    ``50``, not ``2×10⁰``); minor ticks unlabelled (they would crowd)."""
    a = ax.xaxis if axis == "x" else ax.yaxis
    a.set_major_locator(ticker.LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    a.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    a.set_minor_formatter(ticker.NullFormatter())


def times_ten(x: float, digits: int = 2) -> str:
    """``x`` as a reader writes a very small or large number: ``1.0×10⁻¹²`` (plain ``0.25``
    between 0.001 and 10000)."""
    if x == 0 or not np.isfinite(x) or 1e-3 <= abs(x) < 1e4:
        return f"{x:.{digits}g}"
    e = int(np.floor(np.log10(abs(x))))
    sup = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
    return f"{x / 10**e:.{digits - 1}f}×10{str(e).translate(sup)}"
