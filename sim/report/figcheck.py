"""What a reader of a figure trips over, found from the drawn figure (issue 25 item 10): the
checks of :func:`sim.report.plotting.layout_problems` beyond text against text, each a short
sentence naming the axes and the artist.

- a legend inside an axes lying over data (markers, line vertices, bars);
- a text placed in the data over a marker, or running out of its axes (cut off);
- text smaller than :data:`MIN_POINTS`;
- units and symbols written in ASCII (``um``, ``sigma``, ``+-``) instead of µm, σ and ±;
- tick labels that need more than :data:`MAX_DIGITS` significant digits (a range too
  narrow for the size of its values);
- a histogram with isolated empty bins among full ones (a comb: bins out of step with the
  data's rounding);
- legend entries drawn in a pale colour, or two entries with the same marker and line
  that differ by a colour too close to tell apart.

:func:`figure_facts` gives what the tests check a figure by: per axes its title, labels,
number of series and the range of its data.
"""

from __future__ import annotations

import re

import numpy as np

from sim.report.mpl import collections as mcoll
from sim.report.mpl import lazy

_cbook, _colors = lazy("matplotlib.cbook"), lazy("matplotlib.colors")
_container, _lines, _quiver = (
    lazy("matplotlib.container"),
    lazy("matplotlib.lines"),
    lazy("matplotlib.quiver"),
)

__all__ = ["reader_problems", "figure_facts", "data_points", "points_inside"]
__all__ += ["MIN_POINTS", "MAX_DIGITS"]

#: the smallest font a reader can read on a report page (points)
MIN_POINTS = 6.0
#: significant digits a tick label may need
MAX_DIGITS = 5
_ASCII = (
    (re.compile(r"(?<![\w.])um(?![\w.])"), "'um' (write µm)"),
    (re.compile(r"(?<![\w.])sigma(?![.\w]*\.)", re.I), "'sigma' (write σ)"),
    (re.compile(r"\+-|\+/-"), "'+-' (write ±)"),
    (re.compile(r"\d[eE][-+]?\d"), "a number in e-notation (write ×10ⁿ, or choose the unit)"),
)
_DIGITS = re.compile(r"^[\s$]*[-−+]?([\d.,]*\d)(?:[eE][-−+]?\d+)?\s*(?:%|°)?[\s$]*$")


def _marker_points(ax) -> np.ndarray:
    """Display coordinates of every drawn marker: markers of lines, scatter offsets, quiver
    tails."""
    pts = []
    for ln in ax.lines:
        if ln.get_visible() and ln.get_marker() not in (None, "", "None", " ", ","):
            xy = np.asarray(ln.get_xydata(), float)
            pts.append(ln.get_transform().transform(xy[np.isfinite(xy).all(1)]))
    for c in ax.collections:
        if c.get_visible() and isinstance(c, (mcoll.PathCollection, _quiver.Quiver)):
            off = np.asarray(c.get_offsets(), float)
            if off.size:
                pts.append(c.get_offset_transform().transform(off[np.isfinite(off).all(1)]))
    return np.concatenate(pts) if pts else np.zeros((0, 2))


def _densify(xy: np.ndarray, step: float = 3.0) -> np.ndarray:
    """Points every ``step`` pixels along a polyline in display coordinates."""
    if len(xy) < 2 or len(xy) > 2000:
        return xy
    out = [xy[:1]]
    for a, b in zip(xy[:-1], xy[1:]):
        n = int(min(np.hypot(*(b - a)) / step, 400)) + 1
        out.append(a + (b - a) * np.linspace(0, 1, n + 1)[1:, None])
    return np.concatenate(out)


def data_points(ax) -> np.ndarray:
    """Display coordinates a legend must not hide: markers, points along drawn lines and
    line collections (error bars, observation lines), the corners and centres of bars."""
    pts = [_marker_points(ax)]
    for ln in ax.lines:
        if ln.get_visible() and ln.get_linestyle() not in ("None", "", " "):
            xy = np.asarray(ln.get_xydata(), float)
            if ln.get_drawstyle() in _cbook.STEP_LOOKUP_MAP and ln.get_drawstyle() != "default":
                xy = np.column_stack(_cbook.STEP_LOOKUP_MAP[ln.get_drawstyle()](*xy.T))
            xy = ln.get_transform().transform(xy[np.isfinite(xy).all(1)])
            pts.append(_densify(xy))
    for c in ax.collections:
        if c.get_visible() and isinstance(c, mcoll.LineCollection) and len(c.get_segments()) < 3000:
            for seg in c.get_segments():
                seg = np.asarray(seg, float)
                if seg.size and np.isfinite(seg).all():
                    pts.append(_densify(c.get_transform().transform(seg)))
    for cont in ax.containers:
        if isinstance(cont, _container.BarContainer):
            for p in cont.patches:
                b = p.get_window_extent()
                if b.width > 0 and b.height > 0:
                    pts.append(np.array([[b.x0, b.y1], [b.x1, b.y1], [(b.x0 + b.x1) / 2, b.y1]]))
    pts = [p for p in pts if len(p)]
    return np.concatenate(pts) if pts else np.zeros((0, 2))


def points_inside(pts: np.ndarray, box, shrink: float = 1.0) -> int:
    if not len(pts):
        return 0
    x, y = pts[:, 0], pts[:, 1]
    return int(
        np.sum(
            (x > box.x0 + shrink)
            & (x < box.x1 - shrink)
            & (y > box.y0 + shrink)
            & (y < box.y1 - shrink)
        )
    )


def _legend_and_text_problems(i: int, ax, renderer) -> list[str]:
    probs = []
    area = ax.get_window_extent(renderer)
    leg = ax.get_legend()
    if leg is not None and leg.get_visible():
        box = leg.get_window_extent(renderer)
        n = points_inside(data_points(ax), box)
        if n:
            probs.append(f"axes {i}: the legend lies over the data ({n} drawn points under it)")
    marks = _marker_points(ax)
    for t in ax.texts:
        if not (t.get_visible() and t.get_text().strip()):
            continue
        box = t.get_window_extent(renderer)
        if (
            box.x0 < area.x0 - 1
            or box.x1 > area.x1 + 1
            or box.y0 < area.y0 - 1
            or box.y1 > area.y1 + 1
        ):
            probs.append(f"axes {i}: text {t.get_text()!r} runs out of the axes")
        if points_inside(marks, box, shrink=0.5):
            probs.append(f"axes {i}: text {t.get_text()!r} lies over a marker")
    return probs


def _significant(label: str) -> int:
    m = _DIGITS.match(label.replace("−", "-"))
    if not m:
        return 0
    d = m.group(1).replace(",", "")
    if "." not in d:
        d = d.rstrip("0")
    return len(d.replace(".", "").lstrip("0"))


def _tick_problems(i: int, ax) -> list[str]:
    probs = []
    for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
        labels = [t.get_text() for t in axis.get_majorticklabels() if t.get_visible()]
        worst = max(labels, key=_significant, default="")
        if _significant(worst) > MAX_DIGITS:
            probs.append(
                f"axes {i}: {name} tick labels need {_significant(worst)} digits ({worst!r}): "
                "the range is narrow for the size of its values"
            )
    return probs


def _comb_problems(i: int, ax) -> list[str]:
    probs = []
    for cont in ax.containers:
        if not isinstance(cont, _container.BarContainer) or len(cont.patches) < 10:
            continue
        h = np.array([p.get_height() for p in cont.patches])
        nz = np.flatnonzero(h > 0)
        if nz.size < 3:
            continue
        inner = h[nz[0] : nz[-1] + 1]
        if inner.mean() < 5:  # too few counts per bin for an empty bin to mean a comb
            continue
        holes = np.sum((inner[1:-1] == 0) & (inner[:-2] > 0) & (inner[2:] > 0))
        if holes >= 3 and holes >= 0.15 * inner.size:
            probs.append(f"axes {i}: a histogram with {holes} isolated empty bins (a comb)")
    return probs


def _handle_colour(h):
    if isinstance(h, _container.ErrorbarContainer) and h.lines[0] is not None:
        h = h.lines[0]  # an error-bar series: its data line (a sweep's series were skipped)
    if isinstance(h, _lines.Line2D):
        c = h.get_color()
        if h.get_linestyle() in ("None", "") and h.get_markerfacecolor() != "none":
            c = h.get_markerfacecolor()  # a marker alone: its face, else its edge
        hollow = _colors.same_color(h.get_markerfacecolor(), "white")
        return _colors.to_rgba(c, h.get_alpha()), (h.get_marker(), h.get_linestyle(), hollow)
    if isinstance(h, mcoll.PathCollection) and len(h.get_facecolors()):
        return _colors.to_rgba(h.get_facecolors()[0], h.get_alpha()), ("scatter", "")
    return None, None


def _colour_problems(i: int, ax) -> list[str]:
    leg = ax.get_legend()
    if leg is None or not leg.get_visible():
        return []
    probs, seen = [], []
    drawn = dict(zip(*reversed(ax.get_legend_handles_labels())))  # label -> the series
    for h, t in zip(leg.legend_handles, leg.get_texts()):
        rgba, style = _handle_colour(drawn.get(t.get_text(), h))  # an error bar's proxy
        # in the legend is its bars' LineCollection: the series itself has the colour
        if rgba is None:
            continue
        a = rgba[3]
        rgb = np.array(rgba[:3]) * a + (1 - a)  # over white
        name = t.get_text()
        if rgb @ [0.299, 0.587, 0.114] > 0.8:
            probs.append(f"axes {i}: legend entry {name!r} is drawn in a pale colour")
        for other, orgb, ostyle in seen:
            if ostyle == style and np.abs(rgb - orgb).max() < 0.12:
                probs.append(f"axes {i}: legend entries {other!r} and {name!r} look alike")
        seen.append((name, rgb, style))
    return probs


def _text_style_problems(texts) -> list[str]:
    probs = []
    for what, t in texts:
        s = t.get_text()
        if t.get_fontsize() < MIN_POINTS:
            probs.append(f"{what} {s[:30]!r} is set at {t.get_fontsize():.0f} pt")
        if "$" in s:
            continue
        for pat, why in _ASCII:
            if pat.search(s):
                probs.append(f"{what} {s[:40]!r} writes {why}")
    return probs


def reader_problems(fig, renderer, texts) -> list[str]:
    """The checks listed in the module docstring, on a drawn ``fig``; ``texts``: ``(what,
    Text)`` of every visible text of the figure."""
    probs = _text_style_problems(texts)
    for i, ax in enumerate(fig.axes):
        if not ax.get_visible():
            continue
        probs += _legend_and_text_problems(i, ax, renderer)
        probs += _tick_problems(i, ax) + _comb_problems(i, ax) + _colour_problems(i, ax)
    return probs


def _series(ax) -> int:
    leg = ax.get_legend()
    if leg is not None:
        return len(leg.get_texts())
    n = sum(1 for ln in ax.lines if ln.get_visible())
    n += sum(
        1 for c in ax.collections if c.get_visible() and not isinstance(c, mcoll.PolyCollection)
    )
    return n + sum(1 for c in ax.containers if isinstance(c, _container.BarContainer))


def figure_facts(fig) -> list[dict]:
    """Per visible axes with data: ``title``, ``xlabel``, ``ylabel``, ``series`` (legend
    entries, else drawn lines, collections and bar groups), ``xlim`` and ``ylim``."""
    out = []
    for ax in fig.axes:
        if not ax.get_visible() or not (ax.lines or ax.collections or ax.patches or ax.images):
            continue
        out.append(
            {
                "title": " ".join(
                    t for t in (ax.get_title("left"), ax.get_title(), ax.get_title("right")) if t
                ),
                "xlabel": ax.get_xlabel(),
                "ylabel": ax.get_ylabel(),
                "series": _series(ax),
                "xlim": tuple(sorted(ax.get_xlim())),
                "ylim": tuple(sorted(ax.get_ylim())),
            }
        )
    return out
