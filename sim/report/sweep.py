"""Figure and Markdown of a ``[sweep]`` run (``sweep.parquet``, see :mod:`sim.mc.sweep`):
every claim against the first swept key (``sweep.png``), and the table of cells.
"""

from __future__ import annotations

import functools
import itertools
from pathlib import Path

import numpy as np

from sim.mc.publish import drawn
from sim.mc.storage import read_provenance
from sim.report.drawing import one_at_a_time
from sim.report.labels import apart
from sim.report.mpl import ticker
from sim.report.plotting import (
    figures_off,
    place_legends,
    plt,
    readable_limits,
    save,
    times_ten,
)
from sim.report.read import columns
from sim.report.tables import fmt, md_table

__all__ = ["fig_sweep", "level_texts", "sweep_markdown"]


def _claim_columns(t: dict, keys: list) -> list[str]:
    skip = set(keys) | {"cell", "replicate", "label", "seed", "feasible", "reason"}
    return [c for c in t if c not in skip and not c.endswith((":lo", ":hi")) and c + ":lo" in t]


#: unit suffixes of config keys and claim ids (the project names units in its names)
_UNITS = {"_mm": "mm", "_um": "µm", "_m": "m", "_cm": "cm", "_pct": "%", "_ppm": "ppm"}
_UNITS.update({"_arcsec": "arcsec", "_s": "s", "_mm2": "mm²", "_deg": "deg"})
#: words of a claim id that mark a proportion (drawn, intervals included, inside [0, 1])
_PROPORTION = ("coverage", "false_alarm", "share", "rate", "proportion", "fraction", "power")
#: series colours: the default cycle without red, which marks infeasible cells
_COLOURS = ["tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink"]
_COLOURS += ["tab:gray", "tab:olive", "tab:cyan"]
#: after every colour, the next series change marker and line (the tenth series was drawn
#: exactly as the first: two legend entries alike, their lines told apart by nothing)
_STYLES = [("o", "-"), ("s", "--"), ("^", ":"), ("D", "-."), ("v", (0, (5, 1, 1, 1, 1, 1)))]


def _style(n: int) -> dict:
    """Colour, marker and line of series ``n``: distinct for 45 series, then repeating (past
    the colours, hollow markers: a legend's short handle hides a dashed line)."""
    k = (n // len(_COLOURS)) % len(_STYLES)
    marker, line = _STYLES[k]
    style = {"color": _COLOURS[n % len(_COLOURS)], "marker": marker, "linestyle": line}
    return style | ({"markerfacecolor": "white"} if k else {})  # hollow: told apart in a legend


def _value_texts(values) -> dict:
    """Each value of a swept key (by its ``repr``) as a legend shows it: floats with the
    fewest significant digits (at least 4) that keep every value apart (a range's
    0.031111111111111112 was cut to "0.0311111111111..."), anything else as ``str``."""
    vals = {repr(v): v for v in values}  # by repr: a list-valued key's values are lists
    floats = {k: v for k, v in vals.items() if isinstance(v, float)}
    for digits in range(4, 18):
        shown = {k: f"{v:.{digits}g}" for k, v in floats.items()}
        if len(set(shown.values())) == len(shown):
            break
    return {
        k: shown[k] if k in floats else _BOOL_TEXT[k] if isinstance(v, bool) else str(v)
        for k, v in vals.items()
    }


#: a bool level as the study file writes it (TOML), by its ``repr``
_BOOL_TEXT = {"False": "false", "True": "true"}


def level_texts(values: list) -> list[str]:
    """A swept key's column of a sweep's table (README.md's, ``sim show``'s): each float
    level as asked, its shortest text (``45.001``, ``0.001``), or, past 12 characters, with
    the fewest digits that keep the levels apart (:func:`_value_texts`); a bool as TOML
    writes it (``false``, not ``no``); anything else as :func:`fmt` shows it. With three
    digits, ``plate.spacing_mm = [45.0, 45.001]`` read 45.0 in both rows, and a range's
    0.30000000000000004 read 0.300."""
    finite = [isinstance(v, float) and bool(np.isfinite(v)) for v in values]
    short = _value_texts([v for v, f in zip(values, finite) if f])
    return [
        (r if len(r := repr(v)) <= 12 else short[r])
        if f
        else _BOOL_TEXT[repr(v)]
        if isinstance(v, bool)
        else fmt(v)
        for v, f in zip(values, finite)
    ]


def unit_of(name: str) -> str:
    """The unit a key or claim id names by its suffix (``plate.spacing_mm`` -> ``mm``)."""
    for suffix in sorted(_UNITS, key=len, reverse=True):
        if name.endswith(suffix):
            return _UNITS[suffix]
    return ""


def _is_proportion(name: str, *arrays) -> bool:
    vals = np.concatenate([a[np.isfinite(a)] for a in arrays[:1]]) if arrays else np.array([])
    inside = vals.size == 0 or (vals.min() >= 0 and vals.max() <= 1)
    return inside and any(w in name.split(".")[-1] or w in name for w in _PROPORTION)


def _y_label(claim: str, proportion: bool) -> str:
    if proportion:
        return "proportion"
    if unit_of(claim):
        return f"simulated value ({unit_of(claim)})"
    return "simulated ratio" if "ratio" in claim else "simulated value (no unit)"


def _column(t: dict, name: str) -> np.ndarray:
    return np.array([np.nan if a is None else a for a in t[name]], float)


def _legend_values(values, n: int = 16) -> dict:
    """:func:`_value_texts` in at most ``n`` characters that tell the values apart
    (:func:`sim.report.labels.apart`): a swept ``network.generate`` whose lists differ only
    in a sigma was cut at its start, and both series of ``sweep.png`` read
    ``generate=[{'kind': 'dx',...``."""
    texts = _value_texts(values)
    return dict(zip(texts, apart(list(texts.values()), n)))


def _short(text: str, n: int = 40) -> str:
    """A legend or tick label of at most ``n`` characters (a list-valued key's values would
    crowd the axes out of the figure)."""
    return text if len(text) <= n else text[: n - 1] + "\u2026"


def _legend_names(keys: list[str]) -> list[str]:
    """The other swept keys as a legend names them: the last part of each dotted key when
    those are distinct (``solver.max_iter`` -> ``max_iter``). A label of the whole keys cut
    at 40 characters lost the key that told two series apart (``network.estimate_scale=
    False, solver.ma...`` twice)."""
    last = [k.rsplit(".", 1)[-1] for k in keys]
    return last if len(set(last)) == len(last) else list(keys)


#: what a panel's bars are, by the ``interval`` of the claim's rows (``sim.claims.book``): a
#: one-plate claim's bars are the spread of one plate, not an interval of its value (two
#: cells' bars overlapped where their medians differed by many standard errors), a region
#: row's are its range over the region, its marker the range's low end
_BARS = {
    "ci": "",
    "exact": "",
    "spread": "bars: central 95 % of plates, not an interval of the value",
    "region": "bars: range over the region, marker its low end",
}


def _bars(kinds) -> str:
    """The panel's note on its bars, from the claim's interval kinds over the cells."""
    kinds = list(kinds or ())
    said = list(dict.fromkeys(_BARS.get(k, "") for k in kinds if _BARS.get(k, "")))
    if said and "ci" in kinds:  # some cells a 95 % interval of the value, some not
        said.insert(0, "bars: a 95 % interval in some cells")
    return "; ".join(said)


@one_at_a_time  # (drawn from two API runs' threads at once)
def fig_sweep(path: Path, png: Path, max_panels: int = 12) -> Path | None:
    """Each claim's value (with its 95 % interval) against the first swept key, one line per
    combination of the other keys; infeasible cells marked by a red band. Proportions (by
    their names, values in [0, 1]) are drawn with their intervals clipped to [0, 1]; tick
    labels say the numbers (no offset). A first key whose values are not numbers (text, lists)
    is drawn at one place per distinct value, its ticks labelled with the values; long
    labels are shortened. Drawn from the rows of ``sweep.parquet`` alone; nothing in a run
    without figures."""
    if figures_off():
        return None
    t = columns(path)
    prov = read_provenance(path)
    keys = prov.get("sweep_keys", [])
    kinds = prov.get("claim_intervals") or {}
    claims = _claim_columns(t, keys)[:max_panels]
    if not keys or not claims:
        return None
    first = t[keys[0]]
    # a bool key's false and true at two labelled places: drawn at 0.0 and 1.0 of a number
    # axis, its ticks read 0.2, 0.4, ... of a switch
    numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in first)
    whole = numeric and all(isinstance(v, int) and not isinstance(v, bool) for v in first)
    ticks = list(dict.fromkeys(repr(v) for v in first))  # text, list values: one place each
    x = np.array([float(v) for v in first] if numeric else [ticks.index(repr(v)) for v in first])
    other = [tuple(t[k][i] for k in keys[1:]) for i in range(len(x))]
    # replicates (cells of one setting, other seeds): one line each, in their group's colour,
    # named once; a line through all of them zig-zagged up and down at each x value
    rep = np.asarray(t["replicate"] if "replicate" in t else np.zeros(len(x)), int)
    feas = np.array(t["feasible"], bool)
    ncol = min(3, len(claims))
    nrow = -(-len(claims) // ncol)
    fig, axs = plt.subplots(
        nrow, ncol, figsize=(4.8 * ncol, 3.6 * nrow), squeeze=False, layout="constrained"
    )
    xunit = unit_of(keys[0])
    xlabel = f"{keys[0]} ({xunit or 'no unit'})" + (
        " - red band: infeasible" if (~feas).any() else ""
    )
    if rep.size and rep.max() > 0:
        xlabel += f" - {rep.max() + 1} replicates, a line each"
    empty: list = []  # panels of a claim without a finite value
    names = _legend_names(keys[1:])
    shown = [_legend_values(t[k]) for k in keys[1:]]
    for ax, c in zip(axs.ravel(), claims):
        v, lo, hi = _column(t, c), _column(t, c + ":lo"), _column(t, c + ":hi")
        prop = _is_proportion(c, v)
        if prop:
            lo, hi = np.clip(lo, 0.0, 1.0), np.clip(hi, 0.0, 1.0)
        for (n, grp), r in itertools.product(enumerate(dict.fromkeys(other)), np.unique(rep)):
            sel = np.array([o == grp for o in other]) & feas & (rep == r)
            o = np.argsort(x[sel], kind="stable")
            lab = ", ".join(f"{k}={s[repr(g)]}" for k, g, s in zip(names, grp, shown))
            ax.errorbar(
                x[sel][o],
                v[sel][o],
                yerr=[np.maximum(v[sel][o] - lo[sel][o], 0), np.maximum(hi[sel][o] - v[sel][o], 0)],
                ms=3,
                capsize=2,
                label=(_short(lab) or None) if r == rep.min() else None,
                **_style(n),
            )
        for xi in x[~feas]:
            ax.axvline(xi, color="tab:red", alpha=0.3, lw=3)
        if not np.isfinite(v[feas]).any():  # an empty panel of -0.04..0.04 on both axes, its
            ax.text(  # legend naming series that are not there, read as a drawn result
                0.5, 0.5, "no finite value in any cell", transform=ax.transAxes,
                ha="center", va="center", fontsize=8,
            )  # fmt: skip
            if x.size and np.isfinite(x).all():
                pad = max(abs(x.max() - x.min()) * 0.05, 0.5 if not numeric else 0.0) or 1.0
                ax.set_xlim(x.min() - pad, x.max() + pad)
            ax.set_yticks([])
            empty.append(ax)
        if prop:
            ax.set_ylim(-0.02, 1.02) if np.nanmax(hi, initial=0) - np.nanmin(
                lo, initial=1
            ) > 0.5 else None
        readable_limits(ax, "y")
        ax.ticklabel_format(axis="both", useOffset=False, style="plain")
        _powers_when_tiny(ax)
        if whole:  # an integer key (settings, a seed) at 1, 2, 3: no tick at 1.25 of it
            ax.xaxis.set_major_locator(ticker.MaxNLocator(integer=True))
        if not numeric:  # at most 25 labels, upright when few: 50 overlapped in a smear, and
            step = -(-len(ticks) // 25)  # cut at their ends they all read the same
            pos = list(range(0, len(ticks), step))
            # (named apart from ``shown``, the other keys' texts the next panel's legend
            # reads: a text first key and a second key failed the whole sweep at its
            # second panel, "string indices must be integers")
            at = apart([_BOOL_TEXT.get(ticks[i], ticks[i]) for i in pos], 16)
            ax.set_xticks(pos, at, fontsize=7, rotation=90 if len(pos) > 6 else 0)
        note = _bars(kinds.get(c))
        ax.set_title(c + (f"\n({note})" if note else ""), fontsize=8, wrap=True)
        ax.set_xlabel(xlabel, fontsize=8)
        ax.set_ylabel(_y_label(c, prop), fontsize=8)
    for ax in axs.ravel()[len(claims) :]:
        ax.axis("off")
    if other[0]:  # once every panel is drawn: the layout is final
        place_legends([a for a in axs.ravel()[: len(claims)] if a not in empty], handlelength=3)
    return save(fig, png)


def _powers_when_tiny(ax) -> None:
    """Tick labels of a y axis whose values all lie below 1e-3 in magnitude (a claim zero but
    for rounding, 1e-16 mm) as ``2.0×10⁻¹⁷``: plain, every label of Brown's bias-invariance
    panels read ``0.000000000000000``."""
    lo, hi = ax.get_ylim()
    if 0 < max(abs(lo), abs(hi)) < 1e-3:
        ax.yaxis.set_major_formatter(_powers_of_ten_class()())


@functools.cache
def _powers_of_ten_class() -> type:
    """The formatter's class, made at a figure's first use: a subclass of matplotlib's
    ``Formatter`` at import loaded matplotlib with every door (tests/test_import_cost.py)."""

    class _PowersOfTen(ticker.Formatter):
        """:func:`times_ten` labels with the fewest digits (two at least) that say each tick's
        value: at two, ticks 2.5e-17 apart read ``1.3×10⁻¹⁶`` at 1.25e-16, and ticks from 1.1e-16
        to 1.3e-16 read ``1.1×10⁻¹⁶`` three times over."""

        digits = 2

        def set_locs(self, locs) -> None:
            super().set_locs(locs)
            v = np.asarray([x for x in locs if np.isfinite(x) and x != 0], float)
            gaps = np.diff(np.unique(np.asarray(locs, float)))
            step = float(gaps.min()) if gaps.size else 0.0
            if not v.size or step <= 0:
                self.digits = 2
                return
            scale = 10.0 ** np.floor(np.log10(np.abs(v)))
            for d in range(2, 16):  # the rounded mantissas within a millionth of the tick step
                if np.all(np.abs(np.round(v / scale, d - 1) - v / scale) * scale <= 1e-6 * step):
                    break
            self.digits = d

        def __call__(self, x, pos=None) -> str:
            return times_ten(x, self.digits)

    return _PowersOfTen


def _value_cell(t: dict, claim: str, i: int, kinds) -> str:
    """A claim's value in cell ``i``: a region row's (every cell's interval kind ``region``)
    is its range over the region, ``0.12–0.92`` as the cell's own README gives it (the
    table gave the range's low end alone, 0.120 in every cell of a sweep of an input the
    region explores, as if it were the value); a claim with a 95 % interval in every cell
    (``ci``) is its value with it, ``1.01 [0.994, 1.02]``, as the cell's own README gives it
    (the value alone: a self-check's 0.065 read without its [0.038, 0.11])."""
    lo, hi = t[claim][i], t[claim + ":hi"][i]
    if list(kinds or ()) == ["ci"] and "" not in (fmt(lo), fmt(hi), fmt(t[claim + ":lo"][i])):
        return f"{fmt(lo)} [{fmt(t[claim + ':lo'][i])}, {fmt(hi)}]"  # (the value alone before)
    if list(kinds or ()) != ["region"] or fmt(hi) in ("", fmt(lo)) or fmt(lo) == "":
        return fmt(lo)
    return f"{fmt(lo)}–{fmt(hi)}"


def sweep_markdown(out: Path, name: str | None = None) -> str:
    """Markdown for a sweep directory from ``sweep.parquet`` alone: the cells with their
    feasibility and claim values, and the figure (for ``sim report``)."""

    t = columns(Path(out) / "sweep.parquet")
    prov = read_provenance(Path(out) / "sweep.parquet")
    keys = prov.get("sweep_keys", [])
    claims = _claim_columns(t, keys)
    kinds = prov.get("claim_intervals") or {}
    levels = {k: level_texts(list(t[k])) for k in keys}
    rows = [
        [
            t["label"][i],
            *[levels[k][i] for k in keys],
            t["seed"][i],
            "yes" if t["feasible"][i] else f"no: {t['reason'][i]}",
            *[
                _value_cell(t, c, i, kinds.get(c) if isinstance(kinds, dict) else None)
                for c in claims
            ],
        ]
        for i in range(len(t["cell"]))
    ]
    txt = md_table(["cell", *keys, "seed", "feasible", *[f"`{c}`" for c in claims]], rows)
    if drawn(Path(out), "sweep.png"):
        txt += f"\n\n![sweep]({name or Path(out).name}/sweep.png)"
    return txt
