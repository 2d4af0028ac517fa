"""The lead's items of the session of 2026-11-28 afternoon (issue 26), one case each; each
failed on the code before its fix.

* the figure check (:func:`sim.report.plotting.layout_problems`) and the legend placement
  (:func:`sim.report.plotting.place_legend`) laid a figure out at the screen's 100 dpi while
  the PNG is drawn at 110: a legend placed with 4 px to spare could touch a point in the PNG
  while the check passed (the last session's 300-cell sweep). Both now see the PNG's own
  geometry.
* ``sim show``'s text table padded by characters: a swept key of CJK names (two terminal
  columns each) pushed the next column of its row out of line (doors24c left it).
"""

import unicodedata

import matplotlib
import numpy as np
from matplotlib import image

from sim.report.mpl import STYLE
from sim.report.plotting import layout_problems, place_legend, plt, save


def test_the_figure_check_measures_the_png_it_passes(tmp_path):
    """The figure the check lays out is the PNG, pixel for pixel in size: its tight box (with
    savefig's padding) at the figure's resolution is the PNG's width and height."""
    fig, ax = plt.subplots(figsize=(4.0, 3.0))
    x = np.linspace(0.0, 1.0, 50)
    ax.plot(x, x**2, "o-", label="a series")
    ax.set(xlabel="x (mm)", ylabel="y (mm)", title="t")
    place_legend(ax)
    png = save(fig, tmp_path / "f.png")
    assert layout_problems(fig) == []  # the check ran and drew the figure
    renderer = fig.canvas.get_renderer()
    box = fig.get_tightbbox(renderer).padded(matplotlib.rcParams["savefig.pad_inches"])
    h, w = image.imread(png).shape[:2]
    assert abs(box.width * fig.dpi - w) <= 1 and abs(box.height * fig.dpi - h) <= 1, (
        (box.width * fig.dpi, box.height * fig.dpi),
        (w, h),
    )
    assert STYLE["savefig.dpi"] == fig.dpi


def test_sim_shows_a_sweep_of_wide_names_in_aligned_columns(tmp_path):
    """A swept key whose values are CJK names (two terminal columns each) and accented ones
    (a combining mark, none): every row's next column starts at one terminal column."""
    from sim.mc.storage import write_table
    from sim.report.run_summary import terminal_table

    names = ["日本測量網", "plate", "Zu\u0308rich", "東京"]
    n = len(names)
    cols = {"cell": list(range(n)), "replicate": [0] * n, "label": [f"c{i}" for i in range(n)]}
    cols.update(seed=list(range(n)), feasible=[True] * n, reason=[""] * n)
    cols["network.name"] = names
    write_table(
        tmp_path / "sweep.parquet", cols, {"study": "network", "sweep_keys": ["network.name"]}
    )
    lines = terminal_table(tmp_path).split("\n\n")[0].splitlines()
    starts = {
        _cols(ln[: ln.index("yes" if "yes" in ln else "feasible")])
        for ln in lines
        if ln[:2] != "--"
    }
    assert len(starts) == 1, lines


def _cols(s: str) -> int:
    """Terminal columns, as a terminal counts them (the test's own count)."""
    return sum(
        0 if unicodedata.combining(c) else 2 if unicodedata.east_asian_width(c) in "WF" else 1
        for c in s
    )
